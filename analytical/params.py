"""Physical parameters of a 3-RPS or 3-PRS manipulator, a pose, and the analytical model's fidelity.

Everything here is in SI units (m, kg, Pa, rad). Scene files speak millimetres and degrees;
`scene` converts once, at the edge, and hands these plain dataclasses inward.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from common.errors import InputError
from common.joints import COUPLINGS, JOINT_TYPES, JOINTS
from common.leg_profile import MIN_PART_DIAMETERS, LegPart, LegProfile
from common.payload import Payload
from common.settings import (
    MAX_ANGLE,
    MAX_LENGTH,
    MAX_SOLVED_MODES,
    MIN_PART,
    check_settings,
    declared,
    nested_setting,
    setting,
)
from common.stiffness import Stiffness

from .architectures import ARCHITECTURES, NAMES, of
from .beam import SHEAR_COEFFICIENTS
from .prs import RAIL_ANGLE_RANGE

BEAM_THEORIES = ("euler-bernoulli", "timoshenko")
PLATFORM_INERTIAS = ("plate", "paper-eq8")
PLATFORM_SHAPES = ("disk", "triangle")
R_JOINT_COORDINATES = ("axis", "paper-eq18")
JOINT_ENDS = ("beam", "solid")
LEG_MODELS = ("beam", "solid")
MAX_ELEMENTS = 200  # dense 18 s x 18 s model: 3600 coordinates at most
# solid legs: a part's Guyan modes are 6 (s + 1) dense columns of its harmonic solid (~10-60k
# dofs): at s = 32 about 100 MB a part; s = 12 is within 0.04 % of the FEM (joint_ends/README)
MAX_SOLID_STATIONS = 32

# Plausible materials and proportions (checked at load, `check_manipulator`).
# Poisson ratio nu = E / (2 G) - 1 in (0, 0.49]: the engineering solids a manipulator is built
# of (metals 0.25-0.35, polymers up to ~0.45). Towards 0.5 the displacement-based P2
# tetrahedra of the FEM reference lock volumetrically: the Lame ratio lambda / mu =
# 2 nu / (1 - 2 nu) is 49 at 0.49 and unbounded at 0.5 (measured: above 0.499 the two modes of
# a symmetric pair split by more than 1e-3, at 0.5 - 2e-16 the solve fails); at nu <= 0
# (auxetic) Cowper's shear coefficient of the Timoshenko legs, 6 (1 + nu) / (7 + 6 nu), falls
# to 0 and E, G no longer describe a material the two models treat alike.
POISSON_RANGE = (0.0, 0.49)  # exclusive minimum, inclusive maximum
DENSITY_RANGE = (500.0, 25_000.0)  # kg/m3: balsa-free woods and foams .. osmium
YOUNGS_MODULUS_RANGE = (1e9, 1000e9)  # Pa: stiff polymers .. diamond-like ceramics
MIN_PLATE_THICKNESS = 1e-3  # m: thinner is a sheet, not the rigid/elastic plate modelled


@dataclass(frozen=True)
class Material:
    youngs_modulus: float = setting(doc="Young's modulus E (an engineering solid: stiff "
                                    "polymers to diamond-like ceramics)", unit="GPa",
                                    minimum=YOUNGS_MODULUS_RANGE[0],
                                    maximum=YOUNGS_MODULUS_RANGE[1])  # Pa
    shear_modulus: float = setting(doc="shear modulus G (E / (2 G) - 1 is the Poisson ratio)",
                                   unit="GPa", minimum=0.0, exclusive_minimum=True,
                                   maximum=YOUNGS_MODULUS_RANGE[1] / 2)  # Pa: G < E / 2
    density: float = setting(doc="mass density rho (an engineering solid)", unit="kg/m3",
                             minimum=DENSITY_RANGE[0], maximum=DENSITY_RANGE[1])  # kg/m^3

    @property
    def poisson_ratio(self) -> float:
        """nu = E / (2 G) - 1 (isotropic)."""
        return self.youngs_modulus / (2.0 * self.shear_modulus) - 1.0


# A dimension of the machine: at least MIN_PART (1 mm), at most MAX_LENGTH (100 m); the reasons
# are in common.settings.
_PART = dict(minimum=MIN_PART, maximum=MAX_LENGTH)
_POSITIVE = dict(minimum=0.0, exclusive_minimum=True)


@dataclass(frozen=True)
class Manipulator:
    """Geometry and material of a 3-RPS manipulator (paper Section 2), or of a 3-PRS
    (`architecture`: sliders on rails carry the revolute joints; `analytical.architecture`).

    The base joints B_i lie on the base circle of radius `base_radius`; the platform joints A_i
    lie on the platform circle of radius `platform_radius`, both at the polar angles
    `leg_angles` (rad), measured from the base x-axis. `base_joint` and `platform_joint` say
    which joint sits at each end of a leg: the paper's equations put the revolute joint on the
    base (axis horizontal, perpendicular to O->B_i) and the spherical joint on the platform;
    its Section 2 text reads the other way round (spherical at the base, revolute at the
    platform with its axis tangent to the platform circle).
    """

    base_radius: float = setting(doc="r1, radius of the circle of base joints B_i", unit="mm",
                                 **_PART)
    platform_radius: float = setting(doc="r2, radius of the circle of platform joints A_i",
                                     unit="mm", **_PART)
    leg_diameter: float = setting(doc="d, diameter of the solid circular legs (with a [leg] "
                                  "housing and rod: not given; the largest of their outer "
                                  "diameters)", unit="mm", **_PART)
    platform_thickness: float = setting(doc="h, thickness of the platform plate", unit="mm",
                                        **_PART)
    material: Material = nested_setting(Material)
    payload: Payload = nested_setting(Payload, default_factory=Payload)
    leg: LegProfile = nested_setting(LegProfile, default_factory=LegProfile)
    stiffness: Stiffness = nested_setting(Stiffness, default_factory=Stiffness)
    leg_angles: tuple[float, float, float] = setting(
        (0.0, 2 * math.pi / 3, 4 * math.pi / 3), kind=tuple, unit="deg", length=3,
        minimum=-MAX_ANGLE, maximum=MAX_ANGLE,
        doc="polar angles of the three legs from the base x-axis (120 degrees apart; one turn "
        "either way at most)")
    platform_shape: str = setting("disk", kind=str, choices=PLATFORM_SHAPES,
                                  doc='plate outline: "disk" of radius r2, or the "triangle" '
                                  "A1A2A3")
    actuator_min: float = setting(0.2, unit="mm", scene_required=True, **_PART,
                                  doc="L_min, shortest leg (Eq. 25; a 3-RPS only)")  # m
    actuator_max: float = setting(1.0, unit="mm", scene_required=True, **_PART,
                                  doc="L_max, longest leg (Eq. 25; a 3-RPS only)")  # m
    s_joint_max: float = setting(math.radians(45.0), unit="deg", scene_required=True,
                                 maximum=math.pi / 2, **_POSITIVE,
                                 doc="alpha_max, largest angle between a leg and the normal of "
                                 "the body carrying its spherical joint (Eq. 25)")  # rad
    r_joint_max: float = setting(math.radians(45.0), unit="deg", scene_required=True,
                                 maximum=math.pi / 2, **_POSITIVE,
                                 doc="beta_max, largest rotation of a revolute joint from the "
                                 "normal of its body (Eq. 25)")  # rad
    architecture: str = setting(NAMES[0], kind=str, choices=NAMES, doc=" or ".join(
        f'"{a.name}" ({a.doc})' for a in ARCHITECTURES.values()))
    rail_angle: float = setting(math.pi / 2, unit="deg", minimum=RAIL_ANGLE_RANGE[0],
                                maximum=RAIL_ANGLE_RANGE[1],
                                doc="3-PRS: inclination of every rail from the base plane, in "
                                "the vertical plane through O and B_i (90: vertical; below 90 "
                                "it leans away from the axis as it rises, above 90 towards it)")
    leg_length: float = setting(0.0, unit="mm", minimum=0.0, maximum=MAX_LENGTH,
                                doc="3-PRS: the fixed length of every leg, joint centre to "
                                "joint centre")  # m
    slider_min: float = setting(0.0, unit="mm", minimum=0.0, maximum=MAX_LENGTH,
                                doc="3-PRS: lowest travel of every slider along its rail, from "
                                "the rail's foot B_i")  # m
    slider_max: float = setting(0.0, unit="mm", minimum=0.0, maximum=MAX_LENGTH,
                                doc="3-PRS: highest travel of every slider along its rail")  # m
    base_joint: str = setting("R", kind=str, choices=JOINT_TYPES,
                              doc="joint at the base end of every leg (the paper's equations: "
                              "R)")
    platform_joint: str = setting("S", kind=str, choices=JOINT_TYPES,
                                  doc="joint at the platform end of every leg (the paper's "
                                  "equations: S)")

    def __post_init__(self) -> None:
        # the kinematics closes on the one joint of a leg with an axis (`axis_end`)
        kinds = [JOINTS.get(j) for j in (self.base_joint, self.platform_joint)]
        if None in kinds or sum(k.has_axis for k in kinds if k is not None) != 1:
            raise InputError(f"base_joint = {self.base_joint!r}, platform_joint = "
                             f"{self.platform_joint!r}: a 3-RPS leg has one R and one S joint "
                             "(R-P-S or S-P-R)")
        arch = of(self)
        if (self.base_joint, self.platform_joint) not in arch.joint_orders:
            admitted = " or ".join(f"({b}, {p})" for b, p in arch.joint_orders)
            raise InputError(f"base_joint = {self.base_joint!r}, platform_joint = "
                             f"{self.platform_joint!r} with architecture = {arch.name!r}: it "
                             f"admits only {admitted} ({arch.doc})")
        arch.prepare(self)  # its derived fields (analytical/prs.py)

    def leg_parts(self, length: float) -> tuple[LegPart, ...]:
        """The parts of a leg `length` long, base joint first (`common.leg_profile`)."""
        return self.leg.parts(length, self.leg_diameter)

    def end_part(self, end: str) -> LegPart:
        """The part of every leg at its `end` ("base" or "platform"): its diameters are the
        joint face's there."""
        return self.leg.end_part(end, self.leg_diameter)

    @property
    def axis_end(self) -> str:
        """The end of every leg ("base" or "platform") whose joint has an axis (the R joint):
        where the axis lies, and so the closure of the kinematics, follows that body."""
        return "base" if JOINTS[self.base_joint].has_axis else "platform"

    def scaled(self, length_factor: float) -> "Manipulator":
        """The same manipulator with every length multiplied by `length_factor`."""
        k = length_factor
        return replace(
            self,
            base_radius=self.base_radius * k,
            platform_radius=self.platform_radius * k,
            leg_diameter=self.leg_diameter * k,
            platform_thickness=self.platform_thickness * k,
            actuator_min=self.actuator_min * k,
            actuator_max=self.actuator_max * k,
            leg_length=self.leg_length * k,
            slider_min=self.slider_min * k,
            slider_max=self.slider_max * k,
            leg=self.leg.scaled(k),
        )


