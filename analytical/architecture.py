"""Architectures: where each leg's base joint sits and what its locked actuator is.

A 3-RPS and a 3-PRS place the same kinds of joints differently, and that is all that differs
between them here: architectures differ in kinematics, never in the models. The platform's side is
common: in both, each leg's revolute joint has a horizontal axis perpendicular to the vertical
plane through O and the leg's base point B_i, so each A_i stays in that plane and the platform
moves as Eq. (2) says. What this module adds, for poses in batches (the pose first):

- "3-RPS" (the paper's): the R joint sits on the base at B_i = r1 (cos psi_i, sin psi_i, 0);
  the actuator is the prismatic leg, its locked variable the leg length L_i = |B_i A_i| in
  [actuator_min, actuator_max]; the drive (its spring, `common.stiffness`) acts along the leg;
  the R joint's body normal, from which Eq. (25)'s beta_i is measured, is the base's z.
- "3-PRS" (the Sprint Z3 head): a rail from each foot B_i, in the same vertical plane, inclined
  `rail_angle` (alpha) from the base plane, u_i = cos(alpha) e_r,i + sin(alpha) e_z (e_r,i
  pointing away from the axis: alpha < 90 deg leans outward as it rises, 90 is vertical,
  > 90 leans inward); a slider at travel s_i along it carries the R joint at
  P_i = B_i + s_i u_i, and a leg of fixed length L joins P_i to A_i. The slider is locked and
  rigid (the base body of the leg's R joint; its mass is not modelled), its travel s_i in
  [slider_min, slider_max] is the locked variable, the drive (screw, nut, bearings: the same
  `actuator_axial` spring) acts along the rail, and beta_i is the leg's angle from the rail
  direction u_i (the slider's normal: with vertical rails, the base's z as in the 3-RPS).
  |P_i A_i| = L gives s_i = (d.u) - sqrt((d.u)^2 - |d|^2 + L^2), d = A_i - B_i: of the two
  roots, the one with the leg leaning forward along the rail ((A_i - P_i).u >= 0, |beta_i|
  <= 90 deg); the other has |beta_i| > 90 deg, beyond every admitted R-joint limit.

Everything else (joint types and their order, the models, the FEM) reads the result as
`PoseGeometry` fields: the base joint centres, `drive_axes` and `actuation`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np


class Manipulator(Protocol):
    """What this module reads of `params.Manipulator` (which imports this module)."""

    @property
    def architecture(self) -> str: ...

    @property
    def base_radius(self) -> float: ...

    @property
    def leg_angles(self) -> tuple[float, float, float]: ...

    @property
    def actuator_min(self) -> float: ...

    @property
    def actuator_max(self) -> float: ...

    @property
    def rail_angle(self) -> float: ...

    @property
    def leg_length(self) -> float: ...

    @property
    def slider_min(self) -> float: ...

    @property
    def slider_max(self) -> float: ...


ARCHITECTURES = ("3-RPS", "3-PRS")
# Rails nearer the base plane than this are refused: the R-joint angle is measured from the
# rail, and a leg standing up from a rail in the base plane would sit near 90 degrees from it.
RAIL_ANGLE_RANGE = (math.radians(20.0), math.radians(160.0))


@dataclass(frozen=True)
class Actuation:
    """The locked actuator's variable of every leg and its range (SI), by scene key."""

    quantity: str  # what it is, for messages and reports: "leg length", "slider travel"
    low: float
    high: float
    low_key: str  # the scene keys of its limits
    high_key: str
    limit_name: str  # the phrase in a PoseError ("actuator range", "slider stroke")


@dataclass(frozen=True)
class LegEnds:
    """For N poses: where each leg's base joint sits and what its actuator reads."""

    base_points: np.ndarray  # (N, 3, 3) base joint centres (B_i, or the sliders' P_i)
    drive_axes: np.ndarray  # (N, 3, 3) unit direction of each leg's drive
    actuation: np.ndarray  # (N, 3) the locked actuator's variable (leg length, slider travel)
    base_normals: np.ndarray  # (N, 3, 3) normal of the base joint's body (beta_i from it)
    closes: np.ndarray  # (N,) bool: the legs can be assembled (the 3-PRS quadratic has roots)


# The [manipulator] keys that belong to one architecture only (the other's scene must not give
# them), and those of them a scene must give.
ARCHITECTURE_KEYS = {"3-RPS": ("actuator_min_mm", "actuator_max_mm"),
                     "3-PRS": ("rail_angle_deg", "leg_length_mm", "slider_min_mm",
                               "slider_max_mm")}
ARCHITECTURE_REQUIRED = {"3-RPS": ("actuator_min_mm", "actuator_max_mm"),
                         "3-PRS": ("leg_length_mm", "slider_max_mm")}
