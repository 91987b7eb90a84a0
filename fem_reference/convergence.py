"""Discretisation error of the FEM reference: mesh-refinement study and Richardson extrapolation.

For every mode, f(h) = f_inf + C h^p is fitted to all sizes of the study (at least three; the
size ratios need not be equal) by least squares: for each trial p the fit is linear in (f_inf, C),
and the observed order p_obs minimises the residual (bounded search on [P_MIN, P_FIT_MAX]). With
exactly three sizes this is the classical three-grid Richardson estimate, p solving
    (f1 - f2) / (f2 - f3) = (h1^p - h2^p) / (h2^p - h3^p);
with more sizes it averages out the mesh-to-mesh scatter of unstructured meshes (the orders of
successive triplets, also reported, scatter by +-1 or more on these meshes because each gmsh mesh
is a different tetrahedralisation, not a nested refinement).

The order used is the observed one bounded by theory: p = min(p_obs, P_THEORY). A rigidly
coupled joint face meets the cylinder wall at a bonded 90-degree edge, where the stress is
singular like r^(lambda - 1) with Williams' exponent lambda = 0.712 (the smallest root for a
wedge of angle pi/2 with one face clamped and one free, Poisson ratio 0.3); the eigenvalue error
of any mesh family whose element sizes all scale with h (uniform, or graded toward the rims with
the rim size a fixed fraction of h, meshing.geometry) then falls like h^(2 lambda) = h^1.42
asymptotically, whatever the element order. An observed order above that is pre-asymptotic
(the smooth part of the error still dominates) and would make the extrapolation too short, so
it is not used; an observed order below it is used as observed (it extrapolates further). The
limit is extrapolated from the two finest sizes at that order (the classical Richardson step,
f_inf = f_n - (f_{n-1} - f_n) / ((h_{n-1} / h_n)^p - 1): the coarse sizes of an unnested,
pre-asymptotic sequence would pull a fit at a bounded order off), and the estimated relative
error of every size is |f_h - f_inf| / f_inf plus the RMS residual of the fit at the observed
order relative to f_inf (the mesh-to-mesh scatter that the model does not explain). h is the
effective element size (V / n_nodes)^(1/3) of each mesh, which follows the mesh actually built
better than the nominal gmsh size (both are reported).

A sequence whose differences change sign (non-monotone) or whose observed order is below P_MIN
has no trustworthy order: then `order` is None, `status` says why, the extrapolated value is the
finest result, and the bound is widened, not shrunk: every size's error is |f_h - f_finest|
plus the largest change between successive sizes carried to the finest size as the tail of a
sequence converging at P_THEORY, |largest change| / ((h_{n-1} / h_n)^P_THEORY - 1).

Beside it, the Grid Convergence Index (Roache 1994; the procedure of Celik et al., J. Fluids
Eng. 130:078001, 2008), per mode, from the three finest sizes (fine first: h1 < h2 < h3,
r21 = h2 / h1, r32 = h3 / h2, e21 = f2 - f1, e32 = f3 - f2): the observed order solves
    p = |ln|e32 / e21| + ln((r21^p - s) / (r32^p - s))| / ln r21,   s = sign(e32 / e21),
capped at the element's formal order (P_FIT_MAX = 4, as Roache advises: an order above it is
pre-asymptotic); the limit is f1 + (f1 - f2) / (r21^p - 1) and the GCI of the finest size
GCI_fine = 1.25 |f1 - f2| / |f1| / (r21^p - 1), i.e. 1.25 times its distance to that limit; the GCI
of every size is 1.25 times its own distance to it (the second size's is Roache's GCI_coarse).
Where the three finest sizes give no order (oscillating or stalled differences, or no root), the
two-mesh GCI stands in: safety factor 3 at the theory order P_THEORY on the largest change of
the three, carried to the finest size. `two_mesh_gci` is that two-mesh form for studies that
solve two sizes only. The stated error of a size is the larger of the two estimates
(`RefinementStudy.stated_errors`): the fidelity choice and the reported error use it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from common.errors import InputError

P_MIN = 0.3  # below: no trustworthy order (a widened bound instead)
P_FIT_MAX = 4.0  # 2 k, the smooth-solution order of P2 eigenvalues: the fit's search range
WILLIAMS_LAMBDA = 0.712  # bonded 90-degree edge (clamped face meets free wall), nu = 0.3
P_THEORY = 2 * WILLIAMS_LAMBDA  # ~1.42: the asymptotic order in h at the singular rims


@dataclass
class ModeConvergence:
    order: float | None  # the order used: min(observed, P_THEORY); None without a trusted one
    extrapolated_hz: float
    relative_error: list[float]  # per size, coarse -> fine
    status: str  # "ok", "non-monotone", "order out of range", "converged"
    orders_by_triplet: list[float | None] = field(default_factory=list)
    observed_order: float | None = None  # the fitted order before the theory bound


MIN_SIZES = 3  # a fitted order and a limit need three sizes at least
GCI_SAFETY_THREE = 1.25  # Roache's safety factor with an observed order (three meshes)
GCI_SAFETY_TWO = 3.0  # ... with an assumed order (two meshes, or no observed order)
# the root search of Celik's order: orders far above P_FIT_MAX occur on closely spaced sizes
# (a ratio of 1.08 between effective sizes): such an order is found, then capped
CELIK_ORDER_MAX = 200.0


@dataclass
class ModeGci:
    """One mode's Grid Convergence Index over the sizes of a study."""

    order: float  # the order the GCI used: observed (capped at P_FIT_MAX), or P_THEORY
    safety_factor: float  # GCI_SAFETY_THREE with an observed order, else GCI_SAFETY_TWO
    extrapolated_hz: float
    relative_error: list[float]  # per size, coarse -> fine: safety * |f_h - limit| / |f_h|
    observed_order: float | None = None  # Celik's order before the cap; None without one