@dataclass(frozen=True)
class Pose:
    """Platform pose by tilt-and-torsion angles with zero torsion (Eq. 1).

    `height` is z of the platform centre o; `azimuth` (phi) is the direction of the tilt axis,
    `tilt` (theta) the tilt angle. x and y follow from the parasitic motion (Eq. 2).
    """

    height: float  # m
    azimuth: float = 0.0  # phi, rad
    tilt: float = 0.0  # theta, rad


@dataclass(frozen=True)
class ModelOptions:
    """Fidelity of the analytical substructure model."""

    elements: int = setting(3, kind=int, minimum=1, maximum=MAX_ELEMENTS,
                            doc="s, beam elements per leg (the paper: 3; frequencies converge "
                            "to 1e-4 by s = 10)")
    beam: str = setting("euler-bernoulli", kind=str, choices=BEAM_THEORIES,
                        doc="beam theory of the leg elements (Timoshenko adds shear "
                        "deformation and rotary inertia)")
    platform_inertia: str = setting("plate", kind=str, choices=PLATFORM_INERTIAS,
                                    doc="true plate inertia, or Eq. (8)'s m r2^2 on every axis")
    r_joint_coordinate: str = setting("axis", kind=str, choices=R_JOINT_COORDINATES,
                                      doc="independent R-joint coordinate: rotation about the "
                                      "joint axis (regular), or the paper's Eq. (18) ratio form")
    modes: int = setting(6, kind=int, minimum=1, maximum=MAX_SOLVED_MODES, scene=False,
                         doc="number of modes solved for (a scene sets [fidelity] modes)")
    shear: str = setting("cowper", kind=str, choices=SHEAR_COEFFICIENTS,
                         doc="Timoshenko shear coefficient of the round legs: Cowper's "
                         "6(1+nu)/(7+6nu) or Hutchinson's 6(1+nu)^2/(7+12nu+4nu^2)")
    joint_ends: str = setting("beam", kind=str, choices=JOINT_ENDS,
                              doc="leg ends at the joints: beam elements to the joint centre, or "
                              "a solid end zone condensed from a small solid model (captures "
                              "the joint face's restraint of warping and Poisson contraction)")
    joint_coupling: str = setting("rigid", kind=str, choices=COUPLINGS,
                                  doc="how a solid end zone's joint face follows the joint "
                                  "centre, as the FEM's coupling (default: the scene's [fem] "
                                  "coupling)")
    end_zone: float = setting(0.5, minimum=0.1, maximum=3.0,
                              doc="length of each solid end zone, in leg diameters")
    legs: str = setting("beam", kind=str, choices=LEG_MODELS,
                        doc="the legs' parts: frame elements (beam, shear and joint_ends "
                        "apply), or each part condensed from its solid of revolution onto its "
                        "s + 1 section nodes (solid: the FEM's own leg, slower; beam, shear and "
                        "joint_ends do not apply)")
    # Not a setting (no scene key) and not part of what the model is: the cache directory
    # whose joint_ends/ holds the condensed end zones and leg parts (None: the default one,
    # common.locations.cache_root). The run sets it from --cache, and it travels with the
    # options to every process that assembles a model. Not compared, so it is in no cache key
    # (common.settings.as_dict) and two runs with different caches compute the same model.
    cache_dir: str | None = field(default=None, compare=False)

    def describe(self) -> str:
        """The model in one line, for records and messages: "solid legs, s = 8, plate inertia"
        or "timoshenko (cowper), s = 5, solid joint ends, plate inertia"."""
        if self.legs == "solid":
            return f"solid legs, s = {self.elements}, {self.platform_inertia} inertia"
        shear = f" ({self.shear})" if self.beam == "timoshenko" else ""
        ends = ", solid joint ends" if self.joint_ends == "solid" else ""
        return f"{self.beam}{shear}, s = {self.elements}{ends}, {self.platform_inertia} inertia"

    def __post_init__(self) -> None:
        check_settings(self)
        if self.legs == "solid" and self.elements > MAX_SOLID_STATIONS:
            raise InputError(f"analytical.elements = {self.elements} with legs = 'solid': at "
                             f"most {MAX_SOLID_STATIONS} stations a part (s = 12 is within "
                             "0.04 % of the FEM already)")
        if self.legs == "solid" and self.joint_ends == "solid":
            raise InputError("analytical.legs = 'solid' with analytical.joint_ends = 'solid': "
                             "a solid leg's faces are its own, it has no end zones (set "
                             "joint_ends = 'beam')")


