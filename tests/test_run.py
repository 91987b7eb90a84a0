"""The validation run: staged outputs, nothing half-written when a run is interrupted."""
from __future__ import annotations

import json

import numpy as np
import pytest

import pipeline.run as run
from results import SCHEMA_VERSION
from tests.conftest import PAPER_SCENE, copied

pytestmark = pytest.mark.slow  # whole validation runs (CI profile): tens of seconds each


def test_interrupted_run_leaves_previous_outputs_intact(tmp_path, monkeypatch, paper_ci_run):
    out = tmp_path / "out"
    out.mkdir()
    (out / "results.json").write_text('{"previous": true}')
    calls = []
    real = run.run_case

    def interrupt_on_second(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(run, "run_case", interrupt_on_second)
    copied(paper_ci_run.cache, tmp_path / "cache")  # warm: the interruption is the point
    with pytest.raises(KeyboardInterrupt):
        run.validate(str(PAPER_SCENE), out, tmp_path / "cache", profile="ci")
    assert json.loads((out / "results.json").read_text()) == {"previous": True}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cache", "out"]  # no staging left
    assert sorted(p.name for p in out.iterdir()) == ["results.json"]


def test_ci_profile_run_writes_the_contract(paper_ci_run):
    out, results = paper_ci_run.out, paper_ci_run.results
    # every cache under the run's cache directory: the fidelity step assembles solid end zones
    assert list((paper_ci_run.cache / "joint_ends").glob("*.npz"))
    assert not paper_ci_run.default_zones.exists()
    on_disk = json.loads((out / "results.json").read_text())
    assert [c["name"] for c in on_disk["cases"]] == ["case1", "case2"]
    for case in on_disk["cases"]:
        for model in ("analytical", "fem"):
            f = case[model]["frequencies_hz"]
            assert len(f) == 6 and f == sorted(f) and case[model]["timings"]
        assert {"analytical_mode", "fem_mode", "mac", "error_percent"} <= set(case["pairs"][0])
        assert len(case["paper"]["theory_hz"]) == 6
    assert (out / "tables" / "case1.csv").read_text().startswith("mode,paper_fea_hz")
    assert (out / "modes" / "case2_fem.vtu").stat().st_size > 0
    assert results["cases"][0]["pose"]["height_origin"] == "calibrated"
    assert on_disk["schema"] == SCHEMA_VERSION and on_disk["environment"]["project_version"]
    assert on_disk["studies"]["height_calibration"]["case"] == "case1"  # calibrated, with rows
    assert [s["case"] for s in on_disk["studies"]["angle_conventions"]] == ["case2"]  # tilted
    # the chosen setting's stated worst error covers every workspace-validation pose, not only
    # the cases and the pose where the best candidate is worst
    fidelity, study = on_disk["fidelity"], on_disk["studies"]["workspace_validation"]
    chosen = fidelity["analytical"]["setting"]
    assert study["default_model"] == chosen
    everywhere = max(abs(e) for p in study["poses"] if p.get("models")
                     for e in p["models"][chosen] if e is not None)
    assert everywhere <= fidelity["analytical"]["worst_error_percent"] + 1e-9


def test_exported_platform_motion_moves_the_platform_joints_as_the_legs_end(paper_ci_run):
    """Each model's platform motion per mode (translation of o, rotation) carries the S joints
    of the platform exactly where the beam model's leg axes end: u(A_i) = t + w x (A_i - o)."""
    results = json.loads((paper_ci_run.out / "results.json").read_text())
    for case in results["cases"]:
        a = case["analytical"]
        motion = np.asarray(a["platform_motion"])
        top = np.asarray(case["pose"]["platform_points_mm"]) * 1e-3
        centre = np.asarray(case["pose"]["centre_mm"]) * 1e-3
        ends = np.asarray(a["leg_axis_shapes"])[:, -1]  # (legs, 3, modes)
        moved = motion[None, :3] + np.cross(motion[3:].T[None], (top - centre)[:, None]
                                            ).transpose(0, 2, 1)
        assert np.allclose(moved, ends, atol=1e-9 * np.abs(ends).max())
        assert np.asarray(case["fem"]["platform_motion"]).shape == motion.shape


def test_the_ci_profile_checks_every_case_of_the_scene_before_any_work(tmp_path):
    """A case outside the CI profile is still the user's: an unreachable one refuses the run
    up front, in one line naming it, with nothing written."""
    text = PAPER_SCENE.read_text(encoding="utf-8") + (
        '\n[cases.unreachable]\ndescription = "too high"\nheight_mm = 5000.0\n')
    scene = tmp_path / "scene.toml"
    scene.write_text(text, encoding="utf-8")
    with pytest.raises(ValueError) as info:
        run.validate(str(scene), tmp_path / "out", tmp_path / "cache", profile="ci")
    assert str(info.value).startswith("cases.unreachable.height_mm = 5000 (azimuth_deg = 0, "
                                      "tilt_deg = 0): leg 1") and "\n" not in str(info.value)
    assert not (tmp_path / "out").exists() and not (tmp_path / "cache").exists()
