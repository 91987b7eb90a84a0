"""A leg as a profile: joint to joint, a sequence of axisymmetric parts, declared once.

A 3-RPS leg is a linear actuator: a housing tube of fixed length from the base joint and a rod
that slides out of it and takes the rest of the pose's length to the platform joint. Each part
is a solid or hollow circle. The beam elements, the solid end zones, the harmonic meridian and
the tetrahedral mesh are all built from the parts this module gives (`LegProfile.parts`); what
each model does with a part (a Timoshenko section, a meridian polygon, a gmsh tube) is its own.

The default, no [leg] table, is the paper's leg: one solid cylinder of the manipulator's
`leg_diameter`, joint to joint. With a housing, the scene gives its length and the four
diameters, and the manipulator's leg diameter becomes the largest outer one (what the overlap
and collision checks and the mesh-size defaults scale with).

The two parts meet at the junction, a plane normal to the leg at `housing_length` from the base
joint: the housing's end face and the rod's end face are each tied to the junction's point on
the leg axis (plane sections, as a beam has them), and the drive (screw, nut, bearings) joins
the two; rigidly unless [stiffness] gives it an axial stiffness (`common.stiffness`).
"""
from __future__ import annotations

from dataclasses import dataclass

from .errors import InputError
from .settings import MAX_LENGTH, MIN_PART, check_settings, declared, setting

ENDS = ("base", "platform")
# A part is at least this many of its diameters long: a tube or rod, not a ring, with room for
# the solid end zones of half a diameter at both its coupled faces and a beam between them
# (analytical.end_zones), at every reachable pose.
MIN_PART_DIAMETERS = 1.2
# The rod slides in the housing's bore with room for a guide bush or wear ring between them:
# this much radially at least (a wall thinner than MIN_PART is a foil, not a part).
MIN_ROD_GAP = MIN_PART


@dataclass(frozen=True)
class LegPart:
    """One axisymmetric part of a leg: from `start` to `end` (m from the base joint along the
    leg), a circle of `outer` diameter with a bore of `inner` diameter (0: solid)."""

    name: str  # "leg", "housing" or "rod"
    start: float
    end: float
    outer: float
    inner: float = 0.0

    @property
    def length(self) -> float:
        return self.end - self.start

    @property
    def hollow(self) -> bool:
        return self.inner > 0.0


_DIAMETER = dict(unit="mm", minimum=0.0, maximum=MAX_LENGTH)


