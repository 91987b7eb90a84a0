"""Inverse kinematics, Eqs. (1)-(3) and (25) (analytical/kinematics.py)."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from analytical.kinematics import PoseError, pose_geometry, tilt_torsion_rotation
from analytical.params import Pose

angles = st.floats(-math.pi, math.pi, allow_nan=False)
tilts = st.floats(-0.5, 0.5, allow_nan=False)


def eq1_as_printed(phi, theta):
    c, s = math.cos, math.sin
    return np.array([
        [c(phi) ** 2 * c(theta) + s(phi) ** 2, c(phi) * c(theta) * s(phi) - s(phi) * c(phi),
         c(phi) * s(theta)],
        [c(phi) * c(theta) * s(phi) - s(phi) * c(phi), s(phi) ** 2 * c(theta) + c(phi) ** 2,
         s(phi) * s(theta)],
        [-c(phi) * s(theta), -s(phi) * s(theta), c(theta)],
    ])


@given(angles, tilts)
def test_rotation_is_eq1_and_proper(phi, theta):
    r = tilt_torsion_rotation(phi, theta)
    assert np.allclose(r, eq1_as_printed(phi, theta), atol=1e-14)
    assert np.allclose(r @ r.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(r) == pytest.approx(1.0)


@settings(max_examples=60)
@given(angles, tilts, st.floats(0.45, 0.75))
def test_parasitic_motion_keeps_every_spherical_joint_in_its_r_joint_plane(manipulator, phi,
                                                                           theta, z):
    """Eq. (2): A_i stays in the vertical plane through O and B_i, as the R joint demands."""
    g = pose_geometry(manipulator, Pose(z, phi, theta), check_limits=False)
    off_plane = np.einsum("ij,ij->i", g.platform_points, g.joint_axes)
    assert np.abs(off_plane).max() < 1e-12
    assert np.allclose(np.einsum("ij,ij->i", g.leg_directions, g.joint_axes), 0, atol=1e-12)


@settings(max_examples=30)
@given(angles, tilts, st.floats(-math.pi, math.pi))
def test_closure_holds_for_a_turned_leg_layout(manipulator, phi, theta, turn):
    m = replace(manipulator, leg_angles=tuple(turn + k * 2 * math.pi / 3 for k in range(3)))
    g = pose_geometry(m, Pose(0.55, phi, theta), check_limits=False)
    assert np.abs(np.einsum("ij,ij->i", g.platform_points, g.joint_axes)).max() < 1e-12


def test_symmetric_pose_geometry(manipulator):
    z = 0.55
    g = pose_geometry(manipulator, Pose(z))
    expected = math.hypot(z, manipulator.base_radius - manipulator.platform_radius)
    assert np.allclose(g.leg_lengths, expected, rtol=1e-14)
    assert np.allclose(g.platform_centre, [0, 0, z])
    for frame in g.leg_frames:  # limb frames are proper rotations
        assert np.allclose(frame.T @ frame, np.eye(3), atol=1e-14)
        assert np.linalg.det(frame) == pytest.approx(1.0)
    # legs lean inward: beta < 0; S-joint angle equals the lean for a level platform
    lean = math.atan2(manipulator.base_radius - manipulator.platform_radius, z)
    assert np.allclose(g.r_joint_angles, -lean)
    assert np.allclose(g.s_joint_angles, lean)


def test_leg_lengths_follow_eq3(manipulator):
    pose = Pose(0.6, math.radians(10), math.radians(-12))
    g = pose_geometry(manipulator, pose)
    r = tilt_torsion_rotation(pose.azimuth, pose.tilt)
    for i, a in enumerate(manipulator.leg_angles):
        oa = manipulator.platform_radius * np.array([math.cos(a), math.sin(a), 0])
        ob = manipulator.base_radius * np.array([math.cos(a), math.sin(a), 0])
        assert np.linalg.norm(g.platform_centre + r @ oa - ob) == pytest.approx(g.leg_lengths[i])


@pytest.mark.parametrize("pose, needle", [
    (Pose(1.2), "outside the actuator range"),
    (Pose(0.15), "outside the actuator range"),
    (Pose(0.55, 0.0, math.radians(60)), "S-joint 1 would reach .* deg, above s_joint_max_deg = 45"),
    (Pose(-0.3), "height = -0.3"),
    (Pose(float("nan")), "height = nan"),
])
def test_unreachable_poses_are_refused_with_the_value(manipulator, pose, needle):
    with pytest.raises(PoseError, match=needle):
        pose_geometry(manipulator, pose)


def test_irregular_leg_layout_is_refused(manipulator):
    m = replace(manipulator, leg_angles=(0.0, 2.0, 4.0))
    with pytest.raises(PoseError, match="120 degrees apart"):
        pose_geometry(m, Pose(0.55))


# The joint order of the paper's Section 2 text: S at the base, R at the platform.

def section2(manipulator):
    return replace(manipulator, base_joint="S", platform_joint="R")


@settings(max_examples=60)
@given(angles, tilts, st.floats(0.45, 0.75))
def test_section2_order_keeps_every_base_joint_in_its_platform_fixed_r_plane(manipulator, phi,
                                                                            theta, z):
    """R at A_i with its axis tangent to the platform circle: B_i - o is perpendicular to the
    axis, the leg too, and the height and the rotation are the pose's."""
    g = pose_geometry(section2(manipulator), Pose(z, phi, theta), check_limits=False)
    assert np.abs(np.einsum("ij,ij->i", g.base_points - g.platform_centre,
                            g.joint_axes)).max() < 1e-12
    assert np.allclose(np.einsum("ij,ij->i", g.leg_directions, g.joint_axes), 0, atol=1e-12)
    assert g.platform_centre[2] == pytest.approx(z, abs=1e-14)
    np.testing.assert_allclose(g.rotation, tilt_torsion_rotation(phi, theta), atol=1e-15)
    # the axes are fixed in the platform: tangent to its circle in the platform frame
    local = g.joint_axes @ g.rotation
    radial = (g.platform_points - g.platform_centre) @ g.rotation
    np.testing.assert_allclose(local[:, 2], 0.0, atol=1e-14)
    np.testing.assert_allclose(np.einsum("ij,ij->i", local, radial), 0.0, atol=1e-14)


