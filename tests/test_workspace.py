"""Workspace maps: the paper's observations (Fig. 6) as properties of the model."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from analytical.model import natural_frequencies
from analytical.params import Pose
from analytical.reach import max_tilt, reachable, regular_radius
from analytical.workspace import frequency_map


def test_frequencies_have_the_threefold_symmetry_of_the_mechanism(scene):
    opts = replace(scene.analytical, modes=6)
    for phi in (0.1, 0.7, 2.0):
        f = [natural_frequencies(scene.manipulator, Pose(0.6, phi + k * 2 * math.pi / 3, 0.2),
                                 opts) for k in range(3)]
        assert np.allclose(f[0], f[1], rtol=1e-9) and np.allclose(f[0], f[2], rtol=1e-9)


def test_frequencies_fall_as_the_platform_rises(scene):
    fmap = frequency_map(scene.manipulator, replace(scene.analytical, modes=3),
                         [0.35, 0.55, 0.75], rings=3, azimuths=6)
    level = fmap.frequencies_hz[:, 0, 0, :]
    assert np.all(np.diff(level, axis=0) < 0)
    assert np.all(np.isfinite(fmap.frequencies_hz))


def test_regular_radius_is_reachable_everywhere_and_tight(scene):
    m = scene.manipulator
    z = 0.55
    radius = regular_radius(m, z, azimuths=36)
    assert 0 < radius < math.radians(89)
    for phi in np.linspace(0, 2 * math.pi, 36, endpoint=False):
        assert reachable(m, Pose(z, phi, radius * 0.999))
    widest = [max_tilt(m, z, phi) for phi in np.linspace(0, 2 * math.pi, 36, endpoint=False)]
    assert min(widest) == radius


def test_unreachable_height_has_an_empty_layer(scene):
    assert regular_radius(scene.manipulator, 1.5) == 0.0


from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st

from analytical.kinematics import PoseError  # noqa: E402


@settings(max_examples=80, deadline=None)
@given(st.floats(0.2, 1.0), st.floats(-math.pi, math.pi), st.floats(-1.2, 1.2))
def test_every_reachable_pose_has_finite_positive_ascending_frequencies(scene, z, phi, theta):
    """Numerical stability over the whole workspace, joint-limit edges included."""
    pose = Pose(z, phi, theta)
    try:
        f = natural_frequencies(scene.manipulator, pose, replace(scene.analytical, modes=8))
    except PoseError:
        assert not reachable(scene.manipulator, pose)
        return
    assert np.all(np.isfinite(f)) and f[0] > 0 and np.all(np.diff(f) >= 0)


def test_the_map_record_gives_each_pose_its_actuators_and_joint_angles(scene):
    """The map's per-pose legs and joint angles (the report's hover) are those of the
    per-pose kinematics at the same height, tilt and azimuth, and absent exactly where the
    map has no frequency."""
    from analytical.kinematics import pose_geometry
    from studies.workspace_map import workspace_map

    ws = workspace_map(scene, layers=3, rings=3, azimuths=5)
    checked = 0
    for iz, layer in enumerate(ws["frequencies_hz"]):
        for r, ring in enumerate(layer):
            for a, f in enumerate(ring):
                values = [ws[k][iz][r][a] for k in ("actuation_mm", "s_joint_angles_deg",
                                                     "r_joint_angles_deg")]
                if f is None:
                    assert values == [None] * 3
                    continue
                g = pose_geometry(scene.manipulator, Pose(ws["heights_mm"][iz] * 1e-3,
                                                          math.radians(ws["azimuths_deg"][a]),
                                                          math.radians(ws["tilts_deg"][iz][r])))
                assert np.allclose(values[0], g.actuation * 1e3, rtol=0, atol=1e-9)
                assert np.allclose(values[1], np.degrees(g.s_joint_angles), rtol=0, atol=1e-9)
                assert np.allclose(values[2], np.degrees(g.r_joint_angles), rtol=0, atol=1e-9)
                checked += 1
    assert checked >= 3 * (1 + 2 * 5) - 5