def sequence_problem(sizes) -> str | None:
    """Why `sizes` (m) is not a refinement sequence (None when it is): at least MIN_SIZES
    sizes, strictly decreasing (coarse -> fine). The one rule, for the scene and the FEM."""
    sizes = [float(s) for s in sizes]
    if len(sizes) < MIN_SIZES:
        return f"Richardson extrapolation needs at least {MIN_SIZES} sizes"
    if any(b >= a for a, b in zip(sizes, sizes[1:])):
        return "sizes must strictly decrease (coarse -> fine)"
    return None


def sequence_around(size: float, design) -> tuple[float, ...]:
    """A refinement sequence (coarse -> fine, m) that holds `size`, for estimating its error.

    The designed sequence when it holds the size, or with the size inserted when it lies
    between the designed sizes; outside them, the designed size ratios scaled to the size: ending
    at it when it is finer (a 40-32-25-20 mm design asked at 10 mm gives 20-16-12.5-10 mm),
    starting at it when it is coarser (at 50 mm: 50-40-31.25-25 mm, since coarser meshes would
    not resolve a leg). An error extrapolated from meshes far from the size says little about it.
    """
    design = tuple(float(h) for h in design)
    if not (math.isfinite(size) and size > 0):
        raise InputError(f"size = {size!r}: expected a positive mesh size")
    if any(math.isclose(size, h, rel_tol=1e-9) for h in design):
        return design
    if size < design[-1]:
        return tuple(h * size / design[-1] for h in design[:-1]) + (float(size),)
    if size > design[0]:
        return (float(size),) + tuple(h * size / design[0] for h in design[1:])
    return tuple(sorted(design + (float(size),), reverse=True))


def observed_order(h, f) -> float | None:
    """Order p through three (h, f) points (h decreasing); None if it cannot be estimated."""
    h1, h2, h3 = h
    f1, f2, f3 = f
    e21, e32 = f2 - f1, f3 - f2
    if e21 == 0 or e32 == 0 or e21 * e32 < 0:
        return None
    ratio = e21 / e32

    def g(p):
        return (h1**p - h2**p) / (h2**p - h3**p) - ratio

    lo, hi = 1e-3, 20.0
    if g(lo) * g(hi) > 0:
        return None
    return float(brentq(g, lo, hi, xtol=1e-10))


def _fit(h, f, p):
    a = np.column_stack([np.ones_like(h), h**p])
    coef, *_ = np.linalg.lstsq(a, f, rcond=None)
    return coef, float(np.sqrt(np.mean((a @ coef - f) ** 2)))


def fit_order(h, f) -> tuple[float, float, float]:
    """(p, f_inf, rms residual) of the least-squares fit f = f_inf + C h^p."""
    h = np.asarray(h, float) / np.max(h)  # scale for conditioning; p is scale-free
    f = np.asarray(f, float)
    grid = np.linspace(P_MIN, P_FIT_MAX, 155)
    res = [_fit(h, f, p)[1] for p in grid]
    k = int(np.argmin(res))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    from scipy.optimize import minimize_scalar
    opt = minimize_scalar(lambda p: _fit(h, f, p)[1], bounds=(lo, hi), method="bounded",
                          options={"xatol": 1e-8})
    p = float(opt.x) if opt.fun <= res[k] else float(grid[k])
    coef, rms = _fit(h, f, p)
    return p, float(coef[0]), rms