def _named(cls, name: str, value: float) -> str:
    """`scene_key = value unit` of a declared field, in the scene file's unit."""
    spec = next(s for n, s, _ in declared(cls) if n == name)
    return f"{spec.scene_key(name)} = {spec.edge(value):.6g}{' ' + spec.unit if spec.unit else ''}"


def _distance_on_circle(radius: float, a: float, b: float) -> float:
    return 2.0 * radius * abs(math.sin(0.5 * (a - b)))


def check_manipulator(m: Manipulator) -> None:
    """Raise ValueError naming the first non-physical or implausible parameter: its scene key,
    its value and the expected range in the scene file's unit, on one line."""
    arch = of(m)
    actuator = {name: getattr(m, name) for name in arch.positive}
    positive = {
        "base_radius": m.base_radius,
        "platform_radius": m.platform_radius,
        "leg_diameter": m.leg_diameter,
        "platform_thickness": m.platform_thickness,
        **actuator,
        "youngs_modulus": m.material.youngs_modulus,
        "shear_modulus": m.material.shear_modulus,
        "density": m.material.density,
        "s_joint_max": m.s_joint_max,
        "r_joint_max": m.r_joint_max,
    }
    for name, value in positive.items():
        cls = Material if name in ("youngs_modulus", "shear_modulus", "density") else Manipulator
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            key = next(s for n, s, _ in declared(cls) if n == name).scene_key(name)
            raise InputError(f"{key} = {value!r} (SI): must be a finite positive number")
    lower, upper = arch.stroke
    if getattr(m, lower) >= getattr(m, upper):
        raise InputError(f"{_named(Manipulator, lower, getattr(m, lower))} is not below "
                         f"{_named(Manipulator, upper, getattr(m, upper))}")
    arch.check(m, lambda name, value: _named(Manipulator, name, value))
    mat = m.material
    low, high = YOUNGS_MODULUS_RANGE
    if not low <= mat.youngs_modulus <= high:
        raise InputError(f"{_named(Material, 'youngs_modulus', mat.youngs_modulus)}: expected "
                         f"{low / 1e9:g} to {high / 1e9:g} GPa (an engineering solid)")
    low, high = DENSITY_RANGE
    if not low <= mat.density <= high:
        raise InputError(f"{_named(Material, 'density', mat.density)}: expected {low:g} to "
                         f"{high:g} kg/m3 (an engineering solid)")
    nu = mat.poisson_ratio
    low, high = POISSON_RANGE
    if not low < nu <= high:
        raise InputError(
            f"{_named(Material, 'shear_modulus', mat.shear_modulus)} with "
            f"{_named(Material, 'youngs_modulus', mat.youngs_modulus)}: Poisson ratio "
            f"E / (2 G) - 1 = {nu:.6g}, expected {low:g} < nu <= {high:g} (G between "
            f"{mat.youngs_modulus / (2 * (1 + high)) / 1e9:.6g} and "
            f"{mat.youngs_modulus / (2 * (1 + low)) / 1e9:.6g} GPa; nearly incompressible "
            "solids lock the FEM's P2 tetrahedra)")
    if m.platform_shape not in PLATFORM_SHAPES:
        raise InputError(
            f"platform_shape = {m.platform_shape!r}: expected one of {', '.join(PLATFORM_SHAPES)}"
        )
    spacing = [math.remainder(a - m.leg_angles[0], 2 * math.pi) for a in m.leg_angles]
    if any(abs(math.remainder(x - k * 2 * math.pi / 3, 2 * math.pi)) > 1e-9
           for k, x in enumerate(spacing)):  # as kinematics.pose_geometry requires
        shown = [float(f"{math.degrees(a):.6g}") for a in m.leg_angles]
        raise InputError(f"leg_angles_deg = {shown}: the parasitic-motion closure (Eq. 2) needs "
                         "the legs 120 degrees apart, in order (e.g. [0, 120, 240])")
    _check_proportions(m)
    m.stiffness.check_joints(m.base_joint, m.platform_joint)


