"""Inverse kinematics of the 3-RPS manipulator (paper Section 2, Eqs. 1-3 and 25).

A pose (height z, tilt-and-torsion angles phi, theta with zero torsion) gives the platform
rotation (Eq. 1), the parasitic translation (Eq. 2), the joint points and leg vectors (Eq. 3),
the R-joint axes, each limb's frame, the chain of joints of every leg, and the joint rotation
angles that Eq. (25) limits.

Two joint orders (the scene's `base_joint` / `platform_joint`):
- "R" at the base, "S" at the platform (the paper's equations, Eqs. 10-17): the R axis is
  horizontal and perpendicular to O->B_i, so every A_i stays in the vertical plane through O and
  B_i; Eq. (2) gives the parasitic translation.
- "S" at the base, "R" at the platform (the paper's Section 2 text): the R axis is fixed in the
  platform, tangent to the platform circle at A_i, so every B_i stays in the platform-fixed plane
  through o, A_i and the platform normal. Seen from the platform this is the first mechanism
  inverted (fixed and moving bodies swapped, radii r2 and r1, rotation R^T = Rz(phi) Ry(-theta)
  Rz(-phi), again zero torsion), so Eq. (2) applied in the platform frame with radius r1 and
  tilt -theta gives the base centre's offset, and the pose's height fixes the rest.

Which of the two it is follows from the joints' declaration (`common.joints`): the end whose
joint has an axis (`Manipulator.axis_end`) carries the axis; `pose_batch` branches the same way.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from common.errors import InputError
from common.joints import JOINTS, JointType
from common.rigid_body import cross

from .architectures import actuation, height_reach, leg_ends, of
from .params import Manipulator, Pose

_EVEN_SPACING = np.array([0.0, 2 * math.pi / 3, 4 * math.pi / 3])


class PoseError(InputError):
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


class Joint(NamedTuple):
    """One joint of a leg: its type, its centre, its axis (R joints), the body it joins."""

    type: str  # "R" (revolute: one rotation about `axis`) or "S" (spherical: three rotations)
    centre: np.ndarray  # (3,) joint centre, m
    axis: np.ndarray | None  # (3,) unit axis of an R joint in base coordinates, None for S
    body: str  # "base" (fixed) or "platform" (moving)

    @classmethod
    def at(cls, kind: str, centre, axis, body: str) -> Joint:
        """A joint of type `kind` (`common.joints.JOINTS`); `axis` is kept only if it has one."""
        return cls(kind, np.asarray(centre), axis if JOINTS[kind].has_axis else None, body)

    @property
    def kind(self) -> JointType:
        """What the joint leaves free (`common.joints`)."""
        return JOINTS[self.type]


@dataclass(frozen=True)
class PoseGeometry:
    """Everything the elastic models need to know about one pose, in base coordinates (m).

    Arrays are indexed by leg i = 0, 1, 2. `joint_axes` are the R-joint axes, at whichever end
    of the leg the R joint sits (`base_joint`, `platform_joint`).
    """

    rotation: np.ndarray  # (3, 3) platform-to-base rotation R, Eq. (1)
    platform_centre: np.ndarray  # (3,) o
    base_points: np.ndarray  # (3, 3) B_i, R-joint centres
    platform_points: np.ndarray  # (3, 3) A_i, S-joint centres
    joint_axes: np.ndarray  # (3, 3) unit R-joint axes, horizontal, perpendicular to OB_i
    leg_lengths: np.ndarray  # (3,) L_i = |B_i A_i|
    leg_frames: np.ndarray  # (3, 3, 3) limb-to-base rotations R_i; columns x_i, y_i, z_i
    s_joint_angles: np.ndarray  # (3,) alpha_i: leg axis vs the S joint's body normal, rad
    r_joint_angles: np.ndarray  # (3,) beta_i: leg axis vs the R joint's body normal, rad
    drive_axes: np.ndarray  # (3, 3) unit direction of each leg's drive (the leg; a rail)
    actuation: np.ndarray  # (3,) the locked actuators (leg lengths; slider travels), m
    base_joint: str = "R"
    platform_joint: str = "S"

    @property
    def leg_directions(self) -> np.ndarray:
        """Unit vectors B_i -> A_i (the limb x_i axes)."""
        return self.leg_frames[:, :, 0]

    @property
    def leg_count(self) -> int:
        return len(self.leg_lengths)

    def leg_joints(self, leg: int) -> tuple[Joint, Joint]:
        """The chain of leg `leg`: (joint at B_i on the base, joint at A_i on the platform)."""
        axis = self.joint_axes[leg]
        return (Joint.at(self.base_joint, self.base_points[leg], axis, "base"),
                Joint.at(self.platform_joint, self.platform_points[leg], axis, "platform"))

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
            drive_axes=self.drive_axes @ g.T,
            actuation=self.actuation.copy(),
            base_joint=self.base_joint,
            platform_joint=self.platform_joint,
        )


def pose_geometry(manipulator: Manipulator, pose: Pose, check_limits: bool = True) -> PoseGeometry:
    """Inverse kinematics, Eqs. (1)-(3): joint points, leg lengths, axes and limb frames.

    The limb frame R_i (Eq. 6) has x_i along the leg B_i -> A_i, y_i along the R-joint axis and
    z_i = x_i x y_i. With `check_limits`, a pose violating Eq. (25) raises PoseError.
    """
    m = manipulator
    if not (math.isfinite(pose.height) and pose.height > 0):
        raise PoseError(f"height = {pose.height!r} m: the platform must be above the base")
    reach = height_reach(m) + m.base_radius + m.platform_radius
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
    radial = np.stack([np.cos(angles), np.sin(angles), np.zeros(3)], axis=1)
    tangent = np.stack([-np.sin(angles), np.cos(angles), np.zeros(3)], axis=1)
    if m.axis_end == "base":
        xy = parasitic_translation(m.platform_radius, pose.azimuth, pose.tilt, layout_angle)
        centre = np.array([xy[0], xy[1], pose.height])
        axes = tangent  # horizontal, perpendicular to O->B_i
    else:  # the inverted mechanism: the base centre seen from the platform follows Eq. (2)
        xy = parasitic_translation(m.base_radius, pose.azimuth, -pose.tilt, layout_angle)
        z_seen = -(pose.height + rot[2, 0] * xy[0] + rot[2, 1] * xy[1]) / rot[2, 2]
        centre = -rot @ np.array([xy[0], xy[1], z_seen])
        axes = tangent @ rot.T  # fixed in the platform, tangent to its circle at A_i
    platform_points = centre + (m.platform_radius * radial) @ rot.T  # Eq. (3): Oo + R oA_i
    ends = leg_ends(m, platform_points[None], radial)  # the architecture's base ends
    if not ends.closes[0]:
        raise PoseError(f"a leg of {m.leg_length * 1e3:g} mm (leg_length_mm) cannot reach its "
                        "platform joint from any point of its rail")
    base_points = ends.base_points[0]
    legs = platform_points - base_points  # B_i A_i, Eq. (3)
    lengths = np.linalg.norm(legs, axis=1)
    if np.any(lengths < 1e-12):
        raise PoseError(f"leg lengths {lengths.tolist()} m: a leg has zero length")
    x_axes = legs / lengths[:, None]
    # The R joint only admits legs perpendicular to its axis.
    off_plane = np.abs(np.einsum("ij,ij->i", x_axes, axes))
    if np.any(off_plane > 1e-9):
        raise PoseError(
            f"leg directions leave the R-joint planes by {off_plane.max():.3g} (cosine): "
            "the pose violates the revolute-joint closure"
        )
    z_axes = cross(x_axes, axes)
    frames = np.stack([x_axes, axes, z_axes], axis=2)
    base_normal, platform_normal = np.array([0.0, 0.0, 1.0]), rot[:, 2]
    # alpha_i from the normal of the body across the leg from the joint with the axis
    s_normal = platform_normal if m.axis_end == "base" else base_normal
    s_angles = np.arccos(np.clip(x_axes @ s_normal, -1.0, 1.0))
    # beta_i: signed rotation of the leg about the R axis from the normal of the R joint's
    # body (positive leans outward)
    if m.axis_end == "base":  # from the base joint's body normal n (z; a rail), in its plane
        normals = ends.base_normals[0]
        outward = np.einsum("ij,ij->i", x_axes, cross(tangent, normals))
        upward = np.einsum("ij,ij->i", x_axes, normals)
    else:
        outward = np.einsum("ij,ij->i", x_axes, radial @ rot.T)
        upward = x_axes @ platform_normal
    r_angles = np.arctan2(outward, upward)
    geom = PoseGeometry(rot, centre, base_points, platform_points, axes, lengths, frames,
                        s_angles, r_angles, ends.drive_axes[0], ends.actuation[0],
                        m.base_joint, m.platform_joint)
    if check_limits:
        check_joint_limits(manipulator, geom)
        check_clearances(manipulator, geom)
    return geom


def check_joint_limits(manipulator: Manipulator, geom: PoseGeometry) -> None:
    """Eq. (25): L_min <= L_i <= L_max (a 3-PRS: s_min <= s_i <= s_max),
    |alpha_i| <= alpha_max, |beta_i| <= beta_max."""
    m = manipulator
    tol = 1e-12
    act = actuation(m)
    for i, value in enumerate(geom.actuation):
        if value < act.low - tol or value > act.high + tol:
            above = value > act.high
            what = of(m).out_of_range(i, value)
            raise PoseError(
                f"{what}, outside the {act.limit_name}: "
                + (f"above {act.high_key} = {act.high * 1e3:g}" if above else
                   f"below {act.low_key} = {act.low * 1e3:g}")
            )
    for i, a in enumerate(geom.s_joint_angles):
        if abs(a) > m.s_joint_max + tol:
            raise PoseError(
                f"S-joint {i + 1} would reach {math.degrees(abs(a)):.1f} deg, above "
                f"s_joint_max_deg = {math.degrees(m.s_joint_max):.6g}"
            )
    for i, b in enumerate(geom.r_joint_angles):
        if abs(b) > m.r_joint_max + tol:
            raise PoseError(
                f"R-joint {i + 1} would reach {math.degrees(abs(b)):.1f} deg, above "
                f"r_joint_max_deg = {math.degrees(m.r_joint_max):.6g}"
            )


# --- bodies that must not interpenetrate ------------------------------------------------------
# Beyond Eq. (25) a pose is reachable only if its bodies stay apart: no two legs touch (each leg
# a cylinder of diameter d, taken as the capsule around its axis segment: a conservative
# stand-in that also covers the joint ends), every leg reaches its platform joint from the base
# side of the plate (it does not lie in or pass through the platform), and the platform plate
# stays above the plane of the base joints (the base's top face). The end of each leg inside the
# plate at its joint (the joint sits on the plate's mid-surface) is the joint patch both models
# share, not an interpenetration.

def clearances(manipulator: Manipulator, base_points: np.ndarray, platform_points: np.ndarray,
               rotation: np.ndarray, platform_centre: np.ndarray) -> dict[str, np.ndarray]:
    """Signed clearances (m; negative: the bodies interpenetrate) of N poses, arrays with the
    pose first: `legs` the smallest gap between two leg surfaces, `approach` the component of
    the unit leg direction B_i -> A_i along the platform normal (positive: from below; scaled
    to metres by the leg diameter), `base` the height of the plate's lowest point above the
    base plane."""
    m = manipulator
    b = np.asarray(base_points, float).reshape(-1, 3, 3)
    a = np.asarray(platform_points, float).reshape(-1, 3, 3)
    rot = np.asarray(rotation, float).reshape(-1, 3, 3)
    centre = np.asarray(platform_centre, float).reshape(-1, 3)
    first, second = [0, 0, 1], [1, 2, 2]  # the three pairs of legs, all poses at once
    gaps = _segment_distance(b[:, first], a[:, first], b[:, second],
                             a[:, second]) - m.leg_diameter
    normal = rot[:, :, 2]
    legs = a - b
    lengths = np.sqrt(np.vecdot(legs, legs))
    up = np.vecdot(legs, normal[:, None, :]) / np.where(lengths > 0, lengths, 1.0)
    half = 0.5 * m.platform_thickness * np.abs(normal[:, 2])
    if m.platform_shape == "triangle":  # the plate's corners are the joints A_i
        lowest = a[:, :, 2].min(axis=1) - half
    else:  # a disk of radius r2 about o
        sideways = np.sqrt(np.clip(1.0 - normal[:, 2] ** 2, 0.0, None))
        lowest = centre[:, 2] - m.platform_radius * sideways - half
    return {"legs": gaps.min(axis=1), "approach": m.leg_diameter * up.min(axis=1),
            "base": lowest}


def _segment_distance(p1, q1, p2, q2) -> np.ndarray:
    """Shortest distance between the segments p1-q1 and p2-q2 ((..., 3) each; Ericson,
    Real-Time Collision Detection, 5.1.9)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    dot = np.vecdot  # (a few vectors: a tenth of einsum's call overhead)
    a, e, f, c, bb = dot(d1, d1), dot(d2, d2), dot(d2, r), dot(d1, r), dot(d1, d2)
    denom = a * e - bb * bb
    safe = lambda x: np.where(x > 0, x, 1.0)  # noqa: E731 (segments have positive length)
    unit = lambda x: np.minimum(np.maximum(x, 0.0), 1.0)  # noqa: E731 (clip to [0, 1])
    s = np.where(denom > 1e-14 * a * e, unit((bb * f - c * e) / safe(denom)), 0.0)
    t = (bb * s + f) / safe(e)
    s = np.where(t < 0, unit(-c / safe(a)), np.where(t > 1, unit((bb - c) / safe(a)), s))
    t = unit(t)
    gap = r + d1 * s[..., None] - d2 * t[..., None]
    return np.sqrt(dot(gap, gap))


CLEARANCE_RULES = {  # clearance -> what a negative value means, for the one-line error
    "legs": "two legs would touch (surfaces {gap:.3f} mm apart)",
    "approach": "a leg would reach its platform joint from above the plate",
    "base": "the platform plate would dip {depth:.3f} mm below the base plane",
}


def check_clearances(manipulator: Manipulator, geom: PoseGeometry) -> None:
    """Raise PoseError if the pose makes bodies interpenetrate (`clearances`)."""
    found = clearances(manipulator, geom.base_points, geom.platform_points, geom.rotation,
                       geom.platform_centre)
    for name, rule in CLEARANCE_RULES.items():
        value = float(found[name][0])
        if value < -CLEARANCE_TOLERANCE:
            raise PoseError(rule.format(gap=value * 1e3, depth=-value * 1e3))


CLEARANCE_TOLERANCE = 1e-12  # m