def richardson(h, f, noise: float = 1e-9) -> ModeConvergence:
    """Extrapolate one mode's frequencies f over sizes h (coarse -> fine, >= 3 sizes) with the
    observed order bounded by theory (module docstring); a widened bound without one."""
    h = np.asarray(h, float)
    f = np.asarray(f, float)
    if len(h) < 3:
        raise InputError(f"sizes = {h.tolist()}: Richardson extrapolation needs three sizes")
    triplets = [observed_order(h[k:k + 3], f[k:k + 3]) for k in range(len(h) - 2)]
    finest = f[-1]
    scale = abs(finest)
    if np.all(np.abs(f - finest) <= noise * scale):
        return ModeConvergence(None, float(finest), [0.0] * len(f), "converged", triplets)
    steps = np.diff(f)
    monotone = np.all(steps <= 0) or np.all(steps >= 0)
    p_obs, _, _ = fit_order(h, f) if monotone else (None, None, None)
    if p_obs is None or p_obs <= P_MIN + 1e-6:
        tail = np.abs(steps).max() / ((h[-2] / h[-1]) ** P_THEORY - 1.0)
        errs = [float((abs(x - finest) + tail) / scale) for x in f]
        return ModeConvergence(None, float(finest), errs,
                               "non-monotone" if p_obs is None else "order out of range",
                               triplets, p_obs)
    p = min(p_obs, P_THEORY)
    _, rms = _fit(h / np.max(h), f, p_obs)  # the scatter the observed model leaves
    f_inf = float(finest - (f[-2] - finest) / ((h[-2] / h[-1]) ** p - 1.0))
    errs = [float((abs(x - f_inf) + rms) / abs(f_inf)) for x in f]
    status = "ok" if p_obs <= P_THEORY else "order bounded by theory"
    return ModeConvergence(float(p), f_inf, errs, status, triplets, float(p_obs))


def celik_order(h, f) -> float | None:
    """Celik's observed order from three sizes coarse -> fine (None without one: a zero or a
    sign-changing difference, i.e. oscillating convergence, s = -1, for which the GCI takes the
    two-mesh form; or no positive root: data no power law f_inf + C h^p can produce)."""
    (h3, h2, h1), (f3, f2, f1) = h, f
    e21, e32 = f2 - f1, f3 - f2
    if e21 == 0 or e32 == 0 or e32 / e21 < 0:
        return None
    r21, r32 = h2 / h1, h3 / h2
    if math.isclose(r21, r32, rel_tol=1e-12):
        p = math.log(abs(e32 / e21)) / math.log(r21)
        return p if p > 0 else None

    def g(p):  # Celik's fixed point with s = 1, without the absolute values that would let
        # a diverging sequence (e32 / e21 below what any power law gives) through
        return (p * math.log(r21) - math.log(e32 / e21)
                - math.log((r21**p - 1.0) / (r32**p - 1.0)))

    lo, hi = 1e-3, CELIK_ORDER_MAX
    if g(lo) * g(hi) > 0:
        return None
    return float(brentq(g, lo, hi, xtol=1e-12))


def gci(h, f) -> ModeGci:
    """One mode's GCI over sizes h (coarse -> fine, >= 2) from its three finest sizes, or its two
    when the study has two or the three give no order (module docstring)."""
    h = np.asarray(h, float)
    f = np.asarray(f, float)
    if len(h) < 2:
        raise InputError(f"sizes = {h.tolist()}: a grid convergence index needs two sizes")
    p_obs = celik_order(h[-3:], f[-3:]) if len(h) >= 3 else None
    finest = float(f[-1])
    ratio = h[-2] / h[-1]
    if p_obs is not None:
        p, safety = min(p_obs, P_FIT_MAX), GCI_SAFETY_THREE
        limit = finest + (finest - f[-2]) / (ratio**p - 1.0)
        errs = [float(safety * abs(x - limit) / abs(x)) for x in f]
    else:
        p, safety = P_THEORY, GCI_SAFETY_TWO
        tail = float(np.abs(np.diff(f[-3:])).max()) / (ratio**p - 1.0)
        limit = finest
        errs = [float(safety * (abs(x - finest) + tail) / abs(x)) for x in f]
    return ModeGci(float(p), safety, float(limit), errs, p_obs)


def two_mesh_limit(fine_hz, coarse_hz, ratio: float, order: float = P_THEORY) -> np.ndarray:
    """The FEM's h -> 0 limit from sizes h and ratio * h (Richardson's step at `order`):
    f_h - (f_H - f_h) / ((H / h)^p - 1)."""
    fine, coarse = np.asarray(fine_hz, float), np.asarray(coarse_hz, float)
    return fine - (coarse - fine) / (ratio**order - 1)


