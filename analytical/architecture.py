"""What an architecture is: where each leg's base joint sits, what its locked actuator is, and
what a scene of it must and must not give, declared as one `Architecture` object per module
(`rps.py`, the paper's 3-RPS; `prs.py`, the 3-PRS head), registered in `architectures.py`.

Architectures differ in kinematics, never in the models. The platform's side is common: in
all, each leg's revolute joint has a horizontal axis perpendicular to the vertical plane through
O and the leg's base point B_i, so each A_i stays in that plane and the platform moves as
Eq. (2) says. An architecture adds, for poses in batches (the pose first), the base ends of the
legs (`leg_ends`: the base joint centres, the drive axes, the locked actuator's variable, the
body normal of the base joint), the actuator's range (`actuation`), the heights worth scanning,
its own refusals and its own reach limits. Everything else (joint types and their order, the
models, the FEM) reads the result as `PoseGeometry` fields. A third architecture is one module
with its `Architecture` and one line in `architectures.py`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Protocol

import numpy as np


class Manipulator(Protocol):
    """What the architectures read of `params.Manipulator` (which imports them)."""

    @property
    def architecture(self) -> str: ...

    @property
    def base_radius(self) -> float: ...

    @property
    def platform_radius(self) -> float: ...

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


Named = Callable[[str, float], str]  # `scene_key = value unit` of a Manipulator field


@dataclass(frozen=True)
class Architecture:
    """One architecture, declared once: its name (the scene's `architecture`), the scene keys
    it owns, its kinematics and its refusals. Lengths SI."""

    name: str
    doc: str  # one sentence for the scene reference (docs/scenes.md)
    keys: tuple[str, ...]  # [manipulator] keys of this architecture only (others refuse them)
    required: tuple[str, ...]  # of those, the keys a scene must give
    fills: Mapping[str, float]  # Manipulator fields its scene does not give, decided here (SI)
    joint_orders: tuple[tuple[str, str], ...]  # (base joint, platform joint) admitted
    leg_word: str  # how messages name one leg ("leg", "slider link")
    stroke: tuple[str, str]  # the Manipulator fields of the locked actuator's range
    positive: tuple[str, ...]  # its Manipulator fields that must be > 0
    shortest: str  # the field a message about the shortest leg names
    rails: bool  # its base joints ride on rails (rail_angle is its key)
    actuation: Callable[[Any], Actuation]
    height_range: Callable[[Any], tuple[float, float]]  # heights to scan for a level platform
    leg_length_range: Callable[[Any], tuple[float, float]]  # (shortest, longest), joint to joint
    height_reach: Callable[[Any], float]  # the greatest height a platform joint can have
    leg_ends: Callable[[Any, np.ndarray, np.ndarray], LegEnds]  # (m, A_i (N,3,3), radial)
    out_of_range: Callable[[int, float], str]  # "leg 2 would be 1012.0 mm long"
    prepare: Callable[[Any], None]  # Manipulator.__post_init__: refusals and derived fields
    check: Callable[[Any, Named], None]  # check_manipulator: refusals naming scene keys
    # its own reach limits of a pose batch beyond the actuator's range and the joint angles:
    # (m, platform_points (N, 3, 3)) -> {scene key: how far beyond, m (> 0: violated)}
    limits: Callable[[Any, np.ndarray], dict[str, np.ndarray]] = field(
        default=lambda m, points: {})


def radial_directions(m: Manipulator) -> np.ndarray:
    """(3, 3) unit vectors e_r,i from the axis towards each leg's base point B_i."""
    angles = np.asarray(m.leg_angles, float)
    return np.stack([np.cos(angles), np.sin(angles), np.zeros(3)], axis=1)
