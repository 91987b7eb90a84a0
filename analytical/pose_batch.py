"""Inverse kinematics of many poses at once (Eqs. 1-3 and 25), for workspace maps.

The vectorised twin of `kinematics.pose_geometry`: the same rotation (Eq. 1), parasitic
translation (Eq. 2), joint points, leg vectors and limb frames (Eq. 3), R-joint axes and joint
angles, for both joint orders, as arrays with the poses in front. Instead of raising PoseError
for a pose that is unreachable, it says so in `feasible` (closure and every limit of Eq. 25).
`pose_geometry` stays the one the FEM meshes from (its meshes must not move by a rounding
error); tests/test_workspace_fast.py checks every field of this twin against it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from common.rigid_body import cross

from .architectures import actuation, height_reach, leg_ends
from .kinematics import CLEARANCE_TOLERANCE, PoseGeometry, clearances, pose_geometry
from .params import Manipulator, Pose

CLOSURE_TOLERANCE = 1e-9  # |cos| of a leg against its R-joint axis, as pose_geometry
LIMIT_TOLERANCE = 1e-12  # slack on the limits of Eq. (25), as check_joint_limits


@dataclass(frozen=True)
class PoseBatch:
    """N poses; every array has the pose index first (legs second where it applies)."""

    heights: np.ndarray  # (N,) m
    azimuths: np.ndarray  # (N,) rad
    tilts: np.ndarray  # (N,) rad
    rotation: np.ndarray  # (N, 3, 3) platform-to-base rotation R, Eq. (1)
    platform_centre: np.ndarray  # (N, 3) o
    base_points: np.ndarray  # (N, 3, 3) B_i
    platform_points: np.ndarray  # (N, 3, 3) A_i
    joint_axes: np.ndarray  # (N, 3, 3) unit R-joint axes
    leg_lengths: np.ndarray  # (N, 3)
    leg_frames: np.ndarray  # (N, 3, 3, 3) limb-to-base rotations R_i, columns x_i, y_i, z_i
    s_joint_angles: np.ndarray  # (N, 3) rad
    r_joint_angles: np.ndarray  # (N, 3) rad
    drive_axes: np.ndarray  # (N, 3, 3) unit direction of each leg's drive
    actuation: np.ndarray  # (N, 3) the locked actuators (leg lengths; slider travels), m
    feasible: np.ndarray  # (N,) bool: closure, every limit of Eq. (25), no interpenetration
    base_joint: str = "R"
    platform_joint: str = "S"

    def __len__(self) -> int:
        return len(self.heights)

    def take(self, index) -> "PoseBatch":
        """The poses selected by `index` (a boolean mask or integer indices)."""
        return PoseBatch(**{f.name: (getattr(self, f.name)[index]
                                     if isinstance(getattr(self, f.name), np.ndarray)
                                     else getattr(self, f.name)) for f in fields(self)})

    def geometry(self, n: int) -> PoseGeometry:
        """Pose `n` as the PoseGeometry the per-pose model takes."""
        return PoseGeometry(self.rotation[n], self.platform_centre[n], self.base_points[n],
                            self.platform_points[n], self.joint_axes[n], self.leg_lengths[n],
                            self.leg_frames[n], self.s_joint_angles[n], self.r_joint_angles[n],
                            self.drive_axes[n], self.actuation[n], self.base_joint,
                            self.platform_joint)


def _rotation_z(angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    zero, one = np.zeros_like(c), np.ones_like(c)
    return np.stack([np.stack([c, -s, zero], -1), np.stack([s, c, zero], -1),
                     np.stack([zero, zero, one], -1)], -2)


def _rotation_y(angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    zero, one = np.zeros_like(c), np.ones_like(c)
    return np.stack([np.stack([c, zero, s], -1), np.stack([zero, one, zero], -1),
                     np.stack([-s, zero, c], -1)], -2)


def _parasitic(radius: float, azimuth: np.ndarray, tilt: np.ndarray,
               layout_angle: float) -> np.ndarray:
    """(N, 2): Eq. (2) for legs at layout_angle + (0, 120, 240) deg (kinematics'
    parasitic_translation, one row per pose)."""
    rel = azimuth - layout_angle
    one_minus_c = 1.0 - np.cos(tilt)
    local = np.stack([-radius * one_minus_c * np.cos(2.0 * rel) / 2.0,
                      radius * one_minus_c * np.sin(2.0 * rel) / 2.0], -1)
    c, s = math.cos(layout_angle), math.sin(layout_angle)
    return local @ np.array([[c, -s], [s, c]]).T


def pose_batch(manipulator: Manipulator, heights, azimuths, tilts) -> PoseBatch:
    """Eqs. (1)-(3) and (25) for every (height, azimuth, tilt), broadcast against each other."""
    m = manipulator
    z, phi, theta = (np.ravel(a).astype(float) for a in np.broadcast_arrays(
        np.asarray(heights, float), np.asarray(azimuths, float), np.asarray(tilts, float)))
    angles = np.asarray(m.leg_angles, float)
    spacing = np.mod(angles - angles[0], 2 * math.pi) - np.array([0.0, 2.0, 4.0]) * math.pi / 3
    if np.abs(spacing).max() > 1e-9:  # legs not 120 degrees apart: pose_geometry's error
        pose_geometry(m, Pose(height_reach(m)), check_limits=False)
    layout_angle = float(angles[0])
    radial = np.stack([np.cos(angles), np.sin(angles), np.zeros(3)], axis=1)
    tangent = np.stack([-np.sin(angles), np.cos(angles), np.zeros(3)], axis=1)
    reach = height_reach(m) + m.base_radius + m.platform_radius
    valid = (np.isfinite(z) & (z > 0) & (z <= 1e3 * reach) & np.isfinite(phi)
             & np.isfinite(theta))
    given = (z, phi, theta)
    z, phi, theta = (np.where(valid, a, d) for a, d in ((z, height_reach(m)), (phi, 0.0),
                                                         (theta, 0.0)))
    rot = _rotation_z(phi) @ _rotation_y(theta) @ _rotation_z(-phi)
    rot_t = np.swapaxes(rot, 1, 2)
    if m.axis_end == "base":
        xy = _parasitic(m.platform_radius, phi, theta, layout_angle)
        centre = np.column_stack([xy, z])
        axes = np.broadcast_to(tangent, (len(z), 3, 3))
    else:  # the inverted mechanism: the base centre seen from the platform follows Eq. (2)
        xy = _parasitic(m.base_radius, phi, -theta, layout_angle)
        z_seen = -(z + rot[:, 2, 0] * xy[:, 0] + rot[:, 2, 1] * xy[:, 1]) / rot[:, 2, 2]
        centre = -np.einsum("nij,nj->ni", rot, np.column_stack([xy, z_seen]))
        axes = tangent @ rot_t
    platform_points = centre[:, None, :] + (m.platform_radius * radial) @ rot_t
    ends = leg_ends(m, platform_points, radial)  # the architecture's base ends
    valid &= ends.closes
    base_points = ends.base_points
    legs = platform_points - base_points
    lengths = np.linalg.norm(legs, axis=2)
    valid &= np.all(lengths >= 1e-12, axis=1)
    x_axes = legs / np.where(lengths > 0, lengths, 1.0)[..., None]
    off_plane = np.abs(np.einsum("nij,nij->ni", x_axes, axes))
    z_axes = cross(x_axes, axes)
    frames = np.stack([x_axes, axes, z_axes], axis=3)
    platform_normal = rot[:, :, 2]
    s_normal = (platform_normal if m.axis_end == "base"
                else np.broadcast_to([0.0, 0.0, 1.0], (len(z), 3)))
    s_angles = np.arccos(np.clip(np.einsum("nij,nj->ni", x_axes, s_normal), -1.0, 1.0))
    if m.axis_end == "base":  # from the base joint's body normal n (z; a rail), in its plane
        normals = ends.base_normals
        outward = np.einsum("nij,nij->ni", x_axes, cross(tangent, normals))
        upward = np.einsum("nij,nij->ni", x_axes, normals)
    else:
        outward = np.einsum("nij,nij->ni", x_axes, radial @ rot_t)
        upward = np.einsum("nij,nj->ni", x_axes, platform_normal)
    r_angles = np.arctan2(outward, upward)
    tol = LIMIT_TOLERANCE
    act = actuation(m)
    feasible = (valid & np.all(off_plane <= CLOSURE_TOLERANCE, axis=1)
                & np.all((ends.actuation >= act.low - tol) & (ends.actuation <= act.high + tol),
                         axis=1)
                & np.all(np.abs(s_angles) <= m.s_joint_max + tol, axis=1)
                & np.all(np.abs(r_angles) <= m.r_joint_max + tol, axis=1))
    apart = clearances(m, base_points, platform_points, rot, centre)
    feasible &= np.all([c >= -CLEARANCE_TOLERANCE for c in apart.values()], axis=0)
    return PoseBatch(*given, rot, centre, np.array(base_points), platform_points,
                     np.array(axes), lengths, frames, s_angles, r_angles, ends.drive_axes,
                     ends.actuation, feasible, m.base_joint, m.platform_joint)
