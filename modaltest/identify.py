"""Scene keys identified from a modal test: the `[identify]` keys fitted to the paired
frequencies of every pose together, with their 95 % intervals and identifiability.

The fit: the keys in log space p_k = ln(value_k), bounded; the residuals r = ln(f_model /
f_test) of every test mode paired at the start (its partner re-found by the pairing's rule at
every step, so a mode that overtakes another is followed by its shape, not its order); scipy's
trust-region reflective least squares (`least_squares(method="trf")`, Levenberg-Marquardt's
bounded relative), with the Jacobian from eigenvalue sensitivities of the model's own matrices:
d(lambda_j) / d(p_k) = phi_j^T (dK/dp_k - lambda_j dM/dp_k) phi_j for mass-normalised phi_j
(Fox and Kapoor 1968), dK/dp_k and dM/dp_k by central differences of the assembled matrices
(exact for a spring, whose K is linear in it, to rounding), so d ln f_j / d p_k =
d(lambda_j)/d(p_k) / (2 lambda_j); one eigen solve a pose per step.

What the data determine: with sigma the standard deviation of ln f_test (stated, or
s^2 = sum r^2 / (m - n) from the m residuals and n keys at the optimum, which then carries the
model's own error too; `noise`), the keys' covariance is sigma^2 (J^T J)^+, and the 95 %
interval of a key is exp(p_k -+ t sqrt(C_kk)) (t of Student's distribution with m - n degrees
of freedom, or 1.96 with a stated sigma). A stated sigma the residuals contradict (their
chi-square beyond its 99.9 % quantile: a model error, or a fit stopped in a wrong minimum) is
replaced by s; the modes' own extraction uncertainty, when the caller gives it (modes from
FRFs: errors fixed per mode), adds to a stated sigma and is a floor under s.

A key correlated beyond CORRELATED (0.9) with another lies along a curved valley (keys in
series, e.g. two springs, correlate near -1): its interval is its profile likelihood's instead
(`profile`): the key held at values walked out from the estimate, the others re-fitted
(bounded) at each, to where the sum of squares rises by (t sigma)^2 (the F(1, m - n)
likelihood-ratio threshold with s, chi-square(1) with a stated sigma); one eigen solve a pose
per re-fit step. A profile that finds a lower sum of squares than the fit's shows the fit
stopped in a wrong minimum: the fit restarts from there. The profiles' time is estimated
from the fit's time a step before they run, and they are refused beyond PROFILE_SECONDS
(their keys then not identifiable: the slopes at the estimate alone cannot tell).

A key is identifiable when its interval, at sigma's one-sided 95 % upper confidence bound
(s sqrt((m - n) / chi-square_{m - n}(5 %)); sigma itself when stated), lies within
`identifiable_within_percent` of its value either side, and it does not sit at a bound, and
its profile (if it has one) closed without reaching a bound: a flag decided on an interval
made narrow by a low draw of s would pick out the draws whose intervals are too narrow. The
interval stated (ci95) is the 95 % one. Otherwise the key is flagged, with the key it trades
off against. The singular values of J / sigma say the same for every combination of keys; a
direction of keys the frequencies do not move at all (a zero singular value) leaves its keys
undetermined whatever the noise.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import Sequence

import numpy as np
import scipy.optimize
import scipy.stats

from analytical.kinematics import pose_geometry
from analytical.params import Manipulator, ModelOptions
from analytical.substructure import assemble
from common.errors import ComputeError
from results.campaign_records import FitMode, FitPose, NoiseRecord, ParameterRecord
from scene.address import Address

from .campaign import Campaign
from .correlate import Scores, match, pair, sampled, scores
from .models import AnalyticalField, analytical_field
from .noise import noise
from .profile import PROFILE_POINTS, Profile, profile

STEP = 1e-4  # the central difference step of the matrices, in ln(value)
AT_BOUND = 1e-6  # a key within this of a bound (in ln) sits at it
# A key whose |correlation| with another exceeds this lies along a curved valley of the sum of
# squares (two springs in series: the frequencies see about 1/k1 + 1/k2): the trade-off inflates
# its variance more than 1 / (1 - 0.9^2) = 5.3 times, so a step of its interval moves the other
# key by more than the other's own interval, and the slopes at the estimate no longer describe
# the valley there; its interval is its profile's
CORRELATED = 0.9
# what a key's profile is expected to cost, for the estimate made before it: 2 sides x about
# 5 re-fits x about 6 steps (measured: 30-110 steps a key on the tests' campaigns)
PROFILE_EXPECTED_STEPS = 60
PROFILE_SECONDS = 120.0  # the profiles of one identification, estimated, at most (twice: cut)
RESTARTS = 3  # fits restarted from a profile's lower point at most


@dataclass
class Problem:
    """The fit of a campaign's keys with one model's settings."""

    campaign: Campaign
    options: ModelOptions
    modes: list[int]  # the model modes solved at each pose
    fitted: list[tuple[int, int]] = field(default_factory=list)  # (pose, test mode), 0-based
    evaluations: int = 0
    partner_changes: int = 0
    previous: dict[tuple[int, int], int] = field(default_factory=dict)
    _cache: dict = field(default_factory=dict)

    @property
    def addresses(self) -> list[Address]:
        return [p.address for p in self.campaign.parameters]

    def manipulator_at(self, x: np.ndarray, k: int | None = None,
                       step: float = 0.0) -> Manipulator:
        """The campaign's machine with the keys at exp(x) (key k moved by `step` in ln)."""
        values = np.exp(np.asarray(x, float))
        if k is not None:
            values = values.copy()
            values[k] *= math.exp(step)
        man = self.campaign.scene.manipulator
        for address, value in zip(self.addresses, values):
            man = address.applied(man, value)
        return man

    def fields(self, x: np.ndarray | None) -> list[AnalyticalField]:
        """The model at every pose with the keys at exp(x) (None: the scene's own values,
        a rigid spring included)."""
        key = None if x is None else tuple(np.round(np.asarray(x, float), 15))
        if key not in self._cache:
            self.evaluations += 1
            man = self.campaign.scene.manipulator if x is None else self.manipulator_at(x)
            out = []
            for tp, count in zip(self.campaign.poses, self.modes):
                geometry = pose_geometry(man, tp.pose)
                out.append(analytical_field(man, tp.pose, geometry, self.options, count))
            self._cache = {key: out}  # one point kept: fun and jac ask for the same x
        return self._cache[key]

    def partners(self, fields: list[AnalyticalField]) -> tuple[list[int], list[float]]:
        """The model mode of every fitted test mode at these fields (0-based), and how alike
        their shapes are. A fitted mode is paired by the pairing's rule; one that finds no
        admissible partner at this point keeps the partner it had (else the most alike mode
        left), so the residual stays continuous; each change of partner is counted."""
        out, likeness = [], []
        by_pose: dict[int, tuple[dict[int, int], set[int], Scores, set[int]]] = {}
        for pose, i in self.fitted:
            tp, f = self.campaign.poses[pose], fields[pose]
            if pose not in by_pose:
                found = scores(tp.modes.shapes, sampled(tp, f), f.frequencies_hz,
                               tp.modes.frequencies_hz)
                pairs, grouped, _ = pair(found, tp.modes.frequencies_hz, f.frequencies_hz,
                                         self.campaign.correlation)
                by_pose[pose] = (pairs, grouped, found, set(pairs.values()))
            pairs, grouped, found, taken = by_pose[pose]
            previous = self.previous.get((pose, i))
            if i in pairs:
                j = pairs[i]
            elif previous is not None and previous not in taken:
                j = previous
            else:
                hz = np.asarray(f.frequencies_hz, float)
                merit = found.score[i] - np.abs(np.log(hz / tp.modes.frequencies_hz[i]))
                merit[list(taken)] = -np.inf
                j = int(np.argmax(merit))
            taken.add(j)
            if previous is not None and previous != j:
                self.partner_changes += 1
            self.previous[(pose, i)] = j
            out.append(j)
            likeness.append(match(found, grouped, i, j))
        return out, likeness

    def residuals(self, x: np.ndarray | None) -> np.ndarray:
        fields = self.fields(x)
        js, _ = self.partners(fields)
        return np.array([math.log(fields[pose].frequencies_hz[j]
                                  / self.campaign.poses[pose].modes.frequencies_hz[i])
                         for (pose, i), j in zip(self.fitted, js)])

    def jacobian(self, x: np.ndarray, columns: Sequence[int] | None = None) -> np.ndarray:
        """d ln f / d ln value of every fitted mode, from eigenvalue sensitivities (of the
        keys `columns` only, in their order, when given)."""
        fields = self.fields(x)
        js, _ = self.partners(fields)
        keys = list(range(len(self.addresses)) if columns is None else columns)
        jac = np.zeros((len(self.fitted), len(keys)))
        moved = [[self.manipulator_at(x, k, step) for step in (STEP, -STEP)] for k in keys]
        for pose in sorted({p for p, _ in self.fitted}):
            rows = [r for r, (p, _) in enumerate(self.fitted) if p == pose]
            a = fields[pose].analysis
            phi = a.modal.shapes[:, [js[r] for r in rows]]
            lam = (2.0 * math.pi * a.frequencies_hz[[js[r] for r in rows]]) ** 2
            tp = self.campaign.poses[pose]
            for c, k in enumerate(keys):
                mats = []
                for man in moved[c]:
                    mats.append(assemble(man, pose_geometry(man, tp.pose), self.options))
                dk = (mats[0].stiffness - mats[1].stiffness) / (2 * STEP)
                dm = (mats[0].mass - mats[1].mass) / (2 * STEP)
                dlam = (np.einsum("qn,qp,pn->n", phi, dk, phi)
                        - lam * np.einsum("qn,qp,pn->n", phi, dm, phi))
                jac[rows, c] = dlam / (2.0 * lam)
        return jac


