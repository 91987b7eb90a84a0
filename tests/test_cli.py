"""The command line contract (rps/README.md: one JSON object with ascending frequencies_hz;
exit 2 and one line on bad input) and its behaviour on bad input."""
from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys

import pytest

from tests.conftest import PAPER_SCENE, ROOT


def run(*args, cwd=ROOT):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "rps", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=300)


def test_analytical_json_contract():
    proc = run("analytical", "--scene", str(PAPER_SCENE), "--case", "case1", "--elements", "3",
               "--json")
    assert proc.returncode == 0, proc.stderr
    payload = json.loads(proc.stdout)
    f = payload["frequencies_hz"]
    assert len(f) == 6 and f == sorted(f) and payload["seconds"] > 0
    assert payload["elements"] == 3 and payload["beam"] == "euler-bernoulli"


def test_timoshenko_and_mode_count_options():
    proc = run("analytical", "--case", "case2", "--beam", "timoshenko", "--modes", "9", "--json")
    assert proc.returncode == 0, proc.stderr
    assert len(json.loads(proc.stdout)["frequencies_hz"]) == 9


def test_analytical_keeps_its_solid_end_zones_under_the_cache_it_is_given(tmp_path):
    cache = tmp_path / "cache"
    proc = run("analytical", "--case", "case1", "--beam", "timoshenko", "--joint-ends", "solid",
               "--cache", str(cache), "--json")
    assert proc.returncode == 0, proc.stderr
    assert len(json.loads(proc.stdout)["frequencies_hz"]) == 6
    assert sorted(p.suffix for p in (cache / "joint_ends").iterdir()) == [".json", ".npz"]
    taken = tmp_path / "file"
    taken.write_text("not a directory")
    proc = run("analytical", "--case", "case1", "--joint-ends", "solid", "--cache", str(taken))
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1
    assert "--cache" in proc.stderr


def scene_with(tmp_path, old, new):
    text = PAPER_SCENE.read_text()
    assert old in text
    path = tmp_path / "scene.toml"
    path.write_text(text.replace(old, new))
    return path


@pytest.mark.parametrize("args, needle", [
    (("--case", "case9"), "case 'case9'"),
    (("--elements", "0"), "error: --elements 0: must be >= 1 and <= 200"),
    (("--beam", "bernoulli"), "'bernoulli'"),
])
def test_bad_arguments_exit_2_with_one_line(args, needle):
    proc = run("analytical", *args)
    assert proc.returncode == 2
    assert proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0] and "Traceback" not in proc.stderr


@pytest.mark.parametrize("old, new, needle", [
    ("leg_diameter_mm = 100.0", "leg_diameter_mm = -100.0", "leg_diameter_mm = -100.0"),
    ('height_mm = 490.0', 'height_mm = 1200.0', "outside the actuator range"),
    ("tilt_deg = -12.0\n", "tilt_deg = -70.0\n", "would reach"),
])
def test_bad_scenes_exit_2_with_one_line(tmp_path, old, new, needle):
    path = scene_with(tmp_path, old, new)
    case = "case1_literal" if "height" in old else "case2"
    proc = run("analytical", "--scene", str(path), "--case", case)
    assert proc.returncode == 2, proc.stdout
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], proc.stderr


def test_fem_json_contract(tmp_path):
    proc = run("fem", "--scene", str(PAPER_SCENE), "--case", "case1", "--size", "40", "--json",
               "--vtu", str(tmp_path / "modes.vtu"))
    assert proc.returncode == 0, proc.stderr
    payload = json.loads(proc.stdout)
    f = payload["frequencies_hz"]
    assert len(f) == 6 and f == sorted(f)
    assert payload["mesh_size_mm"] == 40.0 and payload["dofs"] > 1000
    assert set(payload["timings"]) >= {"mesh", "assemble", "solve"}
    assert (tmp_path / "modes.vtu").stat().st_size > 0


def test_fem_refuses_a_size_beyond_the_leg_diameter():
    proc = run("fem", "--case", "case1", "--size", "500")
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: --size 500 mm: coarser than the leg "
                                                   "diameter 100 mm")


def test_validate_refuses_an_unreachable_case_before_any_work(tmp_path):
    path = scene_with(tmp_path, 'height_mm = 490.0', 'height_mm = 1200.0')
    out = tmp_path / "out"
    proc = run("validate", "--scene", str(path), "--out", str(out), "--cache",
               str(tmp_path / "cache"))
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(
        "error: cases.case1_literal.height_mm = 1200 (azimuth_deg = 0, tilt_deg = 0): leg 1")
    assert not out.exists() and not (tmp_path / "cache").exists()


def test_any_pose_can_be_asked_in_millimetres_and_degrees():
    proc = run("analytical", "--case", "case1", "--height", "700", "--azimuth", "30",
               "--tilt", "10", "--json")
    assert proc.returncode == 0, proc.stderr
    payload = json.loads(proc.stdout)
    assert payload["pose"] == {"height_mm": 700.0, "azimuth_deg": 30.0, "tilt_deg": 10.0}
    higher = json.loads(run("analytical", "--case", "case1", "--height", "900", "--azimuth",
                            "30", "--tilt", "10", "--json").stdout)
    assert all(h < f for h, f in zip(higher["frequencies_hz"], payload["frequencies_hz"]))
    proc = run("analytical", "--height", "1700")
    assert proc.returncode == 2 and "--height 1700 mm: leg 1 would be 1702.9 mm long" in proc.stderr


