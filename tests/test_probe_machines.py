"""The probe of issue 34, kept: machines that cannot exist, places that cannot be used, text the
reports cannot show, refusals that named a derived quantity, and a heavy payload that runs with
a warning.

Each refusal is exit status 2 and one line on stderr that names what the user typed (the scene
key or the option and its value) first, before any expensive step: nothing on stdout, no
progress line, no traceback, nothing written, within seconds. The machine rules are those of
`analytical.plausibility` (docs/scenes.md, "Physical consistency").
"""
from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st  # noqa: F401

from analytical import plausibility
from common.errors import InputError
from rps import app as cli
from scene import parse_scene
from tests.conftest import PAPER_SCENE, REPORT_FIXTURE, ROOT, refused

# warnings of numpy or any library never reach the user raw: each is an error here
pytestmark = pytest.mark.filterwarnings("error")

LEGS_SCENE = ROOT / "scenes" / "actuator-legs.toml"
SLENDER_SCENE = ROOT / "scenes" / "slender.toml"


def edited(tmp_path: Path, source: Path, *changes: tuple[str, str]) -> str:
    text = source.read_text(encoding="utf-8")
    for old, new in changes:
        assert old in text, old
        text = text.replace(old, new, 1)
    path = tmp_path / "scene.toml"
    path.write_text(text, encoding="utf-8")
    return str(path)


def everything_under(folder: Path) -> list[str]:
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*"))



# ---------------------------------------------------------------- machines that cannot exist
@pytest.mark.parametrize("changes, needles", [
    ((("rod_outer_diameter_mm = 60.0 ", "rod_outer_diameter_mm = 90.0 "),
      ("actuator_min_mm = 520.0", "actuator_min_mm = 540.0")),
     ("leg.rod_outer_diameter_mm = 90 with housing_inner_diameter_mm = 80", "rod in bore")),
    ((("rod_outer_diameter_mm = 60.0 ", "rod_outer_diameter_mm = 90.0 "),),  # the bore first
     ("leg.rod_outer_diameter_mm = 90", "rod in bore")),
    ((("rod_outer_diameter_mm = 60.0 ", "rod_outer_diameter_mm = 80.0 "),),
     ("leg.rod_outer_diameter_mm = 80 with housing_inner_diameter_mm = 80",
      "expected rod_outer_diameter_mm <= 78")),
    ((("rod_outer_diameter_mm = 60.0 ", "rod_outer_diameter_mm = 150.0 "),
      ("housing_inner_diameter_mm = 80.0", "housing_inner_diameter_mm = 0.0"),
      ("actuator_min_mm = 520.0", "actuator_min_mm = 620.0")),
     ("leg.housing_inner_diameter_mm = 0 (a solid housing)", "leave [leg] out")),
    ((("centre_mm = [0.0, 0.0, 120.0]", "centre_mm = [100000.0, 0.0, 0.0]"),),
     ("payload.centre_mm = [100000.0, 0.0, 0.0]", "payload envelope")),
    ((("centre_mm = [0.0, 0.0, 120.0]", "centre_mm = [0.0, 0.0, -2000.0]"),),
     ("payload.centre_mm = [0.0, 0.0, -2000.0]", "payload envelope")),
    ((("centre_mm = [0.0, 0.0, 120.0]", "centre_mm = [0.0, 0.0, -600.0]"),),  # inside 4 r2
     ("payload.centre_mm = [0.0, 0.0, -600.0]", "below the base plane",
      "payload above the base")),
    ((("inertia_kg_m2 = [0.40, 0.40, 0.25]", "inertia_kg_m2 = [1000.0, 1000.0, 1000.0]"),),
     ("payload.inertia_kg_m2 = [1000.0, 1000.0, 1000.0] with mass_kg = 35",
      "radius of gyration")),
    ((("leg_angles_deg = [0.0, 120.0, 240.0]", "leg_angles_deg = [0.0, 100.0, 240.0]"),),
     ("leg_angles_deg = [0.0, 100.0, 240.0]", "120 degrees apart")),
], ids=["rod in a smaller bore", "rod rule before stroke rule", "rod equal to the bore",
        "rod in a solid housing", "payload 100 m away", "payload through the base",
        "payload below the base at a reachable pose", "payload inertia far out",
        "legs not 120 degrees apart"])
