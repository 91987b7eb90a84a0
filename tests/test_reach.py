"""The reachable workspace, one definition: Eq. (25) and no interpenetration, for one pose
(pose_geometry raises) and for many (pose_batch.feasible) alike; the level band in closed form
where one limit binds; a bounded sampler."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from analytical.kinematics import PoseError, _segment_distance, clearances, pose_geometry
from analytical.params import Pose
from analytical.pose_batch import pose_batch
from analytical.reach import LAYER_INSET, layer_band, level_band, max_tilts, sample_poses


def test_segment_distance_matches_a_dense_sampling_of_both_segments():
    rng = np.random.default_rng(3)
    p1, q1, p2, q2 = (rng.normal(size=(200, 3)) for _ in range(4))
    exact = _segment_distance(p1, q1, p2, q2)
    s = np.linspace(0.0, 1.0, 401)
    for k in range(0, 200, 20):
        a = p1[k] + np.outer(s, q1[k] - p1[k])
        b = p2[k] + np.outer(s, q2[k] - p2[k])
        sampled = np.min(np.linalg.norm(a[:, None] - b[None], axis=2))
        assert exact[k] <= sampled + 1e-12
        assert sampled - exact[k] < 1e-2 * max(np.linalg.norm(q1[k] - p1[k]), 1.0)


def test_parallel_and_crossing_segments_have_their_closed_form_distance():
    z = np.zeros(3)
    x, y = np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    parallel = _segment_distance(z[None], x[None], (z + 0.3 * y)[None], (x + 0.3 * y)[None])
    crossing = _segment_distance((-x)[None], x[None], (-y + [0, 0, 0.2])[None],
                                 (y + [0, 0, 0.2])[None])
    assert parallel[0] == pytest.approx(0.3) and crossing[0] == pytest.approx(0.2)


def test_the_plate_dips_below_the_base_where_its_lowest_rim_point_does(manipulator):
    """A disk of radius r2 and thickness h tilted by theta reaches down r2 sin theta +
    (h / 2) cos theta below its centre."""
    m = manipulator
    pose = Pose(0.25, 0.0, math.radians(40.0))
    g = pose_geometry(m, pose, check_limits=False)
    lowest = clearances(m, g.base_points, g.platform_points, g.rotation,
                        g.platform_centre)["base"][0]
    t = pose.tilt
    assert lowest == pytest.approx(g.platform_centre[2] - m.platform_radius * math.sin(t)
                                   - 0.5 * m.platform_thickness * math.cos(t), abs=1e-12)
    low = replace(m, actuator_min=0.05, s_joint_max=math.radians(89.0),
                  r_joint_max=math.radians(89.0))
    below = Pose(0.06, math.radians(60.0), math.radians(20.0))
    with pytest.raises(PoseError, match="below the base plane"):
        pose_geometry(low, below)
    assert not pose_batch(low, below.height, below.azimuth, below.tilt).feasible[0]


def test_thick_legs_that_would_touch_make_the_pose_unreachable_in_both_forms(manipulator):
    """Legs 300 mm thick on joint circles of 200 mm (joints 346 mm apart) touch once the
    platform tilts far enough at a low height: along a tilt path the leg clearance turns
    negative, and from there neither pose_batch nor pose_geometry accepts the pose."""
    m = replace(manipulator, base_radius=0.2, platform_radius=0.2, leg_diameter=0.3,
                actuator_min=0.05, s_joint_max=math.radians(80.0),
                r_joint_max=math.radians(80.0))
    tilts = np.radians(np.linspace(0.0, 50.0, 201))
    batch = pose_batch(m, 0.165, math.radians(45.0), tilts)
    gaps = clearances(m, batch.base_points, batch.platform_points, batch.rotation,
                      batch.platform_centre)["legs"]
    touching = gaps < 0
    assert touching.any() and not touching[0]
    assert not np.any(batch.feasible & touching)
    k = int(np.flatnonzero(touching)[0])
    with pytest.raises(PoseError, match="two legs would touch"):
        pose_geometry(m, Pose(0.165, math.radians(45.0), float(tilts[k])))


def test_the_level_band_of_the_paper_machine_is_its_actuator_range(manipulator):
    """The paper's machine: the level leg is sqrt(z^2 + (r1 - r2)^2) long and the joint limits
    (45 deg against a lean of 100 mm) bind only below z = 100 mm, so L_min and L_max bound the
    band; the layers keep 5 % of L_max from each end."""
    m = manipulator
    lean = m.base_radius - m.platform_radius
    band = level_band(m)
    assert band.low == pytest.approx(math.sqrt(m.actuator_min**2 - lean**2), abs=1e-11)
    assert band.high == pytest.approx(math.sqrt(m.actuator_max**2 - lean**2), abs=1e-11)
    assert (band.binding_low, band.binding_high) == ("actuator_min_mm", "actuator_max_mm")
    low, high = layer_band(m)
    assert low - band.low == pytest.approx(LAYER_INSET * m.actuator_max)
    assert band.high - high == pytest.approx(LAYER_INSET * m.actuator_max)


def test_a_narrow_band_keeps_its_layers_inside_it(manipulator):
    m = replace(manipulator, actuator_min=0.95, actuator_max=1.0)
    band = level_band(m)
    low, high = layer_band(m)
    assert band.low < low < high < band.high
    assert low - band.low == pytest.approx(0.25 * band.width)


def test_the_sampler_is_bounded_on_a_machine_that_hardly_tilts(manipulator):
    """R joints at their level angle plus 0.5 degrees: every draw with a real tilt is refused,
    and the sampler still returns (reachable poses, no endless loop)."""
    m = manipulator
    lean = m.base_radius - m.platform_radius
    z = 0.6
    tight = replace(m, r_joint_max=math.atan2(lean, z) + math.radians(0.5),
                    s_joint_max=math.atan2(lean, z) + math.radians(0.5),
                    actuator_min=math.hypot(z, lean) - 1e-3,
                    actuator_max=math.hypot(z, lean) + 1e-3)
    poses = sample_poses(tight, 20, np.random.default_rng(0))
    assert 1 <= len(poses) <= 20
    for p in poses:
        pose_geometry(tight, p)
    assert float(np.max(max_tilts(tight, z, np.linspace(0, 2 * math.pi, 12)))) < 0.1


def test_the_lookahead_bisection_is_plain_bisection_within_its_tolerance():
    """max_tilts halves several times per batch for few (height, azimuth) pairs: the same
    midpoints and decisions as one halving per batch, so the same tilts within the
    bisection's tolerance (the batches differ in shape: not the same vector path)."""
    from pathlib import Path

    import analytical.reach as reach
    from scene import load_scene

    m = load_scene(Path(__file__).resolve().parents[1] / "scenes" / "paper.toml").manipulator
    band = reach.level_band(m)
    rng = np.random.default_rng(5)
    heights = rng.uniform(band.low - 0.05, band.high + 0.05, 3)
    phis = rng.uniform(0.0, 7.0, 2)
    for tolerance in (1e-6, 1e-10):
        ahead = reach.max_tilts(m, heights[:1], phis[:1], tolerance)
        both = reach.max_tilts(m, heights, phis, tolerance)
        try:
            reach.LOOKAHEAD_POSES = 1  # one halving per batch: plain bisection
            plain = reach.max_tilts(m, heights, phis, tolerance)
        finally:
            reach.LOOKAHEAD_POSES = 64
        # batches of other shapes may round the kinematics differently in the last bit
        # (tests/README.md), which may flip one bisection step: equal within the tolerance
        assert np.abs(both - plain).max() <= tolerance
        assert abs(ahead[0] - plain[0, 0]) <= tolerance
