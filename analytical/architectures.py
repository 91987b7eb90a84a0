"""The registered architectures (`architecture.Architecture`, one module each), and what the
rest of the house asks of a machine's: everything by `of(m)`, never by testing its name."""
from __future__ import annotations

from typing import Any

import numpy as np

from common.errors import InputError

from .architecture import Actuation, Architecture, LegEnds, radial_directions
from .prs import PRS
from .rps import RPS

ARCHITECTURES: dict[str, Architecture] = {a.name: a for a in (RPS, PRS)}
NAMES = tuple(ARCHITECTURES)  # the scene's choices, the default first


def of(m: Any) -> Architecture:
    """The architecture of a manipulator (its `architecture` name, checked by its setting)."""
    try:
        return ARCHITECTURES[m.architecture]
    except KeyError:
        raise InputError(f"architecture = {m.architecture!r}: expected one of "
                         f"{', '.join(NAMES)}") from None


def actuation(m) -> Actuation:
    """The locked actuator of this architecture and its range."""
    return of(m).actuation(m)


def height_range(m) -> tuple[float, float]:
    """Heights (m) to scan for a level platform."""
    return of(m).height_range(m)


def leg_length_range(m) -> tuple[float, float]:
    """(shortest, longest) leg, joint centre to joint centre."""
    return of(m).leg_length_range(m)


def height_reach(m) -> float:
    """The greatest height a platform joint can have (m): scans of heights stop here."""
    return of(m).height_reach(m)


def leg_ends(m, platform_points: np.ndarray, radial: np.ndarray) -> LegEnds:
    """The base ends of the legs of N poses from their platform joints A_i ((N, 3, 3)) and the
    unit radial directions e_r,i of the legs ((3, 3))."""
    return of(m).leg_ends(m, platform_points, radial)


__all__ = ["ARCHITECTURES", "NAMES", "Actuation", "Architecture", "LegEnds", "actuation",
           "height_range", "height_reach", "leg_ends", "leg_length_range", "of",
           "radial_directions"]