@dataclass(frozen=True)
class Fit:
    x0: np.ndarray
    x: np.ndarray
    residuals_before: np.ndarray
    residuals_after: np.ndarray
    jacobian: np.ndarray
    evaluations: int
    seconds: float
    message: str
    converged: bool  # the optimiser met a tolerance (not its evaluation budget)
    steps: int = 0  # the optimiser's steps (each: one eigen solve a pose, the keys' slopes)

    @property
    def seconds_per_step(self) -> float:
        return self.seconds / max(self.steps, 1)


def fit(problem: Problem, x0: np.ndarray, before: np.ndarray) -> Fit:
    """The least-squares fit of the problem's keys from x0 (ln of the start values);
    `before`: the residuals at the scene's own values."""
    params = problem.campaign.parameters
    lo, hi = np.log([p.low for p in params]), np.log([p.high for p in params])
    start = time.perf_counter()
    try:
        result = scipy.optimize.least_squares(
            problem.residuals, x0, jac=problem.jacobian, bounds=(lo, hi), method="trf",
            x_scale=1.0, xtol=1e-12, ftol=1e-12, gtol=1e-12,
            max_nfev=problem.campaign.identify.max_evaluations)
    except (ValueError, np.linalg.LinAlgError) as exc:
        raise ComputeError(f"identification: the fit failed: {exc}") from None
    x = result.x
    after = problem.residuals(x)
    jac = problem.jacobian(x)
    return Fit(x0, x, before, after, jac, problem.evaluations, time.perf_counter() - start,
               str(result.message), bool(result.status > 0), int(result.nfev))


