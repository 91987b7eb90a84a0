"""Physical parameters of a 3-RPS manipulator, a pose, and the analytical model's fidelity.

Everything here is in SI units (m, kg, Pa, rad). Scene files speak millimetres and degrees;
`pipeline.scene` converts once, at the edge, and hands these plain dataclasses inward.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
import math

BEAM_THEORIES = ("euler-bernoulli", "timoshenko")
PLATFORM_INERTIAS = ("plate", "paper-eq8")
PLATFORM_SHAPES = ("disk", "triangle")
R_JOINT_COORDINATES = ("axis", "paper-eq18")
MAX_ELEMENTS = 200  # dense 18 s x 18 s model: 3600 coordinates at most


@dataclass(frozen=True)
class Material:
    youngs_modulus: float  # Pa
    shear_modulus: float  # Pa
    density: float  # kg/m^3

    @property
    def poisson_ratio(self) -> float:
        """nu = E / (2 G) - 1 (isotropic)."""
        return self.youngs_modulus / (2.0 * self.shear_modulus) - 1.0


@dataclass(frozen=True)
class Manipulator:
    """Geometry and material of a 3-RPS manipulator (paper Section 2).

    B_i (revolute joints) lie on the base circle of radius `base_radius`; A_i (spherical joints)
    lie on the platform circle of radius `platform_radius`, both at the polar angles
    `leg_angles` (rad), measured from the base x-axis. Each R-joint axis is horizontal and
    perpendicular to O->B_i.
    """

    base_radius: float  # r1, m
    platform_radius: float  # r2, m
    leg_diameter: float  # d, m
    platform_thickness: float  # h, m
    material: Material
    leg_angles: tuple[float, float, float] = (0.0, 2 * math.pi / 3, 4 * math.pi / 3)
    platform_shape: str = "disk"  # plate outline: "disk" of radius r2, or "triangle" A1A2A3
    actuator_min: float = 0.2  # L_min, m (Eq. 25)
    actuator_max: float = 1.0  # L_max, m (Eq. 25)
    s_joint_max: float = math.radians(45.0)  # alpha_max, rad (Eq. 25)
    r_joint_max: float = math.radians(45.0)  # beta_max, rad (Eq. 25)

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

    elements: int = 3  # s, beam elements per leg
    beam: str = "euler-bernoulli"
    platform_inertia: str = "plate"  # true plate inertia, or Eq. (8)'s m r2^2 on every axis
    r_joint_coordinate: str = "axis"  # regular form, or the paper's Eq. (18)/(21) ratio form
    modes: int = 6
    shear_coefficient: float | None = None  # None: Cowper's value for a solid circle

    def __post_init__(self) -> None:
        if not isinstance(self.elements, int) or not 1 <= self.elements <= MAX_ELEMENTS:
            raise ValueError(f"elements = {self.elements!r}: need an integer in "
                             f"[1, {MAX_ELEMENTS}] (frequencies converge to 1e-4 by s = 10)")
        if self.beam not in BEAM_THEORIES:
            raise ValueError(f"beam = {self.beam!r}: expected one of {', '.join(BEAM_THEORIES)}")
        if self.platform_inertia not in PLATFORM_INERTIAS:
            raise ValueError(
                f"platform_inertia = {self.platform_inertia!r}: expected one of "
                f"{', '.join(PLATFORM_INERTIAS)}"
            )
        if self.r_joint_coordinate not in R_JOINT_COORDINATES:
            raise ValueError(
                f"r_joint_coordinate = {self.r_joint_coordinate!r}: expected one of "
                f"{', '.join(R_JOINT_COORDINATES)}"
            )
        if not isinstance(self.modes, int) or self.modes < 1:
            raise ValueError(f"modes = {self.modes!r}: need an integer >= 1")


def check_manipulator(m: Manipulator) -> None:
    """Raise ValueError naming the first non-physical parameter."""
    positive = {
        "base_radius": m.base_radius,
        "platform_radius": m.platform_radius,
        "leg_diameter": m.leg_diameter,
        "platform_thickness": m.platform_thickness,
        "actuator_min": m.actuator_min,
        "actuator_max": m.actuator_max,
        "youngs_modulus": m.material.youngs_modulus,
        "shear_modulus": m.material.shear_modulus,
        "density": m.material.density,
        "s_joint_max": m.s_joint_max,
        "r_joint_max": m.r_joint_max,
    }
    for name, value in positive.items():
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"{name} = {value!r}: must be a finite positive number")
    if m.actuator_min >= m.actuator_max:
        raise ValueError(
            f"actuator_min = {m.actuator_min} m is not below actuator_max = {m.actuator_max} m"
        )
    nu = m.material.poisson_ratio
    if not -1.0 < nu < 0.5:
        raise ValueError(f"poisson ratio E/(2G) - 1 = {nu:.4g}: must lie in (-1, 0.5)")
    if m.platform_shape not in PLATFORM_SHAPES:
        raise ValueError(
            f"platform_shape = {m.platform_shape!r}: expected one of {', '.join(PLATFORM_SHAPES)}"
        )
