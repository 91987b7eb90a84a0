"""Inverse kinematics of the 3-RPS manipulator (paper Section 2, Eqs. 1-3 and 25).

A pose (height z, tilt-and-torsion angles phi, theta with zero torsion) gives the platform
rotation (Eq. 1), the parasitic translation (Eq. 2), the joint points and leg vectors (Eq. 3),
the R-joint axes, each limb's frame, and the joint rotation angles that Eq. (25) limits.
"""
from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from .params import Manipulator, Pose


_EVEN_SPACING = np.array([0.0, 2 * math.pi / 3, 4 * math.pi / 3])


class PoseError(ValueError):
    """The pose cannot be assembled or violates a joint or actuator limit."""


def rotation_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rotation_y(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def tilt_torsion_rotation(azimuth: float, tilt: float) -> np.ndarray:
    """Platform-to-base rotation, Eq. (1): R = Rz(phi) Ry(theta) Rz(-phi) (zero torsion)."""
    return rotation_z(azimuth) @ rotation_y(tilt) @ rotation_z(-azimuth)


def parasitic_translation(platform_radius: float, azimuth: float, tilt: float,
                          layout_angle: float = 0.0) -> np.ndarray:
    """Horizontal position (x, y) of the platform centre forced by the R joints, Eq. (2).

    Eq. (2) holds for legs at 0, 120 and 240 degrees. A layout turned by `layout_angle` about z
    is the same mechanism seen from a turned frame, so its parasitic motion is Eq. (2) evaluated
    at azimuth - layout_angle and turned back.
    """
    rel = azimuth - layout_angle
    one_minus_c = 1.0 - math.cos(tilt)
    xy_local = np.array([
        -platform_radius * one_minus_c * math.cos(2.0 * rel) / 2.0,
        platform_radius * one_minus_c * math.sin(2.0 * rel) / 2.0,
    ])
    c, s = math.cos(layout_angle), math.sin(layout_angle)
    return np.array([[c, -s], [s, c]]) @ xy_local


@dataclass(frozen=True)
class PoseGeometry:
    """Everything the elastic models need to know about one pose, in base coordinates (m).

    Arrays are indexed by leg i = 0, 1, 2.
    """

    rotation: np.ndarray  # (3, 3) platform-to-base rotation R, Eq. (1)
    platform_centre: np.ndarray  # (3,) o
    base_points: np.ndarray  # (3, 3) B_i, R-joint centres
    platform_points: np.ndarray  # (3, 3) A_i, S-joint centres
    joint_axes: np.ndarray  # (3, 3) unit R-joint axes, horizontal, perpendicular to OB_i
    leg_lengths: np.ndarray  # (3,) L_i = |B_i A_i|
    leg_frames: np.ndarray  # (3, 3, 3) limb-to-base rotations R_i; columns x_i, y_i, z_i
    s_joint_angles: np.ndarray  # (3,) alpha_i: leg axis vs platform normal, rad
    r_joint_angles: np.ndarray  # (3,) beta_i: leg axis vs base normal, about the R axis, rad

    @property
    def leg_directions(self) -> np.ndarray:
        """Unit vectors B_i -> A_i (the limb x_i axes)."""
        return self.leg_frames[:, :, 0]

    def transformed(self, rotation: np.ndarray, translation=(0.0, 0.0, 0.0)) -> "PoseGeometry":
        """The same pose seen after a rigid motion x -> G x + t of the whole manipulator."""
        g = np.asarray(rotation, float)
        t = np.asarray(translation, float)
        return PoseGeometry(
            rotation=g @ self.rotation,
            platform_centre=g @ self.platform_centre + t,
            base_points=self.base_points @ g.T + t,
            platform_points=self.platform_points @ g.T + t,
            joint_axes=self.joint_axes @ g.T,
            leg_lengths=self.leg_lengths.copy(),
            leg_frames=np.einsum("ab,ibc->iac", g, self.leg_frames),
            s_joint_angles=self.s_joint_angles.copy(),
            r_joint_angles=self.r_joint_angles.copy(),
        )


def pose_geometry(manipulator: Manipulator, pose: Pose, check_limits: bool = True) -> PoseGeometry:
    """Inverse kinematics, Eqs. (1)-(3): joint points, leg lengths, axes and limb frames.

    The limb frame R_i (Eq. 6) has x_i along the leg B_i -> A_i, y_i along the R-joint axis and
    z_i = x_i x y_i. With `check_limits`, a pose violating Eq. (25) raises PoseError.
    """
    m = manipulator
    if not (math.isfinite(pose.height) and pose.height > 0):
        raise PoseError(f"height = {pose.height!r} m: the platform must be above the base")
    reach = m.actuator_max + m.base_radius + m.platform_radius
    if pose.height > 1e3 * reach:  # beyond any leg by orders of magnitude (and overflow)
        raise PoseError(f"height = {pose.height!r} m: no leg of this manipulator reaches it")
    for name in ("azimuth", "tilt"):
        if not math.isfinite(getattr(pose, name)):
            raise PoseError(f"{name} = {getattr(pose, name)!r}: not a finite angle")
    angles = np.asarray(m.leg_angles, float)
    layout_angle = float(angles[0])
    spacing = np.mod(angles - layout_angle, 2 * math.pi)
    if np.abs(spacing - _EVEN_SPACING).max() > 1e-9:
        raise PoseError(
            f"leg_angles = {np.degrees(angles).round(6).tolist()} deg: the parasitic-motion "
            "closure (Eq. 2) needs legs 120 degrees apart"
        )
    rot = tilt_torsion_rotation(pose.azimuth, pose.tilt)
    xy = parasitic_translation(m.platform_radius, pose.azimuth, pose.tilt, layout_angle)
    centre = np.array([xy[0], xy[1], pose.height])
    radial = np.stack([np.cos(angles), np.sin(angles), np.zeros(3)], axis=1)
    base_points = m.base_radius * radial
    platform_points = centre + (m.platform_radius * radial) @ rot.T  # Eq. (3): Oo + R oA_i
    axes = np.stack([-np.sin(angles), np.cos(angles), np.zeros(3)], axis=1)
    legs = platform_points - base_points  # B_i A_i, Eq. (3)
    lengths = np.linalg.norm(legs, axis=1)
    if np.any(lengths < 1e-12):
        raise PoseError(f"leg lengths {lengths.tolist()} m: a leg has zero length")
    x_axes = legs / lengths[:, None]
    # The R joint only admits legs perpendicular to its axis (A_i in the joint's plane).
    off_plane = np.abs(np.einsum("ij,ij->i", x_axes, axes))
    if np.any(off_plane > 1e-9):
        raise PoseError(
            f"leg directions leave the R-joint planes by {off_plane.max():.3g} (cosine): "
            "the pose violates the revolute-joint closure"
        )
    z_axes = np.stack([  # x_i x y_i
        x_axes[:, 1] * axes[:, 2] - x_axes[:, 2] * axes[:, 1],
        x_axes[:, 2] * axes[:, 0] - x_axes[:, 0] * axes[:, 2],
        x_axes[:, 0] * axes[:, 1] - x_axes[:, 1] * axes[:, 0],
    ], axis=1)
    frames = np.stack([x_axes, axes, z_axes], axis=2)
    normal = rot[:, 2]
    s_angles = np.arccos(np.clip(x_axes @ normal, -1.0, 1.0))
    # beta_i: signed rotation of the leg about the R axis, from vertical (positive leans outward)
    outward = np.einsum("ij,ij->i", x_axes, radial)
    r_angles = np.arctan2(outward, x_axes[:, 2])
    geom = PoseGeometry(rot, centre, base_points, platform_points, axes, lengths, frames,
                        s_angles, r_angles)
    if check_limits:
        check_joint_limits(manipulator, geom)
    return geom


def check_joint_limits(manipulator: Manipulator, geom: PoseGeometry) -> None:
    """Eq. (25): L_min <= L_i <= L_max, |alpha_i| <= alpha_max, |beta_i| <= beta_max."""
    m = manipulator
    tol = 1e-12
    for i, length in enumerate(geom.leg_lengths):
        if length < m.actuator_min - tol or length > m.actuator_max + tol:
            raise PoseError(
                f"leg {i + 1} length {length * 1e3:.3f} mm is outside the actuator range "
                f"[{m.actuator_min * 1e3:.1f}, {m.actuator_max * 1e3:.1f}] mm"
            )
    for i, a in enumerate(geom.s_joint_angles):
        if abs(a) > m.s_joint_max + tol:
            raise PoseError(
                f"S-joint {i + 1} angle {math.degrees(a):.3f} deg exceeds "
                f"alpha_max = {math.degrees(m.s_joint_max):.3f} deg"
            )
    for i, b in enumerate(geom.r_joint_angles):
        if abs(b) > m.r_joint_max + tol:
            raise PoseError(
                f"R-joint {i + 1} angle {math.degrees(b):.3f} deg exceeds "
                f"beta_max = {math.degrees(m.r_joint_max):.3f} deg"
            )