def test_workspace_map_command():
    proc = run("workspace", "--layers", "3", "--rings", "2", "--azimuths", "6", "--json")
    assert proc.returncode == 0, proc.stderr
    payload = json.loads(proc.stdout)
    assert len(payload["heights_mm"]) == 3 and len(payload["frequencies_hz"][0][1]) == 6


@pytest.mark.parametrize("args, needle", [
    (("--elements", "100000"), "--elements 100000: must be >= 1 and <= 200"),
    (("--height", "1e308"), "--height 1e308 mm: must be > 0 and <= 100000 mm"),
])
def test_absurd_values_are_refused_in_one_line(args, needle):
    proc = run("analytical", *args)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], proc.stderr


def test_version_names_the_project_and_its_commit():
    proc = run("--version")
    assert proc.returncode == 0, proc.stderr
    assert re.fullmatch(r"rps-elastodynamics \d+\.\d+\.\d+\S* \(commit [0-9a-f]{7,}(-dirty)?\)",
                        proc.stdout.strip()), proc.stdout


def test_help_lists_every_command_and_every_option_default_and_unit():
    from rps.app import _Help, build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    top = run("--help").stdout
    for name, sub in commands.choices.items():
        assert re.search(rf"^\s+{re.escape(name)}\b", top, re.M), name
        for action in sub._actions:
            if action.option_strings and action.nargs != 0 and action.dest != "help":
                text = _Help("x")._get_help_string(action)
                assert "default" in text, (name, action.option_strings)
            if action.dest in ("height", "size"):
                assert action.metavar == "MM"
            if action.dest in ("azimuth", "tilt"):
                assert action.metavar == "DEG"
    assert "(default: 8)" in run("workspace", "--help").stdout


def test_the_default_scene_does_not_depend_on_the_working_directory(tmp_path):
    proc = run("analytical", "--case", "case1", "--json", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["case"] == "case1"


def test_human_output_is_rounded_and_json_is_exact():
    human = run("analytical", "--case", "case2")
    assert human.returncode == 0, human.stderr
    assert not re.search(r"\d\.\d{6,}", human.stdout), human.stdout
    assert "frequencies_hz: " in human.stdout
    exact = json.loads(run("analytical", "--case", "case2", "--json").stdout)
    shown = re.search(r"frequencies_hz: (.*)", human.stdout).group(1).split(", ")
    assert shown == [f"{f:.2f}" for f in exact["frequencies_hz"]]
    assert any(len(repr(f).split(".")[1]) > 6 for f in exact["frequencies_hz"])


def test_cache_info_and_clear_touch_only_cache_entries(tmp_path):
    from runtime.cache import ResultCache

    cache = tmp_path / "cache"
    ResultCache(cache).put("fem", "0123456789abcdef01234567", {"x": 1})
    (cache / "meshes").mkdir()
    (cache / "meshes" / f"{'ab' * 32}.json").write_text("{}")
    (cache / "meshes" / f"{'ab' * 32}.vtu").write_bytes(b"0" * 1000)
    (cache / "notes.txt").write_text("mine")
    (cache / "fem" / "notes.txt").write_text("mine too")
    (cache / "tmp").mkdir()  # left empty by an earlier run
    info = json.loads(run("cache", "info", "--cache", str(cache), "--json").stdout)
    assert info["entries"] == 2 and info["kinds"]["meshes"]["bytes"] >= 1002
    proc = run("cache", "clear", "--cache", str(cache))
    assert proc.returncode == 0 and "2 entries" in proc.stdout
    assert sorted(p.relative_to(cache).as_posix() for p in cache.rglob("*")) == [
        "fem", "fem/notes.txt", "notes.txt"]
    assert json.loads(run("cache", "info", "--cache", str(cache), "--json").stdout)[
        "entries"] == 0


def test_estimate_error_refuses_a_size_beyond_the_dof_guard_before_any_work(tmp_path):
    proc = run("fem", "--case", "case1", "--size", "3", "--estimate-error", "--cache",
               str(tmp_path / "cache"))
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: --size 3 mm --estimate-error: ")
    assert "max_dofs" in lines[0]
    assert not (tmp_path / "cache").exists()


def test_estimate_error_refines_around_a_size_outside_the_scenes_sequence(tmp_path):
    """The scene refines 40-32-25-20 mm; asked at 50 mm, the study keeps those ratios and starts
    at 50 mm (coarse meshes: seconds)."""
    proc = run("fem", "--case", "case1", "--size", "50", "--estimate-error", "--json",
               "--cache", str(tmp_path / "cache"))
    assert proc.returncode == 0, proc.stderr
    payload = json.loads(proc.stdout)
    assert payload["refinement_mm"] == pytest.approx([50.0, 40.0, 31.25, 25.0])
    assert len(payload["estimated_error_percent"]) == 6


def test_developer_commands_refuse_to_run_outside_a_checkout(monkeypatch, capsys):
    import rps.app as cli
    import rps.args

    monkeypatch.setattr(rps.args, "checkout_root", lambda: None)
    assert cli.main(["scene-docs"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "repository checkout" in err[0]
