"""The run's milling-stability studies on the 3-PRS spindle head (scenes/3prs-head.toml and its
[cutting]): a case's lobes of the analytical model against the FEM's (studies/lobes.py), the
stability map over the workspace (studies/stability_map.py) against the one-pose command, and
the report's charts of both."""
from __future__ import annotations

import json
import math
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from analytical.kinematics import pose_geometry
from scene import load_scene
from tests.conftest import ROOT

HEAD = ROOT / "scenes" / "3prs-head.toml"


@pytest.fixture(scope="module")
def head():
    scene = load_scene(HEAD)
    return replace(scene, cutting=replace(scene.cutting, speeds=40))


def test_case_lobes_of_the_model_meet_the_fems(head, tmp_path):
    """At the level case: the analytical model's least critical depth within 3 % of the
    FEM's (measured 1.2 % at 400 speeds), at the same speed; the FEM's two meshes agree on it
    within 0.5 % (measured 0.003 %); the record is the declared one and the chart draws it."""
    from reports.interactive_lobes import case_lobes as chart
    from runtime.cache import ResultCache
    from studies import STUDIES
    from studies.lobes import case_lobes

    geometry = pose_geometry(head.manipulator, head.case("level").pose)
    record = case_lobes(head, geometry, ResultCache(tmp_path / "cache"))
    study = next(s for s in STUDIES if s.key == "lobes")
    study.record.checked(record, "case level")
    an, fem = record["summary"]
    assert an["least_rpm"] == fem["least_rpm"]
    assert abs(an["error_percent"]) < 3.0
    assert fem["fem_error_percent"] < 0.5
    assert len(record["spindle_rpm"]) == 40
    assert chart(record, "level") is not None


def test_stability_map_is_the_one_pose_lobes_at_every_pose(head, tmp_path):
    """The map (batched model, one thinned grid) at each reached pose equals `rps lobes` of the
    scene at that pose (the per-pose model) within the stated discretisation error, and its
    least over the map is the least of its poses."""
    from reports.interactive_lobes import stability_map as chart
    from studies import STUDIES
    from studies.stability_map import stability_map

    record = stability_map(head, layers=1, rings=2, azimuths=3)
    study = next(s for s in STUDIES if s.key == "stability_map")
    study.record.checked(record, "results")
    assert record["poses"] >= 4 and record["speeds"] == 40
    (scene_file := tmp_path / "head.toml").write_text(
        HEAD.read_text().replace("speeds = 400", "speeds = 40"))
    layer = record["least_depth_mm"][0]
    checked = 0
    for r, ring in enumerate(layer):
        for a, depth in enumerate(ring):
            if depth is None or (r == 0 and a > 0):
                continue
            out = tmp_path / f"p{r}{a}"
            p = subprocess.run(
                [sys.executable, "-m", "rps", "lobes", "--scene", str(scene_file),
                 "--height", f"{record['heights_mm'][0]:.9f}",
                 "--tilt", f"{record['tilts_deg'][0][r]:.9f}",
                 "--azimuth", f"{record['azimuths_deg'][a]:.9f}", "--out", str(out),
                 "--json"], capture_output=True, text=True, cwd=tmp_path)
            assert p.returncode == 0, p.stderr
            one = json.loads(p.stdout)
            assert one["least"]["depth_mm"] == pytest.approx(
                depth, rel=max(one["max_error_percent"], 1e-3) / 100)
            checked += 1
    assert checked >= 3
    least = min(v for ring in layer for v in ring if v is not None)
    assert record["least"][0]["depth_mm"] == pytest.approx(least, rel=1e-12)
    assert math.isfinite(record["estimated_seconds"]) and record["estimated_seconds"] > 0
    assert chart(record) is not None
    assert np.isfinite(record["max_error_percent"])


def test_frf_file_feeds_the_same_lobes_as_the_scene(tmp_path):
    """`rps frf` then `rps lobes --tool-modes frf.json --cutting` (the frf.json's base-frame
    modes turned into the cut's plane with its platform rotation) gives the diagram `rps lobes
    --scene` gives at the same pose, speed by speed; with the feed turned by 180 degrees too."""
    scene_text = HEAD.read_text().replace("speeds = 400", "speeds = 24")
    (tmp_path / "head.toml").write_text(scene_text)
    cut = scene_text[scene_text.index("[cutting]"):]
    (tmp_path / "cut.toml").write_text(cut.replace('feed_direction_deg = 0.0',
                                                   'feed_direction_deg = 180.0'))

    def rps(*args):
        p = subprocess.run([sys.executable, "-m", "rps", *args], capture_output=True,
                           text=True, cwd=tmp_path)
        assert p.returncode == 0, p.stderr
        return json.loads(p.stdout) if "--json" in args else None

    pose = ("--case", "tilted")
    rps("frf", "--scene", "head.toml", *pose, "--out", "frf", "--json")
    direct = rps("lobes", "--scene", "head.toml", *pose, "--out", "a", "--json")
    via = rps("lobes", "--tool-modes", "frf/frf.json", "--cutting", "cut.toml", "--out", "b",
              "--json")
    assert direct["spindle_rpm"] == via["spindle_rpm"]
    assert np.allclose(direct["critical_depth_mm"], via["critical_depth_mm"], rtol=1e-6)


