"""The regenerative milling equation integrated in time, independently of the stability
methods: the referee of their depths (tests/test_lobes.py). Classical fourth-order Runge-Kutta
with a fixed step h = tau / steps (the delay is a whole number of steps), the force
b K(t) (r(t) - r(t - tau)) with K read at each stage's own time (the teeth that cut then), the
delayed values at the half steps from the cubic Hermite interpolant of the stored r and r'.
It returns the largest tool displacement of each tooth period: a cut below its critical
depth decays, one above it grows, and the growth per period tends to the largest multiplier's
modulus."""
from __future__ import annotations

import math

import numpy as np

from .milling import ToolModes, force_matrix
from .sdm import Cut


def period_amplitudes(modes: ToolModes, cut: Cut, speed_hz: float, depths, periods: int,
                      steps: int = 400, seed: int = 1) -> np.ndarray:
    """max |r| over each tooth period (len(depths), periods), from a small random start with
    a still past (every depth the same start)."""
    depths = np.asarray(depths, float)
    nb, m = len(depths), modes.count
    tau = 1.0 / (cut.teeth * speed_hz)
    h = tau / steps
    rate = 2 * math.pi * speed_hz
    u = modes.shape
    w, z = modes.omega, modes.zeta
    rng = np.random.default_rng(seed)
    q = np.tile(rng.normal(size=m) * 1e-6, (nb, 1))
    v = np.zeros((nb, m))
    hist_r = np.zeros((steps + 1, nb, 2))  # the last period's r and r' at the steps
    hist_v = np.zeros((steps + 1, nb, 2))
    out = np.zeros((nb, periods))

    def k_at(t: float) -> np.ndarray:
        return force_matrix(cut.start + rate * t, cut.teeth, cut.start, cut.exit, cut.kt,
                            cut.kn)

    def accel(q, v, t, r_old):
        r = q @ u.T
        force = depths[:, None] * np.einsum("de,be->bd", k_at(t), r - r_old)
        return force @ u - 2 * z * w * v - w**2 * q

    t = 0.0
    for p in range(periods):
        peak = np.zeros(nb)
        for k in range(steps):
            r0, r1 = hist_r[k], hist_r[k + 1]  # the delayed values at t and t + h
            d0, d1 = hist_v[k], hist_v[k + 1]
            rmid = 0.5 * (r0 + r1) + h * (d0 - d1) / 8.0
            k1q, k1v = v, accel(q, v, t, r0)
            k2q, k2v = v + 0.5 * h * k1v, accel(q + 0.5 * h * k1q, v + 0.5 * h * k1v,
                                                t + 0.5 * h, rmid)
            k3q, k3v = v + 0.5 * h * k2v, accel(q + 0.5 * h * k2q, v + 0.5 * h * k2v,
                                                t + 0.5 * h, rmid)
            k4q, k4v = v + h * k3v, accel(q + h * k3q, v + h * k3v, t + h, r1)
            hist_r[k] = q @ u.T  # the present replaces the past at this phase
            hist_v[k] = v @ u.T
            q = q + h / 6.0 * (k1q + 2 * k2q + 2 * k3q + k4q)
            v = v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
            t += h
            peak = np.maximum(peak, np.linalg.norm(q @ u.T, axis=1))
        hist_r[steps] = q @ u.T  # the next period's first delayed value is this one's end
        hist_v[steps] = v @ u.T
        out[:, p] = peak
    return out