@settings(max_examples=30)
@given(angles, tilts)
def test_section2_order_is_the_paper_mechanism_seen_from_the_platform(manipulator, phi, theta):
    """Swapping fixed and moving bodies (radii r1 <-> r2, rotation R^T) maps one joint order
    onto the other: the relative positions of the joints agree."""
    m = section2(manipulator)
    g = pose_geometry(m, Pose(0.55, phi, theta), check_limits=False)
    b_seen = (g.base_points - g.platform_centre) @ g.rotation  # B_i in the platform frame
    inverted = replace(manipulator, base_radius=m.platform_radius,
                       platform_radius=m.base_radius)
    # (the height only shifts the inverted mechanism along its normal: Eq. (2) does not use it)
    gi = pose_geometry(inverted, Pose(0.55, phi, -theta), check_limits=False)
    # the inverted mechanism's moving joints, relative to its centre, equal B_i seen from o
    np.testing.assert_allclose(gi.platform_points - gi.platform_centre,
                               b_seen - b_seen.mean(axis=0), atol=1e-12)
    np.testing.assert_allclose(gi.platform_centre[:2], b_seen.mean(axis=0)[:2], atol=1e-12)


def test_section2_level_pose_is_the_same_geometry(manipulator):
    a = pose_geometry(manipulator, Pose(0.55))
    b = pose_geometry(section2(manipulator), Pose(0.55))
    np.testing.assert_allclose(a.platform_points, b.platform_points, atol=1e-15)
    assert [j.type for j in b.leg_joints(0)] == ["S", "R"]
    assert b.leg_joints(0)[1].body == "platform" and b.leg_joints(0)[1].axis is not None


def test_a_leg_needs_one_r_and_one_s_joint(manipulator):
    with pytest.raises(ValueError, match="base_joint = 'R', platform_joint = 'R'"):
        replace(manipulator, platform_joint="R")