@dataclass(frozen=True)
class Intervals:
    """What the data determine of the keys."""

    parameters: list[ParameterRecord]
    noise: NoiseRecord
    singular_values: list[float]
    correlation: list[list[float]]
    better: np.ndarray | None  # a point a profile found below the fit's minimum (ln), else None
    note: str  # the profiles: which keys, their cost


def uncertainty(fit_: Fit, campaign: Campaign, problem: Problem | None = None,
                extraction: np.ndarray | None = None) -> Intervals:
    """The keys' values, 95 % intervals and identifiability; the noise used; the singular
    values of J / sigma; the keys' correlation matrix. With the `problem`, the interval of a
    key correlated beyond CORRELATED with another is its profile's (`profile`), else (and
    without it) the linearised one. `extraction`: the fitted modes' own standard uncertainties
    (relative; `noise`)."""
    settings = campaign.identify
    m, n = fit_.jacobian.shape
    found = noise(fit_, campaign, extraction)
    sigma, t = found.sigma, found.quantile
    jtj = fit_.jacobian.T @ fit_.jacobian
    cov = sigma**2 * np.linalg.pinv(jtj) if math.isfinite(sigma) else np.full((n, n), np.nan)
    scale = max(sigma, 1e-300) if math.isfinite(sigma) else 1.0
    singular = np.linalg.svd(fit_.jacobian / scale, compute_uv=False)
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    # a direction of keys the frequencies do not move: the pseudo-inverse gives it no variance,
    # so it is found from the singular values instead (relative to the largest)
    _, sv, vt = np.linalg.svd(fit_.jacobian, full_matrices=True)
    sv = np.concatenate([sv, np.zeros(n - len(sv))]) if len(sv) < n else sv
    null = vt[sv <= 1e-8 * max(sv.max(initial=0.0), 1e-300)]
    lo_all, hi_all = (np.log([p.low for p in campaign.parameters]),
                      np.log([p.high for p in campaign.parameters]))
    within = settings.identifiable_within_percent

    partners: list[tuple[float, int]] = []
    for k in range(n):
        row = corr[k] if np.all(np.isfinite(corr[k])) else np.zeros(n)
        others = [(abs(float(row[j])), j) for j in range(n) if j != k]
        partners.append(max(others) if others else (0.0, k))
    half = t * sd
    at_bound = (fit_.x - lo_all < AT_BOUND) | (hi_all - fit_.x < AT_BOUND)
    # no direction of the data moves it, or its interval is wider than its whole search
    unresolved = [bool(len(null) and np.max(np.abs(null[:, k])) > 1e-3) or bool(
        math.isfinite(half[k]) and half[k] > hi_all[k] - lo_all[k]) for k in range(n)]
    profiled = [k for k in range(n) if partners[k][0] > CORRELATED and problem is not None
                and fit_.converged and math.isfinite(half[k]) and not unresolved[k]
                and not at_bound[k]]
    profiles: dict[int, Profile] = {}
    note = ""
    if profiled:
        assert problem is not None
        estimate = len(profiled) * PROFILE_EXPECTED_STEPS * fit_.seconds_per_step
        if estimate > PROFILE_SECONDS:
            note = (f"profiles of {len(profiled)} correlated keys not run: about "
                    f"{estimate:.0f} s ({len(profiled)} x {PROFILE_EXPECTED_STEPS} re-fit steps "
                    f"of {fit_.seconds_per_step:.2g} s), more than the {PROFILE_SECONDS:g} s "
                    "allowed")
        else:
            start = time.perf_counter()
            ss_min = float(fit_.residuals_after @ fit_.residuals_after)
            # the likelihood ratio's threshold: F(1, m - n) s^2 = (t s)^2 estimated,
            # chi-square(1) sigma^2 = (1.96 sigma)^2 stated; and the decision's
            rise = (t * sigma) ** 2
            steps = 0
            for k in profiled:
                found_k = profile(problem, fit_.x, k, ss_min, (rise, rise * found.decide**2),
                                  half[k], start + 2.0 * PROFILE_SECONDS)
                steps += found_k.steps
                if found_k.better is not None:
                    return Intervals([], found.record, [], [], found_k.better,
                                     f"the profile of {campaign.parameters[k].address.name} "
                                     "found a lower sum of squares than the fit's")
                profiles[k] = found_k
            note = (f"profile-likelihood intervals of {len(profiled)} keys correlated beyond "
                    f"{CORRELATED:g} ({steps} re-fit steps, {time.perf_counter() - start:.1f} "
                    f"s; estimated {estimate:.1f} s)")

    def unsure(decided: float) -> str:
        """Why a key within the criterion at the estimated noise is not identifiable."""
        spread = (f"spans {100 * (decided - 1):.3g} % either side" if math.isfinite(decided)
                  else "reaches a bound or is not found")
        return (f"but only because the noise estimated is small: at its 95 % upper "
                f"confidence bound ({found.decide:.3g} s, {m - n} degrees of freedom) the "
                f"interval {spread}, looser than the {within:g} % asked")

    records = []
    for k, p in enumerate(campaign.parameters):
        x = fit_.x[k]
        c, j = partners[k]
        partner = (f"; correlated {corr[k, j]:+.2f} with {campaign.parameters[j].address.name}"
                   if c > CORRELATED else "")
        prof = profiles.get(k)
        if prof is not None:  # the profile's interval
            lower, upper = prof.low.end, prof.high.end
            widest = max(x - lower, upper - x)
            bound = prof.low.at_bound or prof.high.at_bound
            complete = prof.low.complete and prof.high.complete
            factor = math.exp(widest) if complete and not bound else math.inf
            d_low, d_high = prof.decided
            decided = (math.exp(max(x - d_low.end, d_high.end - x)) if d_low.complete
                       and d_high.complete and not d_low.at_bound and not d_high.at_bound
                       else math.inf)
            identifiable = max(factor, decided) - 1.0 <= within / 100.0
            how = "profile likelihood, the other keys re-fitted at each value"
            if identifiable:
                reason = (f"determined within {100 * math.expm1(lower - x):+.3g} % / "
                          f"{100 * math.expm1(upper - x):+.3g} % (95 %, {how}), within the "
                          f"{within:g} % asked" + partner)
            elif factor - 1.0 <= within / 100.0 and complete:
                reason = (f"determined within {100 * math.expm1(lower - x):+.3g} % / "
                          f"{100 * math.expm1(upper - x):+.3g} % (95 %, {how}), "
                          + unsure(decided) + partner)
            elif not complete:
                reason = (f"its profile ({how}) did not close within {PROFILE_POINTS} points "
                          "a side or its time: not to be trusted" + partner)
            elif bound:
                reason = (f"its 95 % interval ({how}) reaches a bound of its search: the data "
                          "cannot determine it" + partner)
            else:
                reason = (f"determined only within {100 * math.expm1(lower - x):+.3g} % / "
                          f"{100 * math.expm1(upper - x):+.3g} % (95 %, {how}), looser than the "
                          f"{within:g} % asked (identifiable_within_percent)" + partner)
            ci = [math.exp(lower), math.exp(upper)] if complete else [p.low, p.high]
            std = (100.0 * math.expm1(widest / t) if math.isfinite(factor) else None)
        else:
            factor = (math.exp(half[k]) if math.isfinite(half[k]) and not unresolved[k]
                      else math.inf)
            # correlated beyond CORRELATED and not profiled: its slopes cannot tell
            refused = partners[k][0] > CORRELATED
            decided = factor ** found.decide
            identifiable = (decided - 1.0 <= within / 100.0 and not at_bound[k]
                            and not unresolved[k] and not refused)
            if unresolved[k]:
                reason = ("the test frequencies do not depend on it (or only through a "
                          "combination with other keys): the data cannot determine it"
                          + partner)
            elif at_bound[k]:
                reason = ("at a bound of its search: the data push it beyond [low, high]"
                          + partner)
            elif not math.isfinite(half[k]):
                reason = found.record["source"]
            elif refused:
                reason = (f"correlated beyond {CORRELATED:g} with another key and its "
                          f"profile not run ({note or 'no profile asked'}): its slopes at "
                          "the estimate alone cannot tell" + partner)
            elif identifiable:
                reason = (f"determined within {100 * (factor - 1):.3g} % either side (95 %), "
                          f"within the {within:g} % asked" + partner)
            elif factor - 1.0 <= within / 100.0:
                reason = (f"determined within {100 * (factor - 1):.3g} % either side (95 %), "
                          + unsure(decided) + partner)
            elif factor > 2.0:
                reason = (f"the data cannot determine it: its 95 % interval spans a factor "
                          f"{factor:.3g} either side" + partner)
            else:
                reason = (f"determined only within {100 * (factor - 1):.3g} % either side "
                          f"(95 %), looser than the {within:g} % asked "
                          "(identifiable_within_percent)" + partner)
            ci = ([math.exp(x - half[k]), math.exp(x + half[k])] if math.isfinite(factor)
                  else [p.low, p.high])
            std = 100.0 * math.expm1(sd[k]) if math.isfinite(factor) else None
        if not fit_.converged:
            identifiable = False
            reason = (f"the fit did not converge within max_evaluations "
                      f"({settings.max_evaluations}): {fit_.message}")
        records.append(ParameterRecord(
            key=p.address.name, unit=p.address.unit, initial=p.initial, value=math.exp(x),
            ci95=ci, bounds=[p.low, p.high], identifiable=bool(identifiable),
            at_bound=bool(at_bound[k]), relative_std_percent=std, reason=reason))
    corr_list = [[float(v) if math.isfinite(v) else 0.0 for v in row] for row in corr]
    return Intervals(records, found.record, [float(s) for s in singular], corr_list, None, note)


