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
model's own error too), the keys' covariance is sigma^2 (J^T J)^+, and the 95 % interval of a
key is exp(p_k -+ t sqrt(C_kk)) (t of Student's distribution with m - n degrees of freedom, or
1.96 with a stated sigma). A key is identifiable when that interval lies within
`identifiable_within_percent` of its value either side and it is not at a bound; otherwise it is
flagged, with the key it trades off against (keys in series, e.g. two springs, correlate near
-1). The singular values of J / sigma say the same for every combination of keys; a direction
of keys the frequencies do not move at all (a zero singular value) leaves its keys undetermined
whatever the noise.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

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

STEP = 1e-4  # the central difference step of the matrices, in ln(value)
AT_BOUND = 1e-6  # a key within this of a bound (in ln) sits at it


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

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """d ln f / d ln value of every fitted mode, from eigenvalue sensitivities."""
        fields = self.fields(x)
        js, _ = self.partners(fields)
        jac = np.zeros((len(self.fitted), len(self.addresses)))
        moved = [[self.manipulator_at(x, k, step) for step in (STEP, -STEP)]
                 for k in range(len(self.addresses))]
        for pose in sorted({p for p, _ in self.fitted}):
            rows = [r for r, (p, _) in enumerate(self.fitted) if p == pose]
            a = fields[pose].analysis
            phi = a.modal.shapes[:, [js[r] for r in rows]]
            lam = (2.0 * math.pi * a.frequencies_hz[[js[r] for r in rows]]) ** 2
            tp = self.campaign.poses[pose]
            for k in range(len(self.addresses)):
                mats = []
                for man in moved[k]:
                    mats.append(assemble(man, pose_geometry(man, tp.pose), self.options))
                dk = (mats[0].stiffness - mats[1].stiffness) / (2 * STEP)
                dm = (mats[0].mass - mats[1].mass) / (2 * STEP)
                dlam = (np.einsum("qn,qp,pn->n", phi, dk, phi)
                        - lam * np.einsum("qn,qp,pn->n", phi, dm, phi))
                jac[rows, k] = dlam / (2.0 * lam)
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
               str(result.message), bool(result.status > 0))


def uncertainty(fit_: Fit, campaign: Campaign) -> tuple[list[ParameterRecord], NoiseRecord,
                                                        list[float], list[list[float]]]:
    """The keys' values, 95 % intervals and identifiability; the noise used; the singular
    values of J / sigma; the keys' correlation matrix."""
    settings = campaign.identify
    m, n = fit_.jacobian.shape
    dof = m - n
    if settings.frequency_noise_percent > 0.0:
        sigma = math.log1p(settings.frequency_noise_percent / 100.0)
        t = float(scipy.stats.norm.ppf(0.975))
        noise = NoiseRecord(frequency_percent=settings.frequency_noise_percent, source="stated",
                            degrees_of_freedom=dof)
    elif dof > 0:
        sigma = math.sqrt(float(fit_.residuals_after @ fit_.residuals_after) / dof)
        t = float(scipy.stats.t.ppf(0.975, dof))
        noise = NoiseRecord(frequency_percent=100.0 * math.expm1(sigma), source="residuals",
                            degrees_of_freedom=dof)
    else:
        sigma, t = math.nan, math.nan
        noise = NoiseRecord(frequency_percent=None, source="none: as many keys as paired "
                            "frequencies, no residual to estimate it from; state "
                            "frequency_noise_percent", degrees_of_freedom=dof)
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
    records = []
    lo_all, hi_all = (np.log([p.low for p in campaign.parameters]),
                      np.log([p.high for p in campaign.parameters]))
    for k, p in enumerate(campaign.parameters):
        x = fit_.x[k]
        half = t * sd[k]
        at_bound = bool(x - lo_all[k] < AT_BOUND or hi_all[k] - x < AT_BOUND)
        # no direction of the data moves it, or its interval is wider than its whole search
        unresolved = bool(len(null) and np.max(np.abs(null[:, k])) > 1e-3) or bool(
            math.isfinite(half) and half > hi_all[k] - lo_all[k])
        factor = math.exp(half) if math.isfinite(half) and not unresolved else math.inf
        within = settings.identifiable_within_percent
        identifiable = (factor - 1.0 <= within / 100.0 and not at_bound and not unresolved
                        and fit_.converged)
        partner = ""
        if n > 1 and np.all(np.isfinite(corr[k])):
            others = [(abs(corr[k, j]), j) for j in range(n) if j != k]
            c, j = max(others)
            if c > 0.9:
                partner = (f"; correlated {corr[k, j]:+.2f} with "
                           f"{campaign.parameters[j].address.name}")
        if not fit_.converged:
            reason = (f"the fit did not converge within max_evaluations "
                      f"({settings.max_evaluations}): {fit_.message}")
        elif unresolved:
            reason = ("the test frequencies do not depend on it (or only through a combination "
                      "with other keys): the data cannot determine it" + partner)
        elif at_bound:
            reason = "at a bound of its search: the data push it beyond [low, high]" + partner
        elif not math.isfinite(half):
            reason = noise["source"]
        elif identifiable:
            reason = (f"determined within {100 * (factor - 1):.3g} % either side (95 %), "
                      f"within the {within:g} % asked" + partner)
        elif factor > 2.0:
            reason = (f"the data cannot determine it: its 95 % interval spans a factor "
                      f"{factor:.3g} either side" + partner)
        else:
            reason = (f"determined only within {100 * (factor - 1):.3g} % either side (95 %), "
                      f"looser than the {within:g} % asked (identifiable_within_percent)"
                      + partner)
        ci = ([math.exp(x - half), math.exp(x + half)] if math.isfinite(factor)
              else [p.low, p.high])
        records.append(ParameterRecord(
            key=p.address.name, unit=p.address.unit, initial=p.initial, value=math.exp(x),
            ci95=ci, bounds=[p.low, p.high], identifiable=bool(identifiable),
            at_bound=at_bound,
            relative_std_percent=(100.0 * math.expm1(sd[k]) if math.isfinite(factor)
                                  else None),
            reason=reason))
    corr_list = [[float(v) if math.isfinite(v) else 0.0 for v in row] for row in corr]
    return records, noise, [float(s) for s in singular], corr_list


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
