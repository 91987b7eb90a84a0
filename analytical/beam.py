"""3D two-node frame elements: stiffness and mass in the element frame (paper Eq. 4).

Local x runs along the element from node 1 to node 2. Each node carries six coordinates in the
order (u_x, u_y, u_z, theta_x, theta_y, theta_z), so an element has 12. Bending in the x-y plane
uses (u_y, theta_z); bending in the x-z plane uses (u_z, theta_y), where theta_y = -du_z/dx.

Two theories:
- Euler-Bernoulli: cubic Hermite bending, linear axial and torsion, consistent translational mass
  and torsional (polar) inertia; no rotary inertia of bending, no shear deformation.
- Timoshenko: the shear-flexible element of Przemieniecki (Theory of Matrix Structural Analysis,
  1968) with shear parameter Phi = 12 E I / (kappa G A L^2), consistent translational and rotary
  inertia (the latter as in Friedman & Kosmatka, Comput. Struct. 47, 1993). Phi = 0 and no rotary
  inertia recover Euler-Bernoulli's bending exactly. Its axial and torsional mass is the
  average of the consistent and the lumped one, rho A h [[5, 1], [1, 5]] / 12: a wave of
  wavenumber k on elements h long then has omega_h^2 = 12 (c / h)^2 (1 - cos kh) / (5 + cos kh)
  = (c k)^2 (1 - (k h)^4 / 240 + ...), a frequency error of -(k h)^4 / 480 instead of the
  consistent mass's +(k h)^2 / 24, so a leg's torsion and axial modes are as
  converged at s = 3-5 as its bending (measured: a leg's quarter-wave torsion mode +0.22 % at
  s = 5 with the consistent mass, the whole error of the joint-end model's worst workspace mode).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from common.errors import InputError


@dataclass(frozen=True)
class Section:
    """Cross-section properties (SI)."""

    area: float  # A, m^2
    second_moment_y: float  # I_y, m^4 (bending in x-z)
    second_moment_z: float  # I_z, m^4 (bending in x-y)
    torsion_constant: float  # J, m^4 (St Venant)
    polar_moment: float  # I_p = I_y + I_z, m^4 (torsional inertia)
    shear_coefficient: float  # kappa

    @classmethod
    def solid_circle(cls, diameter: float, poisson_ratio: float,
                     shear: str = "cowper") -> "Section":
        """A solid circular section with the shear coefficient kappa of `shear`."""
        r = diameter / 2.0
        i = math.pi * r**4 / 4.0
        return cls(math.pi * r**2, i, i, 2.0 * i, 2.0 * i,
                   circle_shear_coefficient(poisson_ratio, shear))

    @classmethod
    def circle(cls, outer: float, inner: float, poisson_ratio: float,
               shear: str = "cowper") -> "Section":
        """A solid (inner = 0) or hollow circle of diameters `outer` and `inner`:
        A = pi (a^2 - b^2), I = pi (a^4 - b^4) / 4, J = I_p = 2 I (a circle's St Venant
        constant is its polar moment), kappa from `circle_shear_coefficient`."""
        if inner == 0.0:
            return cls.solid_circle(outer, poisson_ratio, shear)
        a, b = outer / 2.0, inner / 2.0
        i = math.pi * (a**4 - b**4) / 4.0
        return cls(math.pi * (a**2 - b**2), i, i, 2.0 * i, 2.0 * i,
                   circle_shear_coefficient(poisson_ratio, shear, b / a))


SHEAR_COEFFICIENTS = ("cowper", "hutchinson")


def circle_shear_coefficient(poisson_ratio: float, form: str = "cowper",
                             bore: float = 0.0) -> float:
    """Timoshenko shear coefficient of a circle, solid (bore = 0) or hollow with inner to outer
    radius ratio `bore` = m = b / a:

    - Cowper (J. Appl. Mech. 33, 1966): 6 (1+nu) (1+m^2)^2 / ((7+6nu) (1+m^2)^2 + (20+12nu) m^2),
      6(1+nu)/(7+6nu) solid, 2(1+nu)/(4+3nu) for a thin tube;
    - Hutchinson (J. Appl. Mech. 68, 2001): 6 (1+m^2)^2 (1+nu)^2 / ((7+12nu+4nu^2)(1+m^4)
      + (34+48nu+16nu^2) m^2), 6(1+nu)^2/(7+12nu+4nu^2) solid, (1+nu)/(2+nu) for a thin tube.
    """
    nu, m2 = poisson_ratio, bore**2
    if not 0.0 <= bore < 1.0:
        raise InputError(f"bore ratio = {bore!r}: expected 0 <= inner / outer < 1")
    if form == "cowper":
        return 6.0 * (1.0 + nu) * (1 + m2) ** 2 / ((7.0 + 6.0 * nu) * (1 + m2) ** 2
                                                    + (20.0 + 12.0 * nu) * m2)
    if form == "hutchinson":
        return 6.0 * (1 + m2) ** 2 * (1.0 + nu) ** 2 / (
            (7.0 + 12.0 * nu + 4.0 * nu**2) * (1 + m2**2) + (34.0 + 48.0 * nu + 16.0 * nu**2) * m2)
    raise InputError(f"shear = {form!r}: expected one of {', '.join(SHEAR_COEFFICIENTS)}")


def _matrix(rows, shape: tuple) -> np.ndarray:
    """A matrix from rows of entries, each a scalar or an array of `shape`: (*shape, n, m)."""
    if not shape:
        return np.array(rows, float)
    out = np.empty(shape + (len(rows), len(rows[0])))
    for i, row in enumerate(rows):
        for j, entry in enumerate(row):
            out[..., i, j] = entry
    return out


def _bending_stiffness(ei: float, length, shear_param) -> np.ndarray:
    """4x4 bending stiffness on (w1, slope1, w2, slope2), slope = +dw/dx (batched over the
    leading shape of `length`)."""
    L, p = length, shear_param
    c = ei / ((1.0 + p) * L**3)
    return np.asarray(c)[..., None, None] * _matrix([
        [12.0, 6 * L, -12.0, 6 * L],
        [6 * L, (4 + p) * L**2, -6 * L, (2 - p) * L**2],
        [-12.0, -6 * L, 12.0, -6 * L],
        [6 * L, (2 - p) * L**2, -6 * L, (4 + p) * L**2],
    ], np.shape(L))


def _bending_mass(rho_a: float, rho_i: float, length, shear_param) -> np.ndarray:
    """4x4 consistent bending mass on (w1, slope1, w2, slope2): translational + rotary."""
    L, p = length, shear_param
    t = rho_a * L / (1.0 + p) ** 2
    a = 13 / 35 + 7 * p / 10 + p**2 / 3
    b = (11 / 210 + 11 * p / 120 + p**2 / 24) * L
    c = 9 / 70 + 3 * p / 10 + p**2 / 6
    d = (13 / 420 + 3 * p / 40 + p**2 / 24) * L
    e = (1 / 105 + p / 60 + p**2 / 120) * L**2
    f = (1 / 140 + p / 60 + p**2 / 120) * L**2
    translational = np.asarray(t)[..., None, None] * _matrix([
        [a, b, c, -d],
        [b, e, d, -f],
        [c, d, a, -b],
        [-d, -f, -b, e],
    ], np.shape(L))
    if rho_i == 0.0:
        return translational
    r = rho_i / ((1.0 + p) ** 2 * L)
    g = (1 / 10 - p / 2) * L
    h = (2 / 15 + p / 6 + p**2 / 3) * L**2
    k = (1 / 30 + p / 6 - p**2 / 6) * L**2
    rotary = np.asarray(r)[..., None, None] * _matrix([
        [6 / 5, g, -6 / 5, g],
        [g, h, -g, -k],
        [-6 / 5, -g, 6 / 5, -g],
        [g, -k, -g, h],
    ], np.shape(L))
    return translational + rotary


# Local coordinates of each 4x4 bending block in the 12x12 element ordering.
_PLANE_XY = np.array([1, 5, 7, 11])  # (u_y1, theta_z1, u_y2, theta_z2); theta_z = +du_y/dx
_PLANE_XZ = np.array([2, 4, 8, 10])  # (u_z1, theta_y1, u_z2, theta_y2); theta_y = -du_z/dx
# (w, theta_y) = diag(1, -1, 1, -1) (w, dw/dx): the x-z block is D k D, i.e. k * outer(d, d)
_FLIP_XZ = np.outer([1.0, -1.0, 1.0, -1.0], [1.0, -1.0, 1.0, -1.0])
_IX_XY = np.ix_(_PLANE_XY, _PLANE_XY)
_IX_XZ = np.ix_(_PLANE_XZ, _PLANE_XZ)
_IX_AXIAL = np.ix_([0, 6], [0, 6])
_IX_TWIST = np.ix_([3, 9], [3, 9])
_BAR = np.array([[1.0, -1.0], [-1.0, 1.0]])
_BAR_MASS = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6.0  # consistent
_BAR_MASS_HIGHER = np.array([[5.0, 1.0], [1.0, 5.0]]) / 12.0  # (consistent + lumped) / 2


def frame_element(youngs_modulus: float, shear_modulus: float, density: float,
                  section: Section, length, theory: str = "euler-bernoulli"
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Element stiffness and mass (consistent; Timoshenko's rod part averaged, module doc),
    each 12x12, in the element frame.

    `theory` is "euler-bernoulli" or "timoshenko". `length` may be an array of lengths: the
    matrices then carry its shape in front, (..., 12, 12), one element per length.
    """
    L = float(length) if np.ndim(length) == 0 else np.asarray(length, float)
    if not np.all(np.greater(L, 0.0)):
        raise InputError(f"element length = {float(np.min(L))!r} m: must be positive")
    E, G, rho, s = youngs_modulus, shear_modulus, density, section
    # shear parameter of each bending plane: x-y bends on I_z, x-z bends on I_y
    phi_xy: float | np.ndarray
    phi_xz: float | np.ndarray
    if theory == "euler-bernoulli":
        phi_xy = phi_xz = 0.0
        rotary = False
    elif theory == "timoshenko":
        phi_xy = 12 * E * s.second_moment_z / (s.shear_coefficient * G * s.area * L**2)
        phi_xz = 12 * E * s.second_moment_y / (s.shear_coefficient * G * s.area * L**2)
        rotary = True
    else:
        raise InputError(f"beam theory = {theory!r}: expected euler-bernoulli or timoshenko")

    k = np.zeros(np.shape(L) + (12, 12))
    m = np.zeros(np.shape(L) + (12, 12))
    per_length = np.asarray(L)[..., None, None]
    rod_mass = _BAR_MASS_HIGHER if theory == "timoshenko" else _BAR_MASS
    k[..., _IX_AXIAL[0], _IX_AXIAL[1]] = E * s.area / per_length * _BAR
    m[..., _IX_AXIAL[0], _IX_AXIAL[1]] = rho * s.area * per_length * rod_mass
    k[..., _IX_TWIST[0], _IX_TWIST[1]] = G * s.torsion_constant / per_length * _BAR
    m[..., _IX_TWIST[0], _IX_TWIST[1]] = rho * s.polar_moment * per_length * rod_mass
    k[..., _IX_XY[0], _IX_XY[1]] = _bending_stiffness(E * s.second_moment_z, L, phi_xy)
    m[..., _IX_XY[0], _IX_XY[1]] = _bending_mass(
        rho * s.area, rho * s.second_moment_z if rotary else 0.0, L, phi_xy)
    k[..., _IX_XZ[0], _IX_XZ[1]] = _FLIP_XZ * _bending_stiffness(E * s.second_moment_y, L,
                                                                 phi_xz)
    m[..., _IX_XZ[0], _IX_XZ[1]] = _FLIP_XZ * _bending_mass(
        rho * s.area, rho * s.second_moment_y if rotary else 0.0, L, phi_xz)
    return k, m


def assemble_beam(youngs_modulus: float, shear_modulus: float, density: float,
                  section: Section, length, elements: int,
                  theory: str = "euler-bernoulli") -> tuple[np.ndarray, np.ndarray]:
    """Stiffness and mass of a straight uniform beam of `elements` equal elements, in its frame.

    Returns two 6(s+1) x 6(s+1) matrices on the nodes 0..s from one end to the other; an
    array of lengths gives one beam per length, (..., 6(s+1), 6(s+1)).
    """
    if elements < 1:
        raise InputError(f"elements = {elements!r}: need at least one")
    ke, me = frame_element(youngs_modulus, shear_modulus, density, section,
                           np.divide(length, elements), theory)
    n = 6 * (elements + 1)
    k = np.zeros(ke.shape[:-2] + (n, n))
    m = np.zeros(ke.shape[:-2] + (n, n))
    for e in range(elements):
        sl = slice(6 * e, 6 * e + 12)
        k[..., sl, sl] += ke
        m[..., sl, sl] += me
    return k, m
