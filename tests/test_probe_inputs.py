"""The probe of issue 20, kept: one representative bad input of each class, replayed in-process.

Each is refused with exit status 2 and one line on stderr that names what the user typed (the
option with its value, or the scene key) first, then why; nothing on stdout, no warning, no
traceback. The classes: huge mode counts, absurd angles, absurd lengths, tolerances and rim
grading below any attainable accuracy, a mesh whose solve cannot fit in the machine's memory
(whatever max_dofs says), a pose beyond the joint limits or the actuator range.
"""
from __future__ import annotations

import pytest

from rps import app as cli
from tests.conftest import PAPER_SCENE

# warnings of numpy or any library never reach the user raw: each is an error here
pytestmark = pytest.mark.filterwarnings("error")


def scene_with(tmp_path, old: str, new: str):
    text = PAPER_SCENE.read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / "scene.toml"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return str(path)


def refused(capsys, argv) -> str:
    """The one stderr line of a refused command (argparse's refusals exit from parse_args)."""
    try:
        status = cli.main(argv)
    except SystemExit as exc:
        status = exc.code
    assert status == 2
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert out == "" and len(lines) == 1, err
    assert "Traceback" not in err and "Warning" not in err
    return lines[0]


@pytest.mark.parametrize("argv, start", [
    # modes: bounded by the declaration of [fidelity] modes (60), then by the model's size
    (["fem", "--modes", "5000"], "error: --modes 5000: must be >= 1 and <= 60"),
    (["workspace", "--modes", "1000"], "error: --modes 1000: must be >= 1 and <= 60"),
    (["workspace", "--modes", "60", "--layers", "1"], "error: --modes 60: the map follows at "
     "most 53 modes"),
    (["analytical", "--modes", "60"], "error: --modes 60: the model has only 54 coordinates"),
    # angles: one turn either way, tilt at most 90 degrees; long numbers shortened
    (["analytical", "--azimuth", "1e308"], "error: --azimuth 1e308 deg: must be >= -360 and "
     "<= 360 deg"),
    (["analytical", "--azimuth", "9" * 309], "error: --azimuth 9999999999...999999 (309 chars) "
     "deg: must be"),
    (["analytical", "--tilt", "1e9"], "error: --tilt 1e9 deg: must be >= -90 and <= 90 deg"),
    # lengths: at most 100 m
    (["analytical", "--height", "1e300"], "error: --height 1e300 mm: must be > 0 and <= "
     "100000 mm"),
    # sizes: a floor
    (["fem", "--size", "1e-300"], "error: --size 1e-300 mm: must be >= 0.01 and"),
    # poses beyond Eq. (25): the typed option first, then the limit by its scene key
    (["analytical", "--tilt", "60"], "error: --tilt 60 deg: S-joint 1 would reach 94.0 deg, "
     "above s_joint_max_deg = 45"),
    (["analytical", "--height", "5000"], "error: --height 5000 mm: leg 1 would be 5001.0 mm "
     "long, outside the actuator range: above actuator_max_mm = 1000"),
    (["analytical", "--elements", "0"], "error: --elements 0: must be >= 1 and <= 200"),
])
def test_bad_options_are_refused_naming_what_was_typed(capsys, argv, start):
    assert refused(capsys, argv).startswith(start)


@pytest.mark.parametrize("old, new, needle", [
    ("actuator_max_mm = 1000.0", "actuator_max_mm = 1e300",
     "manipulator.actuator_max_mm = 1e+300: must be >= 1 and <= 100000 mm"),
    ("tolerance_percent = 1.0", "tolerance_percent = 1e-300",
     "fidelity.tolerance_percent = 1e-300: must be >= 0.01 and <= 50"),
    ("rim_factor = 0.4", "rim_factor = 1e-300",
     "fem.rim_factor = 1e-300: must be >= 0.005 and <= 1"),
    ("azimuth_deg = 10.0", "azimuth_deg = 1e300",
     "azimuth_deg = 1e+300: must be >= -360 and <= 360 deg"),
])
def test_absurd_scene_values_are_refused_naming_the_key(capsys, tmp_path, old, new, needle):
    line = refused(capsys, ["analytical", "--scene", scene_with(tmp_path, old, new)])
    assert needle in line


def test_a_mesh_beyond_the_machines_memory_is_refused_whatever_max_dofs_says(capsys, tmp_path):
    scene = scene_with(tmp_path, "max_dofs = 600000", "max_dofs = 100000000")
    cache = tmp_path / "cache"
    line = refused(capsys, ["fem", "--scene", scene, "--size", "0.5", "--cache", str(cache)])
    assert line.startswith("error: --size 0.5 mm: the solve needs about ")
    assert "GB" in line and "available" in line
    assert not cache.exists()


def test_the_run_s_chosen_model_is_one_option_away(capsys):
    """The report fixture is a run of scenes/paper.toml: its chosen model (Timoshenko with
    Hutchinson's coefficient) is what --from-results computes."""
    from results import read
    from studies import RECORDS
    from tests.conftest import ROOT

    fixture = ROOT / "tests" / "fixtures" / "report_results.json"
    chosen = read(fixture, RECORDS)["fidelity"]["analytical"]
    assert cli.main(["analytical", "--scene", str(PAPER_SCENE), "--case", "case1",
                     "--from-results", str(fixture), "--json"]) == 0
    import json
    payload = json.loads(capsys.readouterr().out)
    assert (payload["beam"], payload["shear"], payload["elements"]) == (
        chosen["beam"], chosen["shear"], chosen["elements"])
    assert "the run's choice" in payload["settings_from"]
    default = cli.main(["analytical", "--scene", str(PAPER_SCENE), "--case", "case1", "--json"])
    assert default == 0
    assert "--from-results" in json.loads(capsys.readouterr().out)["settings_from"]
