"""The 3-RPS (the paper's): the R joint sits on the base at B_i = r1 (cos psi_i, sin psi_i, 0);
the actuator is the prismatic leg, its locked variable the leg length L_i = |B_i A_i| in
[actuator_min, actuator_max]; the drive (its spring, `common.stiffness`) acts along the leg;
the R joint's body normal, from which Eq. (25)'s beta_i is measured, is the base's z. The paper's
equations and its Section 2 text admit either joint order (R-P-S, S-P-R)."""
from __future__ import annotations

import numpy as np

from common.errors import InputError

from .architecture import Actuation, Architecture, LegEnds, Named


def _actuation(m) -> Actuation:
    return Actuation("leg length", m.actuator_min, m.actuator_max, "actuator_min_mm",
                     "actuator_max_mm", "actuator range")


def _leg_ends(m, platform_points: np.ndarray, radial: np.ndarray) -> LegEnds:
    a = np.asarray(platform_points, float)
    feet = m.base_radius * radial
    legs = a - feet
    lengths = np.linalg.norm(legs, axis=2)
    drive = legs / np.where(lengths > 0, lengths, 1.0)[..., None]
    normals = np.broadcast_to([0.0, 0.0, 1.0], a.shape)  # the base's z (a read-only view)
    return LegEnds(np.broadcast_to(feet, a.shape).copy(), drive, lengths, normals,
                   np.ones(len(a), bool))


def _check(m, named: Named) -> None:
    """At the level platform each leg spans the radii's difference horizontally: radii that
    differ by a longest leg or more leave no level pose."""
    if abs(m.base_radius - m.platform_radius) >= m.actuator_max:
        big, small = sorted((("base_radius", m.base_radius),
                             ("platform_radius", m.platform_radius)), key=lambda kv: -kv[1])
        raise InputError(
            f"{named(*big)} with {named(*small)}: the radii differ by "
            f"{(big[1] - small[1]) * 1e3:.6g} mm, at least the longest leg "
            f"({named('actuator_max', m.actuator_max)}); a level platform's legs each span the "
            "radii's difference, so no level pose is reachable; expected the radii less than "
            f"{m.actuator_max * 1e3:g} mm apart")


RPS = Architecture(
    name="3-RPS",
    doc="revolute joints on the base, prismatic legs; the paper",
    keys=("actuator_min_mm", "actuator_max_mm"),
    required=("actuator_min_mm", "actuator_max_mm"),
    fills={},
    joint_orders=(("R", "S"), ("S", "R")),
    leg_word="leg",
    stroke=("actuator_min", "actuator_max"),
    positive=("actuator_min", "actuator_max"),
    shortest="actuator_min",
    rails=False,
    actuation=_actuation,
    height_range=lambda m: (m.actuator_min, m.actuator_max),  # level legs are about that long
    leg_length_range=lambda m: (m.actuator_min, m.actuator_max),
    height_reach=lambda m: m.actuator_max,
    leg_ends=_leg_ends,
    out_of_range=lambda i, value: f"leg {i + 1} would be {value * 1e3:.1f} mm long",
    prepare=lambda m: None,
    check=_check,
)
