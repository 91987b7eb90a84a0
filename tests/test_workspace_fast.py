"""Workspace maps in batches: the same model as the per-pose one, and modes followed by shape
(analytical/pose_batch.py, batch_model.py, tracking.py, workspace.py)."""
from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from analytical.batch_model import assemble_batch
from analytical.batch_solve import batch_frequencies, batch_modes, standard_form
from analytical.kinematics import PoseError, pose_geometry
from analytical.model import natural_frequencies
from analytical.params import Pose
from analytical.pose_batch import pose_batch
from analytical.reach import MAX_TILT, max_tilt, reachable
from analytical.substructure import assemble
from analytical.tracking import match_modes, steps_needing_shapes
from analytical.workspace import frequency_map
from scene import load_scene
from tests.conftest import ROOT

FIELDS = ("rotation", "platform_centre", "base_points", "platform_points", "joint_axes",
          "leg_lengths", "leg_frames", "s_joint_angles", "r_joint_angles")


def machine(name: str, turn_deg: float = 0.0):
    m = load_scene(ROOT / "scenes" / f"{name}.toml").manipulator
    return replace(m, leg_angles=tuple(a + math.radians(turn_deg) for a in m.leg_angles))


def random_poses(n: int, seed: int):
    rng = np.random.default_rng(seed)
    return rng.uniform(0.15, 1.1, n), rng.uniform(-4, 4, n), rng.uniform(-1.0, 1.0, n)


@pytest.mark.parametrize("name, turn", [("paper", 0.0), ("paper-section2", 0.0),
                                        ("stocky", 17.0), ("paper-section2", -41.0)])
def test_batch_kinematics_is_pose_geometry_for_every_pose(name, turn):
    """Every field of every pose within 1e-12 (m, rad) of pose_geometry, and a pose is
    feasible exactly when pose_geometry accepts it (both joint orders, turned layouts)."""
    m = machine(name, turn)
    z, phi, theta = random_poses(1500, seed=len(name))
    batch = pose_batch(m, z, phi, theta)
    accepted = 0
    for n in range(len(z)):
        try:
            geometry = pose_geometry(m, Pose(z[n], phi[n], theta[n]))
        except PoseError:
            assert not batch.feasible[n]
            continue
        accepted += 1
        assert batch.feasible[n]
        twin = batch.geometry(n)
        for field in FIELDS:
            assert np.allclose(getattr(twin, field), getattr(geometry, field), rtol=0,
                               atol=1e-12), field
    assert accepted > 100  # the sample reaches well into the workspace


@pytest.mark.parametrize("name, options", [
    ("paper", dict()),
    ("paper", dict(beam="timoshenko", elements=5, modes=9)),
    ("paper", dict(r_joint_coordinate="paper-eq18", modes=4)),
    ("paper-section2", dict(elements=2, platform_inertia="paper-eq8")),
    ("stocky", dict(beam="timoshenko", shear="hutchinson", elements=1, modes=4)),
])
def test_batch_model_is_the_per_pose_model(name, options):
    """K and M agree with substructure.assemble to 1e-14 of their largest entry, frequencies
    with the per-pose solve to 1e-9 (relative), and the batch's shapes are M-orthonormal to
    1e-10."""
    scene = load_scene(ROOT / "scenes" / f"{name}.toml")
    m, opts = scene.manipulator, replace(scene.analytical, **options)
    batch = pose_batch(m, *random_poses(400, seed=7))
    batch = batch.take(batch.feasible)
    model = assemble_batch(m, batch, opts)
    stiffness, mass = model.stiffness.copy(), model.mass.copy()
    form = standard_form(model)
    hz = batch_frequencies(form, opts.modes)
    hz_v, shapes = batch_modes(form, np.arange(len(batch)), opts.modes)
    for n in range(len(batch)):
        reference = assemble(m, batch.geometry(n), opts)
        assert np.abs(stiffness[n] - reference.stiffness).max() < 1e-14 * np.abs(
            reference.stiffness).max()
        assert np.abs(mass[n] - reference.mass).max() < 1e-14 * np.abs(reference.mass).max()
        f = natural_frequencies(m, Pose(batch.heights[n], batch.azimuths[n], batch.tilts[n]),
                                opts)
        assert np.allclose(hz[n], f, rtol=1e-9, atol=0) and np.allclose(hz_v[n], f, rtol=1e-9)
        gram = shapes[n].T @ mass[n] @ shapes[n]
        assert np.abs(gram - np.eye(opts.modes)).max() < 1e-10


@pytest.fixture(scope="module")
def small_map(scene):
    return frequency_map(scene.manipulator, replace(scene.analytical, modes=4),
                         [0.3, 0.55, 0.8, 1.3], rings=3, azimuths=10, workers=1)


def test_map_frequencies_are_the_per_pose_frequencies_at_every_pose(scene, small_map):
    """Every reachable pose of the map within 1e-9 of natural_frequencies; NaN exactly where
    the pose is unreachable (the 1.3 m layer is above every leg)."""
    fmap, opts = small_map, replace(scene.analytical, modes=4)
    for iz, z in enumerate(fmap.heights):
        for ir, tilt in enumerate(fmap.tilts[iz]):
            for ip, phi in enumerate(fmap.azimuths):
                pose = Pose(z, phi, tilt)
                f = fmap.frequencies_hz[iz, ir, ip]
                if reachable(scene.manipulator, pose):
                    ref = natural_frequencies(scene.manipulator, pose, opts)
                    assert np.allclose(f, ref, rtol=1e-9, atol=0)
                else:
                    assert np.isnan(f).all()
    assert np.isnan(fmap.frequencies_hz[3]).all() and np.isfinite(fmap.frequencies_hz[:3]).all()


