"""The regenerative milling model both stability methods share: the tool's modes in the plane of
the cut and the periodic cutting-force matrix.

The tool point moves r(t) = U q(t) in the cut's (x, y) (x along the feed), with mass-normalised
modes q_j'' + 2 zeta_j omega_j q_j' + omega_j^2 q_j = U_j . F. Tooth j at phi_j(t) =
Omega t + 2 pi j / N (Omega = 2 pi n, n rev/s) cuts the dynamic chip h = dx sin phi + dy cos phi,
dr = r(t) - r(t - tau), tau = 1 / (N n) the tooth period (Altintas, Manufacturing Automation,
2nd ed., 2012, Eq. 3.52-3.55; Insperger & Stepan, IJNME 61:117, 2004, Eq. 44 in one direction).
With F_t = K_t b h and F_r = K_n b h at axial depth b,

    F(t) = b K(t) (r(t) - r(t - tau)),   K(t) = sum_j g(phi_j) D(phi_j),
    D(phi) = [[-p sin, -p cos], [q sin, q cos]],   p = K_t cos + K_n sin,   q = K_t sin - K_n cos,

g = 1 while the tooth is in the cut (chatter.cutting.Cutting.engagement), 0 out of it. The
zero-order method averages K over a tooth period (A0 = N / (2 pi) int D), semi-discretization
keeps it periodic."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from common.errors import InputError

MIN_RATIO, MAX_RATIO = 1e-5, 0.9  # a mode damped less rings for ever; more is not a mode


@dataclass(frozen=True)
class ToolModes:
    """The tool point's modes in the cut's plane: circular frequencies (rad/s), damping ratios
    and mass-normalised displacements U (2, m), rows x (feed) and y, 1/sqrt(kg)."""

    omega: np.ndarray
    zeta: np.ndarray
    shape: np.ndarray

    def __post_init__(self) -> None:
        omega, zeta, shape = (np.asarray(a, float) for a in (self.omega, self.zeta, self.shape))
        if omega.ndim != 1 or zeta.shape != omega.shape or shape.shape != (2, len(omega)):
            raise InputError("tool modes: frequencies, damping ratios and x/y shapes of "
                             "different lengths")
        if not len(omega):
            raise InputError("tool modes: no mode given")
        bad = ~np.isfinite(omega) | (omega <= 0.0)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise InputError(f"tool mode {k + 1}: frequency {omega[k] / (2 * math.pi):g} Hz; "
                             "expected a finite frequency above 0 Hz")
        bad = ~np.isfinite(zeta) | (zeta < MIN_RATIO) | (zeta > MAX_RATIO)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise InputError(f"tool mode {k + 1}: damping ratio {zeta[k]:g}; expected "
                             f"{MIN_RATIO:g} to {MAX_RATIO:g} (a ratio, not a percentage)")
        if not np.isfinite(shape).all():
            raise InputError("tool modes: a shape value is not a finite number")
        if not (np.abs(shape) > 0.0).any():
            raise InputError("tool modes: no mode moves the tool in x or y (every shape is 0): "
                             "nothing can chatter")
        object.__setattr__(self, "omega", omega)
        object.__setattr__(self, "zeta", zeta)
        object.__setattr__(self, "shape", shape)

    @property
    def count(self) -> int:
        return len(self.omega)

    def receptance(self, w) -> np.ndarray:
        """G (nw, 2, 2) complex, m/N, at circular frequencies w (nw,)."""
        w = np.asarray(w, float)[:, None]
        terms = 1.0 / (self.omega**2 - w**2 + 2j * self.zeta * self.omega * w)
        return np.einsum("fj,dj,ej->fde", terms, self.shape, self.shape)

    def modal_stiffness(self) -> np.ndarray:
        """k_dj = omega_j^2 / U_dj^2 (2, m), N/m (inf where the mode leaves d still)."""
        with np.errstate(divide="ignore"):
            return np.where(self.shape != 0.0, self.omega**2 / self.shape**2, np.inf)


def tooth_matrix(phi, kt: float, kn: float) -> np.ndarray:
    """D(phi) (..., 2, 2): one tooth's force per unit depth and unit dynamic displacement."""
    s, c = np.sin(phi), np.cos(phi)
    p, q = kt * c + kn * s, kt * s - kn * c
    return np.stack([np.stack([-p * s, -p * c], -1), np.stack([q * s, q * c], -1)], -2)


def tooth_matrix_slope(phi, kt: float, kn: float) -> np.ndarray:
    """dD/dphi (..., 2, 2) (dp/dphi = -q, dq/dphi = p)."""
    s, c = np.sin(phi), np.cos(phi)
    p, q = kt * c + kn * s, kt * s - kn * c
    return np.stack([np.stack([q * s - p * c, q * c + p * s], -1),
                     np.stack([p * s + q * c, p * c - q * s], -1)], -2)


def engaged(phi, start: float, exit_: float) -> np.ndarray:
    """g(phi): the tooth at angle phi (any turn) is in the cut."""
    a = np.mod(np.asarray(phi, float) - start, 2 * math.pi)
    return a < (exit_ - start)


def force_matrix(phi0, teeth: int, start: float, exit_: float, kt: float, kn: float,
                 slope: bool = False) -> np.ndarray:
    """K (or dK/dphi with `slope`) (..., 2, 2) with the first tooth at phi0 and `teeth` evenly
    spaced; g is read at phi0 itself (the caller picks the side of an entry or exit)."""
    phi0 = np.asarray(phi0, float)
    out = np.zeros(phi0.shape + (2, 2))
    f = tooth_matrix_slope if slope else tooth_matrix
    for j in range(teeth):
        phi = phi0 + 2 * math.pi * j / teeth
        out += np.where(engaged(phi, start, exit_)[..., None, None], f(phi, kt, kn), 0.0)
    return out


def mean_force_matrix(teeth: int, start: float, exit_: float, kt: float, kn: float
                      ) -> np.ndarray:
    """A0 = N / (2 pi) int_start^exit D(phi) dphi (2, 2), in closed form (the zero-order
    method's time-averaged matrix, Altintas & Budak 1995 Eq. 10 times K_t / 2)."""
    def primitive(f: float) -> np.ndarray:
        s2, h, c2 = math.sin(f) ** 2, f / 2.0, math.sin(2 * f) / 4.0
        return np.array([[-kt * s2 / 2 - kn * (h - c2), -kt * (h + c2) - kn * s2 / 2],
                         [kt * (h - c2) - kn * s2 / 2, kt * s2 / 2 - kn * (h + c2)]])
    return teeth / (2 * math.pi) * (primitive(exit_) - primitive(start))


def breakpoints(teeth: int, start: float, exit_: float) -> tuple[float, list[float]]:
    """One tooth period's engagement segments as angles from the first tooth's entry: (the
    period 2 pi / N, the segment ends within it, last = the period): the set of teeth in the
    cut is the same all along a segment."""
    period = 2 * math.pi / teeth
    span = exit_ - start
    inner = math.fmod(span, period)
    if inner <= 1e-12 * period or period - inner <= 1e-12 * period:
        return period, [period]
    return period, [inner, period]
