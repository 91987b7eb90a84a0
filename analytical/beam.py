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


# The bending blocks of the closed forms, each a sum of terms coefficient * L^a * Phi^b /
# (1 + Phi)^d times a fixed 4 x 4 pattern on (w1, slope1, w2, slope2), slope = +dw/dx. Written
# out, as the references print them (c = E I / ((1 + Phi) L^3), t = rho A L / (1 + Phi)^2,
# r = rho I / ((1 + Phi)^2 L)):
#   stiffness        c [[12, 6L, -12, 6L], [6L, (4+Phi)L^2, -6L, (2-Phi)L^2],
#                       [-12, -6L, 12, -6L], [6L, (2-Phi)L^2, -6L, (4+Phi)L^2]]
#   translational    t [[A, B, C, -D], [B, E, D, -F], [C, D, A, -B], [-D, -F, -B, E]],
#                    A = 13/35 + 7Phi/10 + Phi^2/3, B = (11/210 + 11Phi/120 + Phi^2/24) L,
#                    C = 9/70 + 3Phi/10 + Phi^2/6, D = (13/420 + 3Phi/40 + Phi^2/24) L,
#                    E = (1/105 + Phi/60 + Phi^2/120) L^2, F = (1/140 + Phi/60 + Phi^2/120) L^2
#   rotary           r [[6/5, G, -6/5, G], [G, H, -G, -K], [-6/5, -G, 6/5, -G], [G, -K, -G, H]],
#                    G = (1/10 - Phi/2) L, H = (2/15 + Phi/6 + Phi^2/3) L^2,
#                    K = (1/30 + Phi/6 - Phi^2/6) L^2
# Each matrix is then one product of the terms' factors (a few array operations for any number
# of lengths) with their patterns, instead of one array operation per entry.

def _stiffness_pattern(k3: float, k2: float, k1: float, k1_phi: float) -> np.ndarray:
    """The stiffness layout split by the power of L an entry carries: its L^0 entries (12)
    times k3, its L^1 entries (6 L) times k2, its L^2 entries' constants (4, 2) times k1 and
    their Phi parts (+Phi, -Phi) times k1_phi."""
    return np.array([[12 * k3, 6 * k2, -12 * k3, 6 * k2],
                     [6 * k2, 4 * k1 + k1_phi, -6 * k2, 2 * k1 - k1_phi],
                     [-12 * k3, -6 * k2, 12 * k3, -6 * k2],
                     [6 * k2, 2 * k1 - k1_phi, -6 * k2, 4 * k1 + k1_phi]])


def _translational_pattern(a, b, c, d, e, f) -> np.ndarray:
    return np.array([[a, b, c, -d], [b, e, d, -f], [c, d, a, -b], [-d, -f, -b, e]])


def _rotary_pattern(s, g, h, k) -> np.ndarray:
    return np.array([[s, g, -s, g], [g, h, -g, -k], [-s, -g, s, -g], [g, -k, -g, h]])


# (power of L, power of Phi, power of 1 / (1 + Phi), 4 x 4 pattern) per term
_STIFFNESS_TERMS = ((-3, 0, 1, _stiffness_pattern(1, 0, 0, 0)),
                    (-2, 0, 1, _stiffness_pattern(0, 1, 0, 0)),
                    (-1, 0, 1, _stiffness_pattern(0, 0, 1, 0)),
                    (-1, 1, 1, _stiffness_pattern(0, 0, 0, 1)))
_TRANSLATIONAL_TERMS = tuple(
    term for j, (a, b, c, d, e, f) in enumerate((
        (13 / 35, 11 / 210, 9 / 70, 13 / 420, 1 / 105, 1 / 140),
        (7 / 10, 11 / 120, 3 / 10, 3 / 40, 1 / 60, 1 / 60),
        (1 / 3, 1 / 24, 1 / 6, 1 / 24, 1 / 120, 1 / 120)))
    for term in ((1, j, 2, _translational_pattern(a, 0, c, 0, 0, 0)),
                 (2, j, 2, _translational_pattern(0, b, 0, d, 0, 0)),
                 (3, j, 2, _translational_pattern(0, 0, 0, 0, e, f))))
