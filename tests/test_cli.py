"""The command line contract (DESIGN.md) and its behaviour on bad input."""
from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from tests.conftest import PAPER_SCENE, ROOT


def run(*args, cwd=ROOT):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "pipeline", *args], cwd=cwd, env=env,
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


def scene_with(tmp_path, old, new):
    text = PAPER_SCENE.read_text()
    assert old in text
    path = tmp_path / "scene.toml"
    path.write_text(text.replace(old, new))
    return path


@pytest.mark.parametrize("args, needle", [
    (("--case", "case9"), "case 'case9'"),
    (("--elements", "0"), "0 must be >= 1"),
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
    ("tilt_deg = -12.0\n", "tilt_deg = -70.0\n", "exceeds"),
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
    assert payload["mesh_size_m"] == 0.04 and payload["dofs"] > 1000
    assert set(payload["timings"]) >= {"mesh", "assemble", "solve"}
    assert (tmp_path / "modes.vtu").stat().st_size > 0


def test_fem_refuses_a_size_beyond_the_leg_diameter():
    proc = run("fem", "--case", "case1", "--size", "500")
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "0.5 m" in lines[0]


def test_validate_refuses_an_unreachable_case_before_any_work(tmp_path):
    path = scene_with(tmp_path, 'height_mm = 490.0', 'height_mm = 1200.0')
    out = tmp_path / "out"
    proc = run("validate", "--scene", str(path), "--out", str(out), "--cache",
               str(tmp_path / "cache"))
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines()[-1].startswith("error: case case1_literal: leg 1")
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
    assert proc.returncode == 2 and "1702.939 mm is outside" in proc.stderr


def test_workspace_map_command():
    proc = run("workspace", "--layers", "3", "--rings", "2", "--azimuths", "6", "--json")
    assert proc.returncode == 0, proc.stderr
    payload = json.loads(proc.stdout)
    assert len(payload["heights_mm"]) == 3 and len(payload["frequencies_hz"][0][1]) == 6


@pytest.mark.parametrize("args, needle", [
    (("--elements", "100000"), "elements = 100000"),
    (("--height", "1e308"), "no leg of this manipulator reaches it"),
])
def test_absurd_values_are_refused_in_one_line(args, needle):
    proc = run("analytical", *args)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], proc.stderr
