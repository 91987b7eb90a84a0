"""The noise of a modal test's fitted frequencies (`modaltest.identify`): stated, or from the
fit's residuals, with the modes' own extraction uncertainty as a floor, and the quantile its
intervals take."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.stats

from results.campaign_records import NoiseRecord

from .campaign import Campaign

GOODNESS = 0.999  # a stated noise whose residuals' chi-square exceeds this quantile is refused


@dataclass(frozen=True)
class Noise:
    """The standard deviation of ln f_test the intervals use, and its quantile for 95 %."""

    sigma: float  # nan: none
    quantile: float  # Student's t with m - n degrees of freedom (estimated), else normal
    record: NoiseRecord
    decide: float = 1.0  # sigma's one-sided 95 % upper confidence bound over sigma (estimated)

    @staticmethod
    def upper(dof: int) -> float:
        """An estimated s's one-sided 95 % upper confidence bound over s: sqrt((m - n) /
        chi-square_{m - n}(5 %)) (1.42 for 16 degrees of freedom, 2.7 for 3)."""
        return math.sqrt(dof / float(scipy.stats.chi2.ppf(0.05, dof)))


def noise(fit_: Any, campaign: Campaign, extraction: np.ndarray | None = None) -> Noise:
    """The noise of the fitted frequencies of `fit_` (an `identify.Fit`): stated, or from the
    residuals; `extraction`: the fitted modes' own standard uncertainties (relative, e.g. from an
    identification of modes from FRFs), a floor under it.

    A stated noise the residuals contradict (their chi-square above its 99.9 % quantile for m - n
    degrees of freedom) is not used: the fit then misses the data by more than the noise (a model
    error, or a wrong minimum), and the residuals' own s is used instead. The extraction's errors
    are fixed per mode (a fresh test of the same FRFs repeats them), so they add to a stated noise
    in quadrature (their rms over the fitted modes) and are a floor under an estimated one; a floor
    that binds is a known sigma (normal quantile)."""
    settings = campaign.identify
    m, n = fit_.jacobian.shape
    dof = m - n
    ss = float(fit_.residuals_after @ fit_.residuals_after)
    u = (math.sqrt(float(np.mean(np.log1p(extraction) ** 2)))
         if extraction is not None and len(extraction) else 0.0)
    floor = (f"; the modes' extraction uncertainty ({100 * math.expm1(u):.3g} % rms) "
             "included" if u > 0.0 else "")
    normal = float(scipy.stats.norm.ppf(0.975))
    s = math.sqrt(ss / dof) if dof > 0 else math.nan
    if settings.frequency_noise_percent > 0.0:
        sigma = math.hypot(math.log1p(settings.frequency_noise_percent / 100.0), u)
        chi2 = ss / sigma**2
        limit = float(scipy.stats.chi2.ppf(GOODNESS, dof)) if dof > 0 else math.inf
        if chi2 <= limit:
            return Noise(sigma, normal, NoiseRecord(
                frequency_percent=100.0 * math.expm1(sigma), source="stated" + floor,
                degrees_of_freedom=dof))
        return Noise(s, float(scipy.stats.t.ppf(0.975, dof)), NoiseRecord(
            frequency_percent=100.0 * math.expm1(s), source=(
                f"residuals: the stated {settings.frequency_noise_percent:g} % does not explain "
                f"them (chi-square {chi2:.3g} for {dof} degrees of freedom, above its "
                f"{100 * GOODNESS:g} % quantile {limit:.3g}): a model error, or a wrong "
                "minimum"), degrees_of_freedom=dof), Noise.upper(dof))
    if dof > 0 and s >= u:
        return Noise(s, float(scipy.stats.t.ppf(0.975, dof)), NoiseRecord(
            frequency_percent=100.0 * math.expm1(s),
            source="residuals" + (f" (above the modes' extraction uncertainty, "
                                  f"{100 * math.expm1(u):.3g} % rms)" if u > 0.0 else ""),
            degrees_of_freedom=dof), Noise.upper(dof))
    if u > 0.0:
        return Noise(u, normal, NoiseRecord(
            frequency_percent=100.0 * math.expm1(u), source=(
                f"the modes' extraction uncertainty ({100 * math.expm1(u):.3g} % rms)"
                + (f", above the residuals' {100 * math.expm1(s):.3g} %" if dof > 0 else "")),
            degrees_of_freedom=dof))
    return Noise(math.nan, math.nan, NoiseRecord(
        frequency_percent=None, source="none: as many keys as paired frequencies, no residual "
        "to estimate it from; state frequency_noise_percent", degrees_of_freedom=dof))