def two_mesh_error(fine_hz, coarse_hz, ratio: float, order: float = P_THEORY):
    """Estimated relative error (%) of the fine solution from two sizes h and ratio * h:
    |f_h - f_H| / ((H / h)^p - 1) / f_h, Richardson at the singular rims' asymptotic order p (the
    graded meshes' observed orders lie above it, so there the step errs on the large side; on
    uniform meshes the orders approach it from below and the step falls ~5 % short,
    tests/test_rim_singularity.py: the two-mesh GCI, three times it, is stated beside it)."""
    fine, coarse = np.asarray(fine_hz, float), np.asarray(coarse_hz, float)
    return 100 * np.abs(fine - coarse) / (ratio**order - 1) / fine


def two_mesh_gci(fine_hz, coarse_hz, ratio: float) -> np.ndarray:
    """The two-mesh GCI (%) of the fine solutions of sizes h and ratio * h: safety factor 3 at
    the theory order, 3 |f_h - f_H| / |f_h| / (ratio^P_THEORY - 1)."""
    fine, coarse = np.asarray(fine_hz, float), np.asarray(coarse_hz, float)
    return 100 * GCI_SAFETY_TWO * np.abs(fine - coarse) / np.abs(fine) / (ratio**P_THEORY - 1)


@dataclass
class RefinementStudy:
    sizes: list[float]  # nominal mesh sizes, m
    effective_sizes: list[float]  # (V / n_nodes)^(1/3), m
    frequencies_hz: list[list[float]]  # [size][mode]
    dofs: list[int]
    raw_dofs: list[int]
    timings: list[dict]
    modes: list[ModeConvergence]
    gci: list[ModeGci] = field(default_factory=list)

    @property
    def orders(self) -> list[float | None]:
        return [m.order for m in self.modes]

    @property
    def extrapolated_hz(self) -> list[float]:
        return [m.extrapolated_hz for m in self.modes]

    @property
    def relative_errors(self) -> np.ndarray:
        """(n_sizes, n_modes) estimated relative error of every size and mode."""
        return np.array([m.relative_error for m in self.modes]).T

    @property
    def gci_errors(self) -> np.ndarray:
        """(n_sizes, n_modes) GCI of every size and mode."""
        return np.array([g.relative_error for g in self.gci]).T

    @property
    def stated_errors(self) -> np.ndarray:
        """(n_sizes, n_modes) the stated error: the larger of Richardson's estimate and the GCI."""
        return np.maximum(self.relative_errors, self.gci_errors)

    def max_error(self, size_index: int) -> float:
        return float(self.stated_errors[size_index].max())

    def to_dict(self) -> dict:
        return {
            "sizes_m": self.sizes,
            "effective_sizes_m": self.effective_sizes,
            "frequencies_hz": self.frequencies_hz,
            "dofs": self.dofs,
            "raw_dofs": self.raw_dofs,
            "timings": self.timings,
            "observed_order": self.orders,
            "fitted_order": [m.observed_order for m in self.modes],
            "orders_by_triplet": [m.orders_by_triplet for m in self.modes],
            "status": [m.status for m in self.modes],
            "extrapolated_hz": self.extrapolated_hz,
            "relative_error": self.relative_errors.tolist(),
            "gci": self.gci_errors.tolist(),
            "gci_order": [g.order for g in self.gci],
            "gci_safety_factor": [g.safety_factor for g in self.gci],
            "stated_error": self.stated_errors.tolist(),
            "max_relative_error": [self.max_error(k) for k in range(len(self.sizes))],
        }


def study_from_values(sizes, frequencies_hz, dofs, raw_dofs, timings,
                      volume: float) -> RefinementStudy:
    """The study from per-size values ordered coarse -> fine; h is (V / nodes)^(1/3)."""
    freqs = np.asarray(frequencies_hz, float)
    nodes = np.asarray(raw_dofs, float) / 3.0
    h_eff = (volume / nodes) ** (1.0 / 3.0)
    return RefinementStudy(
        sizes=[float(x) for x in sizes],
        effective_sizes=[float(x) for x in h_eff],
        frequencies_hz=freqs.tolist(),
        dofs=[int(x) for x in dofs],
        raw_dofs=[int(x) for x in raw_dofs],
        timings=[dict(t) for t in timings],
        modes=[richardson(h_eff, freqs[:, k]) for k in range(freqs.shape[1])],
        gci=[gci(h_eff, freqs[:, k]) for k in range(freqs.shape[1])],
    )


def study_from_results(results, volume: float) -> RefinementStudy:
    """Build the study from FemResults ordered coarse -> fine."""
    return study_from_values([r.mesh_size for r in results],
                             [r.frequencies_hz for r in results],
                             [r.dofs for r in results], [r.raw_dofs for r in results],
                             [r.timings for r in results], volume)
