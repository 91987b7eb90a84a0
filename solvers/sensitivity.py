"""The sampling design and the statistics of an uncertainty propagation, through SALib.

Why SALib (of SALib, chaospy and openturns): the model is fast enough to be sampled directly,
so the Sobol' indices are estimated from model runs, not from a surrogate whose truncation
error would need a bound of its own (chaospy's polynomial chaos); SALib is the reference
implementation of Saltelli's scheme (Saltelli et al., Comput. Phys. Commun. 181, 2010: the
first-order estimator, Jansen's total-order one) on a scrambled Sobol' sequence (scipy.stats.qmc)
with bootstrap confidence intervals of every index, in pure Python (openturns does this too,
as one part of a large compiled library).

Design: N base points of a scrambled Sobol' sequence in 2d dimensions, read as two matrices
A and B (N x d) of unit values, and d more with column i of A from B (Saltelli's radial
scheme without second-order terms): N (d + 2) model runs. The inputs' distributions turn the
unit values into values (scene.uncertainty). Statistics:

- mean, standard deviation and the 2.5 / 97.5 % quantiles from the 2N points of A and B;
- first-order and total Sobol' indices (SALib's `sobol.analyze`);
- the sampling error of each: the half-width of its 95 % bootstrap interval (the 2N points
  resampled for the moments and quantiles; SALib's own bootstrap for the indices). The
  bootstrap treats the points as independent: for a low-discrepancy design it overstates the
  error (its error falls as 1/N rather than 1/sqrt(N) for smooth outputs), so the stated
  error bounds the true one (tests/test_uncertainty.py measures both).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import TypedDict

import numpy as np

RESAMPLES = 200  # bootstrap resamples of every statistic
CONFIDENCE = 0.95
QUANTILES = (0.025, 0.975)


class Problem(TypedDict):
    """SALib's description of the inputs: d unit variables (scene values are mapped from
    them by the scene's distributions)."""
    num_vars: int
    names: list[str]
    bounds: list[list[float]]


def _problem(d: int) -> Problem:
    return Problem(num_vars=d, names=[f"x{k}" for k in range(d)], bounds=[[0.0, 1.0]] * d)


def design(d: int, n: int, seed: int) -> np.ndarray:
    """Unit values (N (d + 2), d) of Saltelli's scheme on a scrambled Sobol' sequence."""
    from SALib.sample import sobol

    with warnings.catch_warnings():  # N not a power of two: the balance is the user's choice
        warnings.simplefilter("ignore", UserWarning)
        return sobol.sample(_problem(d), n, calc_second_order=False, scramble=True, seed=seed)


def base_rows(n: int, d: int) -> np.ndarray:
    """Rows of A and B in the design (2N): plain draws of the inputs' joint distribution."""
    step = d + 2
    return np.sort(np.concatenate([np.arange(n) * step, np.arange(n) * step + d + 1]))


@dataclass(frozen=True)
class Statistics:
    """One output's statistics, each with its 95 % sampling error (a half-width)."""

    mean: float
    std: float
    q025: float
    q975: float
    mean_error: float
    std_error: float
    q025_error: float
    q975_error: float
    sobol_first: list[float | None]  # per input; None where the output does not vary
    sobol_first_error: list[float | None]
    sobol_total: list[float | None]
    sobol_total_error: list[float | None]


def moments(y, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(mean, std, q025, q975) of the samples `y` (n,) and their bootstrap 95 % half-widths."""
    y = np.asarray(y, float)

    def stats(v):
        q = np.quantile(v, QUANTILES, axis=-1)
        return np.stack([v.mean(axis=-1), v.std(axis=-1, ddof=1), q[0], q[1]])

    rng = np.random.default_rng(seed)
    resampled = stats(y[rng.integers(0, len(y), (RESAMPLES, len(y)))])  # (4, R)
    z = 1.959963984540054  # the normal 97.5 % point
    return stats(y), z * resampled.std(axis=1, ddof=1)


def indices(y, d: int, seed: int) -> tuple[list, list, list, list]:
    """First-order and total Sobol' indices of the design's outputs `y` (N (d + 2),) and their
    95 % bootstrap half-widths (SALib); None for every input where `y` does not vary."""
    from SALib.analyze import sobol

    y = np.asarray(y, float)
    if np.ptp(y) <= 1e-12 * max(1.0, float(np.max(np.abs(y)))):
        none: list = [None] * d
        return none, none, none, none
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        s = sobol.analyze(_problem(d), y, calc_second_order=False, num_resamples=RESAMPLES,
                          conf_level=CONFIDENCE, seed=seed)

    def plain(values) -> list:
        return [float(v) for v in np.asarray(values, float)]

    return plain(s["S1"]), plain(s["S1_conf"]), plain(s["ST"]), plain(s["ST_conf"])


def statistics(y, n: int, d: int, seed: int) -> Statistics:
    """Every statistic of one output over the whole design (`design(d, n, seed)`)."""
    y = np.asarray(y, float)
    value, error = moments(y[base_rows(n, d)], seed)
    first, first_e, total, total_e = indices(y, d, seed)
    mean, std, q025, q975 = (float(v) for v in value)
    mean_e, std_e, q025_e, q975_e = (float(e) for e in error)
    return Statistics(mean, std, q025, q975, mean_e, std_e, q025_e, q975_e,
                      first, first_e, total, total_e)
