"""The 3-PRS (the Sprint Z3 head): a rail from each foot B_i, in the vertical plane through O and
B_i, inclined `rail_angle` (alpha) from the base plane, u_i = cos(alpha) e_r,i + sin(alpha) e_z
(e_r,i pointing away from the axis: alpha < 90 deg leans outward as it rises, 90 is vertical,
> 90 leans inward); a slider at travel s_i along it carries the R joint at P_i = B_i + s_i u_i,
and a leg of fixed length L joins P_i to A_i. The slider is locked and rigid (the base body of the
leg's R joint; its mass is not modelled), its travel s_i in [slider_min, slider_max] is the
locked variable, the drive (screw, nut, bearings: the same `actuator_axial` spring) acts along
the rail, and beta_i is the leg's angle from the rail direction u_i (the slider's normal: with
vertical rails, the base's z as in the 3-RPS). |P_i A_i| = L gives
s_i = (d.u) - sqrt((d.u)^2 - |d|^2 + L^2), d = A_i - B_i: of the two roots, the one with the leg
leaning forward along the rail ((A_i - P_i).u >= 0, |beta_i| <= 90 deg); the other has
|beta_i| > 90 deg, beyond every admitted R-joint limit."""
from __future__ import annotations

import math

import numpy as np

from common.errors import InputError

from .architecture import Actuation, Architecture, LegEnds, Named, radial_directions

# Rails nearer the base plane than this are refused: the R-joint angle is measured from the
# rail, and a leg standing up from a rail in the base plane would sit near 90 degrees from it.
RAIL_ANGLE_RANGE = (math.radians(20.0), math.radians(160.0))


def _actuation(m) -> Actuation:
    return Actuation("slider travel", m.slider_min, m.slider_max, "slider_min_mm",
                     "slider_max_mm", "slider stroke")


def _rails(m, radial: np.ndarray) -> np.ndarray:
    """(3, 3) unit rail directions u_i."""
    a = m.rail_angle
    return math.cos(a) * radial + math.sin(a) * np.array([0.0, 0.0, 1.0])


def _height_reach(m) -> float:
    return m.slider_max * math.sin(m.rail_angle) + m.leg_length


def _leg_ends(m, platform_points: np.ndarray, radial: np.ndarray) -> LegEnds:
    a = np.asarray(platform_points, float)
    feet = m.base_radius * radial
    rails = np.broadcast_to(_rails(m, radial), a.shape)
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


def _limits(m, platform_points: np.ndarray) -> dict[str, np.ndarray]:
    """How far (m) the farthest platform joint A_i lies beyond a leg's length from its rail's
    line (positive: the legs cannot be assembled), by the key that binds: leg_length_mm."""
    a = np.asarray(platform_points, float)
    radial = radial_directions(m)
    d = a - m.base_radius * radial
    along = np.einsum("nij,ij->ni", d, _rails(m, radial))
    off_line = np.sqrt(np.clip(np.einsum("nij,nij->ni", d, d) - along ** 2, 0.0, None))
    return {"leg_length_mm": (off_line - m.leg_length).max(axis=1)}


def _prepare(m) -> None:
    """Its legs have one length, so their length range is [L, L]."""
    object.__setattr__(m, "actuator_min", m.leg_length)
    object.__setattr__(m, "actuator_max", m.leg_length)


def _check(m, named: Named) -> None:
    if m.leg.stepped:
        raise InputError(f"leg.housing_length_mm = {m.leg.housing_length * 1e3:g} with "
                         "architecture = '3-PRS': its legs are links of fixed length, not "
                         "actuators (a housing and a rod belong to a 3-RPS's prismatic legs)")


PRS = Architecture(
    name="3-PRS",
    doc="a slider on a rail from each B_i carries the revolute joint, legs of fixed length",
    keys=("rail_angle_deg", "leg_length_mm", "slider_min_mm", "slider_max_mm"),
    required=("leg_length_mm", "slider_max_mm"),
    fills={"actuator_min": 0.0, "actuator_max": 0.0},  # its legs' one length (prepare)
    joint_orders=(("R", "S"),),  # the revolute joint on the slider, the spherical one above
    leg_word="slider link",
    stroke=("slider_min", "slider_max"),
    positive=("leg_length", "slider_max"),
    shortest="leg_length",
    rails=True,
    actuation=_actuation,
    # its platform joints from the lowest slider to its reach
    height_range=lambda m: (m.slider_min * math.sin(m.rail_angle), _height_reach(m)),
    leg_length_range=lambda m: (m.leg_length, m.leg_length),
    height_reach=_height_reach,
    leg_ends=_leg_ends,
    out_of_range=lambda i, value: f"slider {i + 1} would travel {value * 1e3:.1f} mm",
    prepare=_prepare,
    check=_check,
    limits=_limits,
)