def _check_profile(m: Manipulator) -> None:
    """A housing and a rod: the manipulator's leg diameter is their largest, and the rod
    reaches out of the housing at the shortest leg."""
    leg = m.leg
    leg.check_rod_fits()  # the most basic fault of a leg first (analytical.plausibility)
    if not math.isclose(m.leg_diameter, leg.largest_diameter, rel_tol=1e-12):
        raise InputError(f"{_named(Manipulator, 'leg_diameter', m.leg_diameter)} with a [leg] "
                         f"housing and rod: the leg's diameter is theirs (the largest outer one, "
                         f"{leg.largest_diameter * 1e3:g} mm); leave leg_diameter_mm out")
    if m.actuator_min < leg.shortest_leg():
        raise InputError(
            f"{_named(Manipulator, 'actuator_min', m.actuator_min)}: the shortest leg leaves "
            f"a rod of {(m.actuator_min - leg.housing_length) * 1e3:.6g} mm out of the housing "
            f"(leg.housing_length_mm = {leg.housing_length * 1e3:g}); expected at least "
            f"{MIN_PART_DIAMETERS:g} rod diameters, so actuator_min_mm >= "
            f"{leg.shortest_leg() * 1e3:g}")


def _check_proportions(m: Manipulator) -> None:
    """Bodies that the models take as separate solids meeting only at the joints."""
    d = m.leg_diameter
    if m.leg.stepped:
        _check_profile(m)
    shortest = of(m).shortest
    if m.actuator_min < d:
        raise InputError(f"{_named(Manipulator, shortest, getattr(m, shortest))}: the shortest "
                         f"leg is shorter than its diameter "
                         f"{_named(Manipulator, 'leg_diameter', d)}; expected at least "
                         f"{d * 1e3:g} mm (a leg, not a disk)")
    if m.platform_thickness < MIN_PLATE_THICKNESS:
        raise InputError(f"{_named(Manipulator, 'platform_thickness', m.platform_thickness)}: "
                         f"expected at least {MIN_PLATE_THICKNESS * 1e3:g} mm")
    if m.platform_thickness > m.platform_radius:
        raise InputError(f"{_named(Manipulator, 'platform_thickness', m.platform_thickness)}: "
                         f"thicker than the platform radius "
                         f"{_named(Manipulator, 'platform_radius', m.platform_radius)}; "
                         f"expected at most {m.platform_radius * 1e3:g} mm (a plate)")
    angles = m.leg_angles
    for radius, name, ends, end in ((m.base_radius, "base_radius", "B", "base"),
                                    (m.platform_radius, "platform_radius", "A", "platform")):
        d = m.end_part(end).outer
        for i in range(3):
            for j in range(i + 1, 3):
                gap = _distance_on_circle(radius, angles[i], angles[j])
                if gap <= d:
                    what = (_named(Manipulator, 'leg_diameter', d) if not m.leg.stepped else
                            f"leg.{m.end_part(end).name}_outer_diameter_mm = {d * 1e3:g}")
                    raise InputError(
                        f"{what}: legs {i + 1} and {j + 1} "
                        f"overlap at their joints {ends}{i + 1}, {ends}{j + 1} "
                        f"({gap * 1e3:.6g} mm apart with {_named(Manipulator, name, radius)} and "
                        f"leg_angles_deg); expected a leg diameter below {gap * 1e3:.6g} mm")
    # A plate thicker than the legs is modelled as the scene says: each leg ends at its joint
    # A_i on the plate's mid-surface (the joint sits where the scene puts it), so its last
    # h/2 or more lies inside the plate, in both models alike (a shared idealisation: the
    # legs' ends are leg, the plate's mass and inertia are the whole plate's).