def test_a_machine_that_cannot_exist_is_refused_naming_its_keys(capsys, tmp_path, changes,
                                                                 needles):
    refused(capsys, ["analytical", "--scene", edited(tmp_path, LEGS_SCENE, *changes)],
            *needles)


def test_a_payload_the_legs_cannot_carry_is_refused(capsys, tmp_path):
    scene = edited(tmp_path, SLENDER_SCENE, ("[material]", "[payload]\nmass_kg = 100000.0\n\n"
                                                           "[material]"))
    line = refused(capsys, ["analytical", "--scene", scene], "payload.mass_kg = 100000",
                   "Euler buckling load", "payload weight", "expected at most")
    most = float(line.rsplit("at most ", 1)[1].split(" kg")[0])
    assert 0 < most < 100000.0


def test_a_heavy_but_possible_payload_runs_with_its_warning(capsys, tmp_path):
    # (99 t: the scene's [uncertainty] holds its mass within +-2 kg, below the 100 t limit)
    scene = edited(tmp_path, LEGS_SCENE, ("mass_kg = 35.0", "mass_kg = 99000.0"))
    assert cli.main(["analytical", "--scene", scene, "--json"]) == 0
    out, err = capsys.readouterr()
    payload = json.loads(out)
    [warning] = payload["warnings"]
    assert warning.startswith("payload.mass_kg = 99000 (centre_mm = [0.0, 0.0, 120.0]): the "
                              "weight on the platform loads leg ")
    assert "of its Euler buckling load" in warning and "preload" in warning
    assert err.strip() == f"warning: {warning}"
    assert cli.main(["analytical", "--scene", str(LEGS_SCENE), "--json"]) == 0
    out, err = capsys.readouterr()  # the shipped spindle: no warning
    assert json.loads(out)["warnings"] == [] and err == ""


def test_the_legs_hold_the_weight_by_the_platform_s_equilibrium():
    """Closed form: a mass at o of a level pose of a symmetric machine loads each leg with
    W / (3 cos alpha) and no revolute-joint force; moved towards leg 1 it loads leg 1 more and
    the others less; and the weight rule refuses at the Euler load of the most loaded leg."""
    from dataclasses import replace

    from analytical.pose_batch import pose_batch
    from analytical.reach import level_band
    from common.payload import Payload
    from scene import load_scene

    m = load_scene(SLENDER_SCENE).manipulator
    z = level_band(m).high
    batch = pose_batch(m, [z], [0.0], [0.0])
    cos = batch.leg_frames[0, :, 2, 0]
    forces = plausibility.leg_forces(m, batch, 10.0, (0.0, 0.0, 0.0))[0]
    assert forces == pytest.approx(10.0 * plausibility.GRAVITY / (3 * cos), rel=1e-9)
    toward = plausibility.leg_forces(m, batch, 10.0, (0.5 * m.platform_radius, 0.0, 0.0))[0]
    assert toward[0] > forces[0] > toward[1] and toward[1] == pytest.approx(toward[2])
    vertical = (toward * cos).sum()  # the revolute joints' forces are horizontal here
    assert vertical == pytest.approx(10.0 * plausibility.GRAVITY, rel=1e-9)
    buckling = math.pi**2 * m.material.youngs_modulus * math.pi / 64 * m.leg_diameter**4 / (
        batch.leg_lengths[0, 0] ** 2)
    per_kg = forces[0] / 10.0
    from analytical.platform import platform_mass
    at_buckling = buckling / per_kg - platform_mass(m)
    with pytest.raises(InputError, match="Euler buckling load"):
        plausibility.check(replace(m, payload=Payload(mass=1.01 * at_buckling)))
    [warning] = plausibility.check(replace(m, payload=Payload(mass=0.1 * at_buckling)))
    assert "of its Euler buckling load" in warning


def test_a_payload_far_to_one_side_buckles_the_leg_beneath_it(capsys, tmp_path):
    """5 t at 790 mm (inside the envelope of 4 platform radii) on the slender scene: shared
    evenly it would load a leg to 21 % of its Euler load; the equilibrium puts 1.86 times it
    on leg 1 (the reviewer's independent solve of the same statics)."""
    scene = edited(tmp_path, SLENDER_SCENE, ("[material]", "[payload]\nmass_kg = 5000.0\n"
                                                           "centre_mm = [790.0, 0.0, 0.0]\n\n"
                                                           "[material]"))
    refused(capsys, ["analytical", "--scene", scene], "payload.mass_kg = 5000",
            "leg 1 at", "to 1.86 times its Euler buckling load")