UNCERTAIN = """
[uncertainty]
samples = 64
"stiffness.actuator_axial_n_per_um" = { distribution = "lognormal", cv_percent = CV }
"stiffness.platform_joint_translational_n_per_um" = { distribution = "lognormal", cv_percent = CV }
"payload.mass_kg" = { distribution = "uniform", plus_minus = PM }
"""


def _uncertain_head(tmp_path, cv: float, pm: float):
    path = tmp_path / f"head-{cv:g}.toml"
    path.write_text(HEAD.read_text().replace("speeds = 400", "speeds = 30")
                    + UNCERTAIN.replace("CV", f"{cv:g}").replace("PM", f"{pm:g}"))
    return load_scene(path)


def test_band_of_barely_uncertain_inputs_is_the_machines_own_lobes(tmp_path):
    """An input that barely moves (the 30 kg payload +-1 mg): every quantile of the band is
    the scene's own machine's depth within the draws' stated level error (they run at the
    coarse level of intervals, the machine at the fine one), at every speed."""
    from runtime.cache import ResultCache
    from studies.lobes import lobe_band

    path = tmp_path / "head-tight.toml"
    path.write_text(HEAD.read_text().replace("speeds = 400", "speeds = 30")
                    + UNCERTAIN.split('"stiffness')[0]
                    + '"payload.mass_kg" = { distribution = "uniform", plus_minus = 1e-6 }\n')
    scene = load_scene(path)
    band = lobe_band(scene, scene.case("level").pose, ResultCache(tmp_path / "c"), samples=16)
    assert band["refused"] is None and len(band["spindle_rpm"]) == 30
    level = band["level_error_percent"] / 100
    assert 0 < level < 0.01
    own = np.array(band["nominal_depth_mm"], float)
    for key in ("q025_depth_mm", "median_depth_mm", "q975_depth_mm"):
        assert np.allclose(np.array(band[key], float), own, rtol=level * 1.01 + 1e-4), key
    # by the zero-order method the draws are full diagrams (no levels): the same to 1e-4
    zoa = replace(scene, cutting=replace(scene.cutting, method="zoa"))
    band = lobe_band(zoa, zoa.case("level").pose, ResultCache(tmp_path / "z"), samples=8)
    assert band["refused"] is None and band["level_error_percent"] is None
    assert np.allclose(np.array(band["median_depth_mm"], float),
                       np.array(band["nominal_depth_mm"], float), rtol=1e-4)


def test_band_of_uncertain_joints_holds_the_machine_and_states_its_draws(tmp_path, monkeypatch):
    """Joints and payload uncertain (cv 15 %, +-3 kg): the band is the declared record, its
    quantiles ordered at every speed, the scene's machine's least depth inside the draws'
    2.5-97.5 % range, and the stated interval of the 2.5 % quantile holds it; the chart
    draws the band."""
    from reports.interactive_lobes import case_lobes as chart
    from runtime.cache import ResultCache
    from studies import STUDIES
    from studies.lobes import case_lobes

    scene = _uncertain_head(tmp_path, 15.0, 3.0)
    geometry = pose_geometry(scene.manipulator, scene.case("level").pose)
    monkeypatch.setattr("studies.lobes.BAND_SAMPLES", 32)
    record = case_lobes(scene, geometry, ResultCache(tmp_path / "c"), scene.case("level").pose)
    next(s for s in STUDIES if s.key == "lobes").record.checked(record, "case level")
    band = record["band"]
    assert band is not None and band["refused"] is None and band["samples"] == 32
    q = np.array([band[k] for k in ("q025_depth_mm", "median_depth_mm", "q975_depth_mm")],
                 float)
    assert (np.diff(q, axis=0) >= 0).all()
    assert band["least_q025_mm"] <= band["least_nominal_mm"] <= band["least_q975_mm"]
    lo, hi = band["least_q025_interval_mm"]
    assert lo is None and hi >= band["least_q025_mm"]  # 32 draws: no lower bound
    assert band["least_q975_mm"] > band["least_q025_mm"]  # the joints move the lobes
    fig = chart(record, "level")
    assert fig is not None and any("95 %" in (t.name or "") for t in fig.data)


def test_order_statistics_hold_the_quantile_as_often_as_they_say():
    """quantile_interval: over 4,000 fresh sets of draws of a known distribution, the stated
    order statistics hold its 2.5 % quantile at least 95 % of the time (distribution-free),
    and need at least 146 draws to bound it from below."""
    from studies.lobes import quantile_interval

    rng = np.random.default_rng(7)
    for n in (160, 256):
        lo, hi = quantile_interval(n, 0.025)
        assert 1 <= lo < hi <= n
        x = np.sort(rng.standard_normal((4000, n)), axis=1)
        xi = -1.959963984540054
        held = (x[:, lo - 1] <= xi) & (x[:, hi - 1] > xi)
        assert held.mean() >= 0.95
    assert quantile_interval(145, 0.025)[0] == 0 and quantile_interval(146, 0.025)[0] == 1