_ROTARY_TERMS = ((-1, 0, 2, _rotary_pattern(6 / 5, 0, 0, 0)),
                 (0, 0, 2, _rotary_pattern(0, 1 / 10, 0, 0)),
                 (0, 1, 2, _rotary_pattern(0, -1 / 2, 0, 0)),
                 (1, 0, 2, _rotary_pattern(0, 0, 2 / 15, 1 / 30)),
                 (1, 1, 2, _rotary_pattern(0, 0, 1 / 6, 1 / 6)),
                 (1, 2, 2, _rotary_pattern(0, 0, 1 / 3, -1 / 6)))


# Local coordinates of each 4x4 bending block in the 12x12 element ordering.
_PLANE_XY = np.array([1, 5, 7, 11])  # (u_y1, theta_z1, u_y2, theta_z2); theta_z = +du_y/dx
_PLANE_XZ = np.array([2, 4, 8, 10])  # (u_z1, theta_y1, u_z2, theta_y2); theta_y = -du_z/dx
# (w, theta_y) = diag(1, -1, 1, -1) (w, dw/dx): the x-z block is D k D, i.e. k * outer(d, d)
_FLIP_XZ = np.outer([1.0, -1.0, 1.0, -1.0], [1.0, -1.0, 1.0, -1.0])
_BAR = np.array([[1.0, -1.0], [-1.0, 1.0]])
_BAR_MASS = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6.0  # consistent
_BAR_MASS_HIGHER = np.array([[5.0, 1.0], [1.0, 5.0]]) / 12.0  # (consistent + lumped) / 2
_NO_PLANE, _XY, _XZ = 0, 1, 2  # which shear parameter a term's Phi is
# what multiplies a term: E A, G J, E I_z, E I_y, rho A, rho I_p, rho I_z, rho I_y
_EA, _GJ, _EIZ, _EIY, _RHO_A, _RHO_IP, _RHO_IZ, _RHO_IY = range(8)


@dataclass(frozen=True)
class _Terms:
    """K or M of an element as sum_t property_t L^a_t Phi_t^b_t / (1 + Phi_t)^d_t P_t."""

    patterns: np.ndarray  # (T, e): P_t on the entries some term reaches
    entries: np.ndarray  # (e,): those entries' indices in the flattened 12 x 12
    powers: np.ndarray  # (3, T) integers: a (-3..3), b (0..2), d (0..2)
    plane: np.ndarray  # (T,): which Phi (none, x-y, x-z)
    source: np.ndarray  # (T,): which section property (_EA ... _RHO_IY)

    @classmethod
    def of(cls, terms: list) -> "_Terms":
        """From (a, b, d, plane, property, 12 x 12 P_t) per term."""
        patterns = np.array([t[5].ravel() for t in terms])
        entries = np.flatnonzero(np.any(patterns != 0.0, axis=0))
        return cls(patterns[:, entries], entries, np.array([t[:3] for t in terms]).T,
                   np.array([t[3] for t in terms]), np.array([t[4] for t in terms]))

    def evaluate(self, tables: tuple[np.ndarray, np.ndarray, np.ndarray],
                 properties: np.ndarray) -> np.ndarray:
        """(N, 12, 12) from `_factor_tables` of N lengths and the section's properties."""
        by_power, per_phi, per_shrink = tables
        a, b, d = self.powers
        factors = (properties[self.source] * by_power[:, a + 3]
                   * per_phi[:, 3 * b + self.plane] * per_shrink[:, 3 * d + self.plane])
        out = np.zeros((len(factors), 144))
        out[:, self.entries] = factors @ self.patterns
        return out.reshape(len(factors), 12, 12)