def test_a_platform_too_heavy_for_its_legs_is_refused_without_a_payload(capsys, tmp_path):
    scene = edited(tmp_path, SLENDER_SCENE, ("leg_diameter_mm = 30.0", "leg_diameter_mm = 8.0"),
                   ("platform_thickness_mm = 15.0", "platform_thickness_mm = 200.0"))
    refused(capsys, ["analytical", "--scene", scene], "platform_thickness_mm = 200 with "
            "leg_diameter_mm = 8", "the platform's own weight already buckles it")


def test_an_unreachable_case_is_not_blamed_on_the_payload(capsys, tmp_path):
    scene = edited(tmp_path, LEGS_SCENE, ("centre_mm = [0.0, 0.0, 120.0]",
                                          "centre_mm = [0.0, 0.0, -120.0]"),
                   ("height_mm = 640.0", "height_mm = 100.0"))
    refused(capsys, ["analytical", "--scene", scene, "--case", "level"],
            "cases.level.height_mm = 100")


# ---------------------------------------------------------------- scene values, text, rows
@pytest.mark.parametrize("old, new, needles", [
    ('description = "Case 1: symmetric pose (Table I)"',
     'description = "Case 1:\\u2029 symmetric pose"',
     ("cases.case1.description", "U+2029", "PARAGRAPH SEPARATOR")),
    ('name = "Gong & Lou 2023, 3-RPS"', 'name = "' + "x" * 201 + '"',
     ("name = 'xxxx", "201 characters long, more than 200")),
    ("rim_grading = 1.0", "rim_grading = 1e-300", ("fem.rim_grading = 1e-300", ">= 0.1")),
    ("paper_fea_hz = [114.87,", "paper_fea_hz = [1.0, 114.87,",
     ("cases.case1: the paper's rows differ in length (paper_fea_hz 7,",)),
    ("paper_theory_hz = [115.02, 115.02,", "paper_theory_hz = [115.02,",
     ("cases.case1: the paper's rows differ in length",)),
])
def test_scene_text_and_rows_the_reports_cannot_take_are_refused(capsys, tmp_path, old, new,
                                                                  needles):
    refused(capsys, ["analytical", "--scene", edited(tmp_path, PAPER_SCENE, (old, new))],
            *needles)


def test_a_reason_keeps_its_line_breaks_but_no_control_characters(tmp_path):
    import tomllib
    raw = tomllib.loads(PAPER_SCENE.read_text(encoding="utf-8"))
    raw["calibration"]["height"]["reason"] = "line one\nline two\ttabbed"
    parse_scene(raw)
    raw["calibration"]["height"]["reason"] = "bell \x07"
    with pytest.raises(InputError, match="calibration.height.reason.*U\\+0007"):
        parse_scene(raw)


# ---------------------------------------------------------------- validate: what was typed
@pytest.mark.parametrize("old, new, profile, needles", [
    ("height_mm = 490.0", "height_mm = 1e-300", "ci",
     ("cases.case1_literal.height_mm = 1e-300 (azimuth_deg = 0, tilt_deg = 0): leg 1",)),
    ("value_mm = 543.6", "value_mm = 100.0", "ci",
     ("calibration.height.value_mm = 100 (the height of cases.case1",)),
    ("ci_mesh_size_mm = 40.0", "ci_mesh_size_mm = 0.2", "ci",
     ("fem.ci_mesh_size_mm = 0.2: about", "above max_dofs")),
    ("[fem]  ", "[fem]\nmesh_size_mm = 0.5\n", "full", ("fem.mesh_size_mm = 0.5: about",)),
    ("refinement_mm = [40.0, 32.0, 25.0, 20.0]", "refinement_mm = [40.0, 32.0, 25.0, 2.0]",
     "full", ("fem.refinement_mm = [40.0, 32.0, 25.0, 2.0], its 2 mm mesh: about",)),
], ids=["case height", "calibrated height", "CI mesh", "mesh size", "refinement"])
def test_validate_names_the_scene_key_with_no_progress_line(capsys, tmp_path, old, new, profile,
                                                            needles):
    out, cache = tmp_path / "out", tmp_path / "cache"
    refused(capsys, ["validate", "--scene", edited(tmp_path, PAPER_SCENE, (old, new)), "--out",
                     str(out), "--cache", str(cache), "--profile", profile, "--no-report"],
            *needles)
    assert not out.exists() and not cache.exists()