@dataclass(frozen=True)
class LegProfile:
    """[leg]: the parts of every leg (default: one solid cylinder of leg_diameter_mm)."""

    housing_length: float = setting(
        0.0, **_DIAMETER, doc="length of the housing, the fixed part of the actuator, from the "
        "base joint; the rod takes the rest of the pose's leg length (0: a uniform solid leg of "
        "leg_diameter_mm)")
    housing_outer_diameter: float = setting(0.0, **_DIAMETER,
                                            doc="outer diameter of the housing tube")
    housing_inner_diameter: float = setting(0.0, **_DIAMETER,
                                            doc="bore of the housing (0: solid)")
    rod_outer_diameter: float = setting(0.0, **_DIAMETER,
                                        doc="outer diameter of the rod (piston or screw rod)")
    rod_inner_diameter: float = setting(0.0, **_DIAMETER, doc="bore of the rod (0: solid)")

    def __post_init__(self) -> None:
        check_settings(self)
        if not self.stepped:
            given = [n for n in ("housing_outer_diameter", "housing_inner_diameter",
                                 "rod_outer_diameter", "rod_inner_diameter") if getattr(self, n)]
            if given:
                raise InputError(f"leg.{given[0]}_mm = {getattr(self, given[0]) * 1e3:g} mm "
                                 "without leg.housing_length_mm: a leg with a housing and a rod "
                                 "needs the housing's length")
            return
        if self.housing_length < MIN_PART:
            raise InputError(f"leg.housing_length_mm = {self.housing_length * 1e3:g}: expected "
                             f"at least {MIN_PART * 1e3:g} mm, or 0 for a uniform leg")
        for part in ("housing", "rod"):
            outer = getattr(self, f"{part}_outer_diameter")
            inner = getattr(self, f"{part}_inner_diameter")
            if outer < MIN_PART:
                raise InputError(f"leg.{part}_outer_diameter_mm = {outer * 1e3:g}: expected at "
                                 f"least {MIN_PART * 1e3:g} mm")
            if inner and outer - inner < 2 * MIN_PART:
                raise InputError(
                    f"leg.{part}_inner_diameter_mm = {inner * 1e3:g} with "
                    f"{part}_outer_diameter_mm = {outer * 1e3:g}: the wall is thinner than "
                    f"{MIN_PART * 1e3:g} mm (expected a bore of at most "
                    f"{(outer - 2 * MIN_PART) * 1e3:g} mm, or 0 for a solid {part})")
        if self.housing_length < MIN_PART_DIAMETERS * self.housing_outer_diameter:
            raise InputError(f"leg.housing_length_mm = {self.housing_length * 1e3:g}: expected "
                             f"at least {MIN_PART_DIAMETERS:g} housing diameters, "
                             f"{MIN_PART_DIAMETERS * self.housing_outer_diameter * 1e3:g} mm "
                             "(a tube, not a ring)")

    def check_rod_fits(self) -> None:
        """Refuse a rod that cannot slide in the housing's bore (InputError naming both keys):
        a solid housing has no bore; the bore is at least the rod plus MIN_ROD_GAP each side.
        Not a check of the geometry itself (the models build any two sections), but of a
        machine that can exist: `analytical.plausibility`."""
        if not self.stepped:
            return
        rod, bore = self.rod_outer_diameter, self.housing_inner_diameter
        need = rod + 2 * MIN_ROD_GAP
        if bore == 0.0:
            raise InputError(
                f"leg.housing_inner_diameter_mm = 0 (a solid housing) with rod_outer_diameter_mm "
                f"= {rod * 1e3:g}: the rod slides in the housing's bore; give the bore, "
                f"housing_inner_diameter_mm >= {need * 1e3:g} (rule 'rod in bore'), or leave "
                "[leg] out for a uniform solid leg")
        if bore < need * (1 - 1e-12):
            raise InputError(
                f"leg.rod_outer_diameter_mm = {rod * 1e3:g} with housing_inner_diameter_mm = "
                f"{bore * 1e3:g}: the rod does not fit the housing's bore with "
                f"{MIN_ROD_GAP * 1e3:g} mm of radial room (rule 'rod in bore'); expected "
                f"rod_outer_diameter_mm <= {(bore - 2 * MIN_ROD_GAP) * 1e3:g}")

    @property
    def stepped(self) -> bool:
        """True when the leg is a housing and a rod (a [leg] table), False for a uniform leg."""
        return self.housing_length > 0.0

    @property
    def largest_diameter(self) -> float:
        """The largest outer diameter of a stepped leg (0 for a uniform one)."""
        return max(self.housing_outer_diameter, self.rod_outer_diameter)

    def shortest_leg(self) -> float:
        """The shortest leg this profile admits: the housing plus a rod of MIN_PART_DIAMETERS
        of its own diameters, 0 for a uniform leg."""
        if not self.stepped:
            return 0.0
        return self.housing_length + MIN_PART_DIAMETERS * self.rod_outer_diameter

    def parts(self, length: float, diameter: float) -> tuple[LegPart, ...]:
        """The parts of a leg `length` long (m), base joint first; `diameter` is the uniform
        leg's (the manipulator's leg_diameter), used only when the leg has no housing."""
        if not self.stepped:
            return (LegPart("leg", 0.0, float(length), float(diameter)),)
        if length <= self.housing_length:
            raise InputError(f"leg length {length * 1e3:.6g} mm: not longer than its housing "
                             f"(housing_length_mm = {self.housing_length * 1e3:g})")
        return (LegPart("housing", 0.0, self.housing_length, self.housing_outer_diameter,
                        self.housing_inner_diameter),
                LegPart("rod", self.housing_length, float(length), self.rod_outer_diameter,
                        self.rod_inner_diameter))

    def end_part(self, end: str, diameter: float) -> LegPart:
        """The part at the leg's `end` ("base" or "platform") of a leg of unit length scale:
        its diameters are what a joint face and a solid end zone there have."""
        if end not in ENDS:
            raise ValueError(end)
        if not self.stepped:
            return LegPart("leg", 0.0, 0.0, float(diameter))
        if end == "base":
            return LegPart("housing", 0.0, 0.0, self.housing_outer_diameter,
                           self.housing_inner_diameter)
        return LegPart("rod", 0.0, 0.0, self.rod_outer_diameter, self.rod_inner_diameter)

    def scaled(self, k: float) -> "LegProfile":
        """The same profile with every length multiplied by `k`."""
        return LegProfile(**{name: k * getattr(self, name) for name, _, _ in declared(self)})
