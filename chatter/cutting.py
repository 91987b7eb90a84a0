"""[cutting]: the milling operation whose stability the lobes state, declared once (meaning,
unit, range, scene key), SI inside: N/m^2 for the cutting coefficients, rev/s for the spindle.

Geometry (Altintas' convention, Manufacturing Automation, ch. 3): the tool axis is the
platform normal; x is the feed direction in the platform's plane, `feed_direction_deg` from the
platform's x axis about its normal, y normal to it in the plane of the cut; the cutter turns
clockwise seen from above the tool (from +z), a tooth's immersion angle phi is measured
clockwise from +y. A radial immersion r = a_e / D cuts over phi in [0, arccos(1 - 2 r)] in up
milling and [arccos(2 r - 1), pi] in down milling (full immersion: [0, pi] both)."""
from __future__ import annotations

import math
from dataclasses import dataclass

from common.errors import InputError
from common.settings import check_settings, setting

MAX_RPM = 200_000.0  # the fastest spindles (micro-milling air bearings) turn about this fast
MAX_SPEEDS = 5_000  # speeds of one diagram: 400 resolve the lobes of a 2 kHz mode
MAX_TEETH = 100
MAX_COEFFICIENT = 1e11  # N/m^2 (100,000 N/mm^2): 20 times the hardest steels' Kt
METHODS = ("sdm", "zoa")
DEFAULT_METHOD = "sdm"  # resolves the periodic cut (flip lobes at low immersion) and states its
                        # own discretisation error; "zoa" is the fast average (Hopf lobes only)


@dataclass(frozen=True)
class Cutting:
    """[cutting]: the cutter, the material's cutting coefficients, the direction of the feed
    and the spindle speeds of the diagram."""

    teeth: int = setting(kind=int, minimum=1, maximum=MAX_TEETH,
                         doc="number of teeth (flutes) of the cutter, evenly spaced")
    diameter: float = setting(unit="mm", minimum=0.0, exclusive_minimum=True, maximum=10.0,
                              doc="the cutter's diameter")
    radial_immersion: float = setting(minimum=0.0, exclusive_minimum=True, maximum=1.0,
                                      doc="radial immersion a_e / D, in (0, 1] (1: slotting)")
    kt: float = setting(unit="N/mm2", minimum=0.0, exclusive_minimum=True,
                        maximum=MAX_COEFFICIENT,
                        doc="tangential cutting coefficient K_t (force per chip area)")
    kn: float = setting(unit="N/mm2", minimum=0.0, maximum=MAX_COEFFICIENT,
                        doc="normal (radial) cutting coefficient K_n")
    milling: str = setting("down", kind=str, choices=("down", "up"),
                           doc="down (climb) or up (conventional) milling")
    feed_direction: float = setting(0.0, unit="deg", minimum=-2 * math.pi, maximum=2 * math.pi,
                                    doc="the feed direction in the platform's plane, from the "
                                    "platform's x axis about its normal")
    spindle: tuple[float, ...] = setting((), kind=tuple, unit="rpm",
                                         minimum=0.0, exclusive_minimum=True,
                                         maximum=MAX_RPM / 60.0,
                                         doc="the spindle speed range of the diagram, lowest "
                                         "first (evaluated at `speeds` points)")
    speeds: int = setting(400, kind=int, minimum=2, maximum=MAX_SPEEDS,
                          doc="spindle speeds of the diagram, evenly spaced over the range")
    spindle_list: tuple[float, ...] = setting((), kind=tuple, unit="rpm",
                                              minimum=0.0, exclusive_minimum=True,
                                              maximum=MAX_RPM / 60.0, key="spindle_rpm_list",
                                              doc="exactly these spindle speeds (instead of "
                                              "the range)")
    method: str = setting(DEFAULT_METHOD, kind=str, choices=METHODS,
                          doc="'sdm': semi-discretization of the periodic cut, the reference "
                          "(flip lobes at low immersion, its discretisation error stated); "
                          "'zoa': the zero-order (time-averaged) method, fast, exact enough at "
                          "high immersion only")

    def __post_init__(self) -> None:
        check_settings(self)
        if bool(self.spindle) == bool(self.spindle_list):
            raise InputError("cutting: give spindle_rpm = [low, high] or spindle_rpm_list, "
                             "exactly one of them")
        if self.spindle and len(self.spindle) != 2:
            raise InputError(f"cutting.spindle_rpm = {[v * 60 for v in self.spindle]}: expected "
                             "[lowest, highest], two speeds")
        if self.spindle and not self.spindle[0] < self.spindle[1]:
            raise InputError(f"cutting.spindle_rpm = {[v * 60 for v in self.spindle]}: an empty "
                             "range; give [lowest, highest] with lowest < highest")
        if len(self.spindle_list) > MAX_SPEEDS:
            raise InputError(f"cutting.spindle_rpm_list: {len(self.spindle_list)} speeds, more "
                             f"than {MAX_SPEEDS}")

    @property
    def engagement(self) -> tuple[float, float]:
        """(phi_start, phi_exit), rad: the immersion angles over which a tooth cuts."""
        r = self.radial_immersion
        if self.milling == "up":
            return 0.0, math.acos(max(-1.0, 1.0 - 2.0 * r))
        return math.acos(min(1.0, 2.0 * r - 1.0)), math.pi

    def speeds_hz(self):
        """The diagram's spindle speeds, rev/s, ascending (a list's repeats once)."""
        import numpy as np

        if self.spindle_list:
            return np.unique(np.asarray(self.spindle_list, float))
        return np.linspace(self.spindle[0], self.spindle[1], self.speeds)