def settled(problem: Problem, fit_: Fit, extraction: np.ndarray | None = None
            ) -> tuple[Fit, Intervals]:
    """The fit and its intervals; a fit a profile shows to have stopped in a wrong minimum is
    restarted from the profile's lower point (RESTARTS times at most)."""
    notes = []
    for _ in range(RESTARTS + 1):
        found = uncertainty(fit_, problem.campaign, problem, extraction)
        if found.better is None:
            break
        notes.append(found.note)
        fit_ = fit(problem, found.better, fit_.residuals_before)
    else:
        found = uncertainty(fit_, problem.campaign, None, extraction)
        found = replace(found, note=f"{RESTARTS} restarts from profiles' lower points and "
                        "still not settled: linearised intervals")
    if notes:
        found = replace(found, note="; ".join(
            [f"{n}: the fit restarted from there" for n in notes] + [found.note]))
    return fit_, found


def fit_table(problem: Problem, fit_: Fit, after_fields: list[AnalyticalField],
              macs_after: dict[tuple[int, int], float]) -> list[FitPose]:
    """Before and after, per pose and fitted test mode."""
    out: list[FitPose] = []
    for pose, tp in enumerate(problem.campaign.poses):
        rows = []
        for r, (p, i) in enumerate(problem.fitted):
            if p != pose:
                continue
            test = float(tp.modes.frequencies_hz[i])
            before = test * math.exp(fit_.residuals_before[r])
            after = test * math.exp(fit_.residuals_after[r])
            rows.append(FitMode(test_mode=i + 1, test_hz=test, before_hz=before, after_hz=after,
                                error_before_percent=100.0 * (before / test - 1.0),
                                error_after_percent=100.0 * (after / test - 1.0),
                                mac_after=macs_after.get((pose, i), math.nan)))
        out.append(FitPose(pose=tp.name, modes=rows))
    return out


def rms_percent(residuals: np.ndarray) -> float:
    return float(100.0 * math.sqrt(np.mean(np.expm1(residuals) ** 2))) if len(residuals) else 0.0