# ---------------------------------------------------------------- places
@pytest.fixture
def a_file(tmp_path) -> Path:
    path = tmp_path / "a-file"
    path.write_text("not a directory")
    return path


def test_every_place_is_checked_before_the_benchmarks(capsys, tmp_path, a_file, monkeypatch):
    import studies.fem_verification

    def must_not_run(*args, **kwargs):
        raise AssertionError("the benchmarks started before the places were checked")

    monkeypatch.setattr(studies.fem_verification, "verification_record", must_not_run)
    before = everything_under(tmp_path)
    for argv, needles in [
        (["--out", str(a_file)], ("exists and is not a directory",)),
        (["--out", ""], ("--out '': empty",)),
        (["--out", "/proc"], ("--out /proc: holds", "not an output directory")),
        (["--out", "/proc/out"], ("--out /proc/out: cannot write in /proc",)),
        (["--cache", str(a_file / "sub")], ("is a file, not a directory",)),
    ]:
        refused(capsys, ["verify", "--cache", str(tmp_path / "c"), *argv], *needles)
    assert everything_under(tmp_path) == before


@pytest.mark.parametrize("address, needles", [
    ("nonsense", ("--scheduler nonsense: expected host:port",)),
    ("tcp://127.0.0.1:1", ("--scheduler tcp://127.0.0.1:1: no scheduler answers",)),
    ("http://127.0.0.1:8786", ("not a http:// address",)),
])
def test_a_scheduler_is_checked_before_the_scene_is_read(capsys, tmp_path, address, needles):
    out = tmp_path / "out"
    refused(capsys, ["validate", "--scheduler", address, "--out", str(out), "--cache",
                     str(tmp_path / "cache")], *needles, seconds=10.0)
    assert everything_under(tmp_path) == []


def test_an_unusable_cache_is_one_line_in_every_command(capsys, tmp_path, a_file, monkeypatch):
    import runtime.places

    for command in (["fem", "--size", "60"], ["validate", "--out", str(tmp_path / "o")],
                    ["design", "--design", str(ROOT / "designs" / "3prs-head.toml")]):
        refused(capsys, [*command, "--cache", str(a_file / "sub")],
                f"--cache {a_file / 'sub'}: {a_file} is a file")
    monkeypatch.setattr(runtime.places, "MIN_FREE_CACHE", 10**18)  # a full disk
    refused(capsys, ["fem", "--size", "60", "--cache", str(tmp_path / "c")],
            "MB free on its file system")
    assert everything_under(tmp_path) == ["a-file"]


def test_an_output_folder_must_be_writable(capsys, tmp_path):
    refused(capsys, ["validate", "--out", "/proc/out", "--cache", str(tmp_path / "c")],
            "--out /proc/out: cannot write in /proc")
    refused(capsys, ["design", "--design", str(ROOT / "designs" / "3prs-head.toml"),
                     "--report", "/proc/design-out", "--cache", str(tmp_path / "c")],
            "--report /proc/design-out: cannot write in /proc")