# The joint orders (base joint, platform joint) each architecture admits: a 3-RPS either way
# round (the paper's equations and its Section 2 text), a 3-PRS with its R joint on the slider.
JOINT_ORDERS = {"3-RPS": (("R", "S"), ("S", "R")), "3-PRS": (("R", "S"),)}


def is_prs(m: Manipulator) -> bool:
    return m.architecture == "3-PRS"


def rail_directions(m: Manipulator, radial: np.ndarray) -> np.ndarray:
    """(3, 3) unit rail directions u_i (a 3-RPS has none: its base normal z)."""
    if not is_prs(m):
        return np.broadcast_to([0.0, 0.0, 1.0], radial.shape).copy()
    a = m.rail_angle
    return math.cos(a) * radial + math.sin(a) * np.array([0.0, 0.0, 1.0])


def actuation(m: Manipulator) -> Actuation:
    """The locked actuator of this architecture and its range."""
    if is_prs(m):
        return Actuation("slider travel", m.slider_min, m.slider_max, "slider_min_mm",
                         "slider_max_mm", "slider stroke")
    return Actuation("leg length", m.actuator_min, m.actuator_max, "actuator_min_mm",
                     "actuator_max_mm", "actuator range")


def height_range(m: Manipulator) -> tuple[float, float]:
    """Heights (m) to scan for a level platform: a 3-RPS's actuator range (level legs are
    about that long), a 3-PRS's platform joints from its lowest slider to its reach."""
    if is_prs(m):
        return m.slider_min * math.sin(m.rail_angle), height_reach(m)
    return m.actuator_min, m.actuator_max


def leg_length_range(m: Manipulator) -> tuple[float, float]:
    """(shortest, longest) leg, joint centre to joint centre."""
    if is_prs(m):
        return m.leg_length, m.leg_length
    return m.actuator_min, m.actuator_max


def height_reach(m: Manipulator) -> float:
    """The greatest height a platform joint can have (m): scans of heights stop here."""
    if is_prs(m):
        return m.slider_max * math.sin(m.rail_angle) + m.leg_length
    return m.actuator_max


def radial_directions(m: Manipulator) -> np.ndarray:
    """(3, 3) unit vectors e_r,i from the axis towards each leg's base point B_i."""
    angles = np.asarray(m.leg_angles, float)
    return np.stack([np.cos(angles), np.sin(angles), np.zeros(3)], axis=1)


def rail_shortfall(m: Manipulator, platform_points: np.ndarray) -> np.ndarray:
    """(N,) how far (m) the farthest platform joint A_i lies beyond a leg's length from its
    rail's line (positive: the 3-PRS cannot be assembled); -inf for a 3-RPS."""
    a = np.asarray(platform_points, float)
    if not is_prs(m):
        return np.full(len(a), -np.inf)
    radial = radial_directions(m)
    d = a - m.base_radius * radial
    along = np.einsum("nij,ij->ni", d, rail_directions(m, radial))
    off_line = np.sqrt(np.clip(np.einsum("nij,nij->ni", d, d) - along ** 2, 0.0, None))
    return (off_line - m.leg_length).max(axis=1)


def leg_ends(m: Manipulator, platform_points: np.ndarray, radial: np.ndarray) -> LegEnds:
    """The base ends of the legs of N poses from their platform joints A_i ((N, 3, 3)) and
    the unit radial directions e_r,i of the legs ((3, 3)); the module doc."""
    a = np.asarray(platform_points, float)
    n = len(a)
    feet = m.base_radius * radial
    rails = np.broadcast_to(rail_directions(m, radial), a.shape)
    if not is_prs(m):
        legs = a - feet
        lengths = np.linalg.norm(legs, axis=2)
        drive = legs / np.where(lengths > 0, lengths, 1.0)[..., None]
        return LegEnds(np.broadcast_to(feet, a.shape).copy(), drive, lengths, rails,
                       np.ones(n, bool))
    d = a - feet
    along = np.einsum("nij,nij->ni", d, rails)
    excess = np.einsum("nij,nij->ni", d, d) - m.leg_length ** 2  # |d|^2 - L^2
    disc = along ** 2 - excess
    closes = np.all(disc >= 0.0, axis=1)
    root = np.sqrt(np.clip(disc, 0.0, None))
    # d.u - root, written as excess / (d.u + root) where d.u > 0 (no difference of two nearly
    # equal numbers when the slider is near its foot); where the leg cannot reach (disc < 0)
    # the nearest point of the rail, d.u
    beyond = along > 0.0
    travel = np.where(beyond, excess / np.where(beyond, along + root, 1.0), along - root)
    travel = np.where(disc >= 0.0, travel, along)
    points = feet + travel[..., None] * rails
    return LegEnds(points, rails.copy(), travel, rails.copy(), closes)