def _factor_tables(length: np.ndarray, shear: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per length (N,): L^-3 .. L^3 (N, 7), Phi^0..2 and (1 + Phi)^-(0..2) (N, 9) with Phi of no
    plane (0), x-y and x-z, Phi = shear / L^2 (shear: Phi L^2 per plane)."""
    inverse = 1.0 / length
    square = inverse * inverse
    by_power = np.stack([square * inverse, square, inverse, np.ones_like(length), length,
                         length * length, length * length * length], axis=1)
    phi = np.zeros((len(length), 3))
    phi[:, 1:] = shear * square[:, None]
    shrink = 1.0 / (1.0 + phi)
    ones = np.ones_like(phi)
    return (by_power, np.concatenate([ones, phi, phi * phi], axis=1),
            np.concatenate([ones, shrink, shrink * shrink], axis=1))


def _placed(block: np.ndarray, index) -> np.ndarray:
    out = np.zeros((12, 12))
    out[np.ix_(index, index)] = block
    return out


def _element_terms(timoshenko: bool) -> tuple[_Terms, _Terms]:
    """The terms of K and M of either theory (no shear terms and no rotary inertia in
    Euler-Bernoulli's; Timoshenko's rod mass the averaged one)."""
    rod_mass = _BAR_MASS_HIGHER if timoshenko else _BAR_MASS
    axial, twist = [0, 6], [3, 9]
    stiffness = [(-1, 0, 0, _NO_PLANE, _EA, _placed(_BAR, axial)),
                 (-1, 0, 0, _NO_PLANE, _GJ, _placed(_BAR, twist))]
    mass = [(1, 0, 0, _NO_PLANE, _RHO_A, _placed(rod_mass, axial)),
            (1, 0, 0, _NO_PLANE, _RHO_IP, _placed(rod_mass, twist))]
    for plane, index, flip, bending, rotary in ((_XY, _PLANE_XY, 1.0, _EIZ, _RHO_IZ),
                                               (_XZ, _PLANE_XZ, _FLIP_XZ, _EIY, _RHO_IY)):
        for terms, source, out in ((_STIFFNESS_TERMS, bending, stiffness),
                                   (_TRANSLATIONAL_TERMS, _RHO_A, mass),
                                   (_ROTARY_TERMS if timoshenko else (), rotary, mass)):
            out.extend((a, b, d, plane, source, _placed(flip * pattern, index))
                       for a, b, d, pattern in terms if timoshenko or b == 0)
    return _Terms.of(stiffness), _Terms.of(mass)


_THEORIES = {"euler-bernoulli": _element_terms(False), "timoshenko": _element_terms(True)}


def frame_element(youngs_modulus: float, shear_modulus: float, density: float,
                  section: Section, length, theory: str = "euler-bernoulli"
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Element stiffness and mass (consistent; Timoshenko's rod part averaged, module doc),
    each 12x12, in the element frame.

    `theory` is "euler-bernoulli" or "timoshenko". `length` may be an array of lengths: the
    matrices then carry its shape in front, (..., 12, 12), one element per length. The shear
    parameter of each bending plane: x-y bends on I_z, x-z on I_y.
    """
    L = np.asarray(length, float)
    if not np.all(np.greater(L, 0.0)):
        raise InputError(f"element length = {float(np.min(L))!r} m: must be positive")
    if theory not in _THEORIES:
        raise InputError(f"beam theory = {theory!r}: expected euler-bernoulli or timoshenko")
    E, G, rho, s = youngs_modulus, shear_modulus, density, section
    properties = np.array([E * s.area, G * s.torsion_constant, E * s.second_moment_z,
                           E * s.second_moment_y, rho * s.area, rho * s.polar_moment,
                           rho * s.second_moment_z, rho * s.second_moment_y])
    shear = (12 * E / (s.shear_coefficient * G * s.area)
             * np.array([s.second_moment_z, s.second_moment_y]) if theory == "timoshenko"
             else np.zeros(2))  # Phi L^2 per plane: x-y bends on I_z, x-z on I_y
    k_terms, m_terms = _THEORIES[theory]
    tables = _factor_tables(L.reshape(-1), shear)
    shape = L.shape + (12, 12)
    return (k_terms.evaluate(tables, properties).reshape(shape),
            m_terms.evaluate(tables, properties).reshape(shape))


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