def test_map_on_two_processes_is_the_map_on_one(scene, small_map):
    two = frequency_map(scene.manipulator, replace(scene.analytical, modes=4),
                        [0.3, 0.55, 0.8, 1.3], rings=3, azimuths=10, workers=2)
    assert np.array_equal(two.frequencies_hz, small_map.frequencies_hz, equal_nan=True)
    assert np.array_equal(two.tracked_hz, small_map.tracked_hz, equal_nan=True)
    assert two.crossings == small_map.crossings and two.tracking == small_map.tracking


def test_batch_bisection_lands_where_a_pose_by_pose_bisection_lands(scene):
    """max_tilt (all azimuths of a layer at once) equals the bisection on pose_geometry."""
    def scalar(z, phi, tolerance=1e-6):
        if not reachable(scene.manipulator, Pose(z, phi, 0.0)):
            return 0.0
        lo, hi = 0.0, MAX_TILT
        if reachable(scene.manipulator, Pose(z, phi, hi)):
            return hi
        while hi - lo > tolerance:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if reachable(scene.manipulator, Pose(z, phi, mid)) else (lo, mid)
        return lo

    for z, phi in [(0.3, 0.0), (0.55, 0.4), (0.8, 2.0), (0.95, -1.0), (1.3, 0.0)]:
        assert max_tilt(scene.manipulator, z, phi) == scalar(z, phi)


def test_a_crossing_of_two_families_shows_as_a_crossing(scene):
    """Level poses keep the three-fold symmetry, so families of different symmetry cross
    exactly as the height changes: on the paper's machine the second repeated pair (f5, f6 at
    the root) falls through a threefold leg mode near z = 248.5 mm. Sorted, modes 5-9 kink
    there (their slope changes by over 40 % between steps); followed by shape, every family's
    slope changes by less than 10 % per step, and the crossing is listed between the layers."""
    heights = np.linspace(0.225, 0.275, 9)
    fmap = frequency_map(scene.manipulator, replace(scene.analytical, modes=9), heights,
                         rings=2, azimuths=24, workers=1)

    def worst_slope_change(values):
        slope = np.diff(values, axis=0)
        return np.max(np.abs(np.diff(slope, axis=0) / slope[:-1]), axis=0)

    assert worst_slope_change(fmap.frequencies_hz[:, 0, 0, :]).max() > 0.4
    assert worst_slope_change(fmap.tracked_hz[:, 0, 0, :]).max() < 0.1
    level = [c for c in fmap.crossings if c.along == "height"]
    assert {c.families for c in level} == {(a, b) for a in (4, 5) for b in (6, 7, 8)}
    assert all(heights[3] < c.height < heights[4] and c.tilt == 0.0 for c in level)


def test_a_repeated_pair_is_matched_as_a_subspace():
    """A repeated pair splitting into two modes: any basis of the pair is as good, so its
    members go to the two split modes in ascending order with subspace MAC 1."""
    rng = np.random.default_rng(3)
    basis = np.linalg.qr(rng.standard_normal((30, 4)))[0]
    turn = np.array([[math.cos(0.7), -math.sin(0.7)], [math.sin(0.7), math.cos(0.7)]])
    source = basis.copy()
    target = basis.copy()
    target[:, 1:3] = basis[:, 1:3] @ turn  # the pair's basis turned by 40 degrees
    target_order = [0, 2, 1, 3]  # and listed the other way round
    where, mac = match_modes(source, np.array([100.0, 200.0, 200.0, 300.0]),
                             target[:, target_order], np.array([100.0, 199.0, 201.0, 300.0]))
    assert where.tolist() == [0, 1, 2, 3] and np.allclose(mac, 1.0)


def test_only_steps_that_can_hide_a_crossing_need_shapes():
    """Two lines crossing between samples: the steps around the crossing need shapes, the
    steps where the gap exceeds what the lines move do not."""
    t = np.linspace(0.0, 1.0, 11)
    crossing = np.stack([100 + 20 * t, 110 - 5 * t + 0.0 * t, 200 + 0 * t], axis=1)
    sorted_hz = np.sort(crossing, axis=1)
    need = steps_needing_shapes(sorted_hz)
    swap = np.flatnonzero(np.diff(np.argsort(crossing, axis=1)[:, 0]) != 0)[0]
    assert need[swap] and not need[0] and not need[-1]
    apart = np.stack([100 + 2 * t, 150 + 3 * t, 200 + t], axis=1)
    assert not steps_needing_shapes(apart).any()
    assert steps_needing_shapes(apart, closed=True).shape == (11,)


def test_workspace_map_results_name_families_and_crossings(scene):
    from studies.workspace_map import workspace_map

    result = workspace_map(scene, layers=3, rings=3, azimuths=12, modes=3)
    json.dumps(result, allow_nan=False)
    assert np.shape(result["tracked_frequencies_hz"]) == np.shape(result["frequencies_hz"])
    assert set(result["tracking"]) >= {"root_height_mm", "steps", "steps_matched_by_shape",
                                       "min_mac", "lost_families", "open_rings"}
    assert isinstance(result["crossings"], list)
