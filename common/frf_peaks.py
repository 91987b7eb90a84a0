"""The peaks of a tool receptance (`common.frf`): where each mode that stands out along a
direction peaks (repeated modes one window), its maximum found on a cheap response (the modal
sum: bounded Brent), or on one known only by solving the damped system at a frequency (the
solid's direct response: five solves across the peak, a rational fit, one solve at its top).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Peak:
    """A resonance peak of |H_dd|: its frequency (Hz), height (m/N) and the mode it is near."""

    frequency_hz: float
    magnitude_m_per_n: float
    mode: int


PEAK_FLOOR = 0.05  # a mode's peak is looked for if its one-mode height is this share of the top
DIRECT_FLOOR = 0.25  # the direct check's: the peaks that set the dynamic stiffness (a weaker
                     # one is a shoulder on a neighbour's flank, which a local fit misplaces)
PEAK_XTOL = 1e-6  # the peak's frequency found to this fraction of it


def peak_windows(omega, zeta, phi, direction: int, floor: float = PEAK_FLOOR
                 ) -> list[tuple[int, float, float]]:
    """(mode, low Hz, high Hz) where the modes that stand out along `direction` peak. Modes
    closer than their half-power bandwidth (zeta f: a repeated pair of a symmetric pose, split
    by round-off) make one visible peak and are one group; a group whose one-mode heights
    phi_d^2 / (2 zeta omega^2) sum to at least `floor` of the largest group's is searched
    within 3 half-power bandwidths of its frequencies and no closer to a neighbouring group
    than half way; its mode is the member standing out most."""
    omega, zeta, phi = (np.asarray(a, float) for a in (omega, zeta, phi))
    f = omega / (2.0 * math.pi)
    height = phi[direction] ** 2 / (2.0 * zeta * omega**2)
    groups: list[list[int]] = []
    for j in range(len(f)):
        if groups and f[j] - f[groups[-1][-1]] <= max(zeta[j], zeta[groups[-1][-1]]) * f[j]:
            groups[-1].append(j)
        else:
            groups.append([j])
    tall = np.array([height[g].sum() for g in groups])
    out = []
    for k, g in enumerate(groups):
        if not tall[k] >= floor * tall.max():
            continue
        lo = max(f[g[0]] * (1.0 - 3.0 * zeta[g[0]]), 1e-3 * f[g[0]])  # above 0 Hz
        hi = f[g[-1]] * (1.0 + 3.0 * zeta[g[-1]])
        if k > 0:
            lo = max(lo, 0.5 * (f[groups[k - 1][-1]] + f[g[0]]))
        if k + 1 < len(groups):
            hi = min(hi, 0.5 * (f[g[-1]] + f[groups[k + 1][0]]))
        if hi > lo:
            out.append((int(g[int(np.argmax(height[g]))]), float(lo), float(hi)))
    return out


def find_peaks(magnitude, windows, xtol: float = PEAK_XTOL) -> list[Peak]:
    """The maximum of `magnitude(f_hz)` in each window (bounded Brent), kept where it is a
    peak inside the window (not at its edge: a neighbour's flank there)."""
    import scipy.optimize

    out = []
    for mode, lo, hi in windows:
        found = scipy.optimize.minimize_scalar(lambda f: -magnitude(f), bounds=(lo, hi),
                                               method="bounded",
                                               options={"xatol": xtol * hi})
        f = float(found.x)
        if min(f - lo, hi - f) > 10.0 * xtol * hi:
            out.append(Peak(f, float(-found.fun), mode))
    return out


FIT_POINTS = (-1.0, -0.5, 0.0, 0.5, 1.0)  # a direct solve's samples across a peak, in zeta f
FIT_GRID = 2001  # the fitted response searched on this many points across the window


def rational_fit(f_hz, h) -> tuple[np.ndarray, np.ndarray]:
    """(numerator, denominator) complex coefficients, ascending in w = 2 pi f, of the rational
    (n0 + n1 w) / (1 + d1 w + d2 w^2) through complex samples h by linearised least squares
    (Levy's method): one resonance (a pole pair) on a linear background, exact for one
    viscously damped mode, r / (w_j^2 - w^2 + 2 i zeta w_j w) (d1 = 2 i zeta / w_j)."""
    w = 2.0 * math.pi * np.asarray(f_hz, float)
    scale = w.mean()
    x = w / scale
    h = np.asarray(h, complex)
    a = np.column_stack([np.ones_like(x), x, -h * x, -h * x**2]).astype(complex)
    n0, n1, d1, d2 = np.linalg.lstsq(a, h, rcond=None)[0]  # complex: the damping is i w
    return (np.array([n0, n1 / scale]), np.array([1.0, d1 / scale, d2 / scale**2]))


def direct_peaks(solve, windows: dict[int, list[tuple[int, float, float]]], omega, zeta
                 ) -> dict[int, list[Peak]]:
    """The peaks of a response known only by solving the damped system at a frequency
    (`solve(f_hz) -> (3, 3)` complex, one factorisation a call: the solid's direct response):
    at each window (mode j) five solves across f_j (+-zeta_j f_j, shared by every direction),
    per direction the rational fit of H_dd through them (`rational_fit`: a resonance on a
    linear background), its maximum on a fine grid of the window, and one more solve there,
    whose |H_dd| is the peak reported (flat to second order in the error of its frequency)."""
    omega, zeta = np.asarray(omega, float), np.asarray(zeta, float)
    memo: dict[float, np.ndarray] = {}

    def at(f: float) -> np.ndarray:
        for known, h in memo.items():
            if abs(known - f) <= 1e-9 * max(f, 1e-300):
                return h
        memo[f] = np.asarray(solve(f))
        return memo[f]

    out: dict[int, list[Peak]] = {}
    for d, found in windows.items():
        out[d] = []
        for mode, lo, hi in found:
            f0 = omega[mode] / (2.0 * math.pi)
            fs = sorted({min(hi, max(lo, f0 * (1.0 + zeta[mode] * s))) for s in FIT_POINTS})
            samples = np.array([at(f)[d, d] for f in fs])
            best = fs[int(np.argmax(np.abs(samples)))]
            if len(fs) >= 4:
                num, den = rational_fit(fs, samples)
                grid = np.linspace(lo, hi, FIT_GRID)
                w = 2.0 * math.pi * grid
                fitted = np.abs(np.polyval(num[::-1], w) / np.polyval(den[::-1], w))
                k = int(np.argmax(fitted))
                if 0 < k < FIT_GRID - 1:
                    best = float(grid[k])
            magnitude = abs(at(best)[d, d])
            sampled = int(np.argmax(np.abs(samples)))
            if magnitude < abs(samples[sampled]):  # the fit missed: the best sample stands
                best, magnitude = fs[sampled], abs(samples[sampled])
            out[d].append(Peak(float(best), float(magnitude), int(mode)))
    return out