# ---------------------------------------------------------------- results files
def test_an_oversized_results_file_or_field_is_refused_at_once(capsys, tmp_path, monkeypatch):
    import results.schema
    from rps.app import main as rps_main

    def main(argv):
        return rps_main(["report", *argv])

    data = json.loads(REPORT_FIXTURE.read_text(encoding="utf-8"))
    data["scene"]["name"] = "x" * 5_000_000
    path = tmp_path / "results.json"
    path.write_text(json.dumps(data))
    start = time.perf_counter()
    code = main(["--results", str(path), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and time.perf_counter() - start < 5.0
    assert err.strip() == (f"error: {path}: scene.name: a text of 5,000,000 characters, more "
                           "than the 10,000 a results file holds in one field")
    refused(capsys, ["readme", "--results", str(path)], "scene.name: a text of 5,000,000")
    monkeypatch.setattr(results.schema, "MAX_BYTES", 1000)
    refused(capsys, ["readme", "--results", str(REPORT_FIXTURE)],
            "larger than any results file")
    assert not (tmp_path / "out").exists()


def test_rps_readme_takes_only_a_whole_full_run(capsys, tmp_path, monkeypatch):
    import reports.readme

    monkeypatch.setattr(reports.readme, "update_readme", lambda *a: pytest.fail("written"))
    data = json.loads(REPORT_FIXTURE.read_text(encoding="utf-8"))
    ci = dict(data, profile="ci")
    (tmp_path / "ci.json").write_text(json.dumps(ci))
    refused(capsys, ["readme", "--results", str(tmp_path / "ci.json")],
            "a run of the ci profile")
    (tmp_path / "full.json").write_text(json.dumps(data))  # its modes/ are not beside it
    refused(capsys, ["readme", "--results", str(tmp_path / "full.json")],
            "which is not beside it")


def test_from_results_of_another_scene_is_refused_naming_both(capsys):
    refused(capsys, ["analytical", "--scene", str(LEGS_SCENE), "--from-results",
                     str(REPORT_FIXTURE)], "a run of scene", "'Gong & Lou 2023, 3-RPS'",
            f"not of --scene {LEGS_SCENE}")


# ---------------------------------------------------------------- the rules on random machines
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(bore=st.floats(40.0, 105.0), rod=st.floats(10.0, 104.0))
def test_the_rod_fits_its_bore_exactly_when_the_rule_says(bore, rod):
    import tomllib
    raw = tomllib.loads(LEGS_SCENE.read_text(encoding="utf-8"))
    raw["leg"].update(housing_inner_diameter_mm=bore, rod_outer_diameter_mm=rod,
                      rod_inner_diameter_mm=0.0)
    raw["manipulator"]["actuator_min_mm"] = 420.0 + 1.2 * rod + 1.0
    raw["manipulator"]["actuator_max_mm"] = raw["manipulator"]["actuator_min_mm"] + 300.0
    if bore - rod >= 2.0 + 1e-9:
        parse_scene(raw)
    elif bore - rod < 2.0 - 1e-9:
        with pytest.raises(InputError, match="rod in bore"):
            parse_scene(raw)


@pytest.mark.parametrize("x, z", [(0.0, 120.0), (0.0, -120.0), (0.0, -400.0), (0.0, -500.0),
                                  (600.0, -300.0), (-800.0, 200.0), (800.0, -100.0),
                                  (300.0, -450.0)])
def test_the_payload_stays_above_the_base_at_every_reachable_pose_it_admits(x, z):
    """Against a brute-force sampling of reachable poses (random heights over the whole reach,
    tilts to 86 degrees, not the rule's grid): a centre the rule admits is above the base at
    every one of them; one it refuses is below the base at one of them, or at the grid's."""
    import tomllib

    from analytical.architectures import height_reach
    from analytical.pose_batch import pose_batch
    raw = tomllib.loads(LEGS_SCENE.read_text(encoding="utf-8"))
    raw["payload"]["centre_mm"] = [x, 0.0, z]
    try:
        m = parse_scene(raw).manipulator
        admitted = True
    except InputError as exc:
        assert "payload above the base" in str(exc), exc
        admitted = False
        from dataclasses import replace

        from common.payload import Payload
        m = replace(parse_scene(tomllib.loads(LEGS_SCENE.read_text(encoding="utf-8")))
                    .manipulator, payload=Payload(mass=35.0, centre=(x * 1e-3, 0.0, z * 1e-3)))
    rng = np.random.default_rng(7)
    n = 40000
    batch = pose_batch(m, rng.uniform(0.0, height_reach(m), n), rng.uniform(0, 2 * np.pi, n),
                       rng.uniform(-1.5, 1.5, n))
    batch = batch.take(batch.feasible)
    assert len(batch) > 100
    centre = np.asarray(m.payload.centre)
    lowest = (batch.platform_centre[:, 2] + batch.rotation[:, 2, :] @ centre).min()
    assert (lowest > 0.0) == admitted or (admitted is False and lowest < 0.02)


def test_the_payload_rule_admits_and_refuses_among_those_centres():
    """The centres above are not all on one side of the rule (the test above can fail)."""
    import tomllib
    outcomes = set()
    for x, z in [(0.0, 120.0), (0.0, -500.0)]:
        raw = tomllib.loads(LEGS_SCENE.read_text(encoding="utf-8"))
        raw["payload"]["centre_mm"] = [x, 0.0, z]
        try:
            parse_scene(raw)
            outcomes.add("admitted")
        except InputError:
            outcomes.add("refused")
    assert outcomes == {"admitted", "refused"}
