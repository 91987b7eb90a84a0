"""A key's profile likelihood (`modaltest.identify`): the key held at values walked out from
its estimate, the other keys re-fitted (bounded) at each, to where the sum of squares rises by a
threshold; the interval such a profile gives where the key trades off against another along a
curved valley of the sum of squares (two springs in series)."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.optimize

PROFILE_POINTS = 12  # re-fits of one side of one key's profile at most (walk and narrowing)
PROFILE_REFIT_STEPS = 30  # steps of one re-fit at most
PROFILE_TOLERANCE = 0.01  # an interval's end bracketed to this of its distance from the value
BETTER = 0.01  # a profile point this far (of the threshold) below the fit's minimum: a wrong one


@dataclass(frozen=True)
class Side:
    """One end of a key's profile interval (ln)."""

    end: float
    at_bound: bool  # the sum of squares stays below the threshold out to the bound
    complete: bool  # found within the profile's points, every re-fit converged


@dataclass(frozen=True)
class Profile:
    low: Side  # the 95 % interval's
    high: Side
    decided: tuple[Side, Side]  # the interval identifiability is decided on (`Noise.decide`)
    better: np.ndarray | None  # a point of the profile below the fit's minimum (all keys, ln)
    steps: int  # re-fit steps (each: one eigen solve a pose, the free keys' slopes)


class _Lower(Exception):
    def __init__(self, x: np.ndarray):
        self.x = x


def profile(problem: Any, x_hat: np.ndarray, k: int, ss_min: float,
            rises: tuple[float, float], first: float, deadline: float) -> Profile:
    """The profile of key k of `problem` (an `identify.Problem`) about the fit's x_hat: key k held
    at values walked away from its estimate (first step `first` in ln, then steps from the rise
    seen so far, as if quadratic), the other keys re-fitted (bounded, from the previous point's
    values) at each, until the sum of squares rises by rises[0] above the fit's `ss_min`
    (bracketed, then the bracket narrowed to PROFILE_TOLERANCE of its distance; the outer end of
    the bracket is the interval's end, so it errs wide) or the bound is reached; then on to
    rises[1] (>= rises[0]) the same way. A point below the fit's minimum is returned at once
    (the fit stopped in a wrong minimum). The partners of the fitted modes are left as they
    were."""
    params = problem.campaign.parameters
    lo, hi = np.log([p.low for p in params]), np.log([p.high for p in params])
    columns = [j for j in range(len(x_hat)) if j != k]
    free = np.array(columns, int)
    kept = dict(problem.previous), problem.partner_changes
    steps = 0

    def held(value: float, others: np.ndarray) -> tuple[float, np.ndarray, bool]:
        nonlocal steps
        x = x_hat.copy()
        x[k] = value

        def full(z: np.ndarray) -> np.ndarray:
            y = x.copy()
            y[free] = z
            return y

        if not len(free):
            r = problem.residuals(x)
            steps += 1
            ss, y, ok = float(r @ r), x, True
        else:
            result = scipy.optimize.least_squares(
                lambda z: problem.residuals(full(z)), others,
                jac=lambda z: problem.jacobian(full(z), columns), bounds=(lo[free], hi[free]),
                method="trf", x_scale=1.0, xtol=1e-10, ftol=1e-10, gtol=1e-10,
                max_nfev=PROFILE_REFIT_STEPS)
            steps += int(result.nfev)
            ss, y, ok = 2.0 * float(result.cost), full(result.x), bool(result.status > 0)
        if ss - ss_min < -BETTER * rises[0]:
            raise _Lower(y)
        return ss, y, ok

    def side(direction: float, rise: float, inside: tuple[float, float, np.ndarray],
             offset: float) -> tuple[Side, tuple[float, float, np.ndarray]]:
        """From a point inside (offset, its rise, the others there) out to `rise`."""
        limit = lo[k] if direction < 0 else hi[k]
        span = abs(limit - x_hat[k])
        outside: tuple[float, float] | None = None
        offset, converged, closed = min(offset, span), True, False
        for _ in range(PROFILE_POINTS):
            if time.perf_counter() > deadline or offset <= inside[0]:
                break
            ss, y, ok = held(x_hat[k] + direction * offset, inside[2])
            converged &= ok
            if ss - ss_min >= rise:
                outside = (offset, ss - ss_min)
            else:
                inside = (offset, ss - ss_min, y[free])
            if outside is None:
                if offset >= span:
                    break
                grow = 1.2 * math.sqrt(rise / inside[1]) if inside[1] > 0.0 else 4.0
                offset = min(span, offset * min(max(grow, 1.5), 4.0))
                continue
            a, ra = inside[0], max(inside[1], 0.0)
            b, rb = outside
            if b - a <= PROFILE_TOLERANCE * b:
                closed = True
                break
            # the rise is near quadratic in the offset: its square root near linear
            guess = a + (b - a) * (math.sqrt(rise) - math.sqrt(ra)) / (
                math.sqrt(rb) - math.sqrt(ra))
            offset = min(max(guess, a + 0.1 * (b - a)), b - 0.1 * (b - a))
        if outside is not None:
            return Side(float(x_hat[k] + direction * outside[0]), False,
                        converged and (closed or outside[0] - inside[0]
                                       <= PROFILE_TOLERANCE * outside[0])), inside
        reached = inside[0] >= span
        return Side(float(limit), reached, converged and reached), inside

    ends: list[list[Side]] = [[], []]
    try:
        for direction in (-1.0, 1.0):
            problem.previous = dict(kept[0])
            start = (0.0, 0.0, x_hat[free])
            found, inside = side(direction, rises[0], start, max(first, 1e-9))
            ends[0].append(found)
            if rises[1] > rises[0] and not found.at_bound and found.complete:
                step = abs(found.end - x_hat[k]) * math.sqrt(rises[1] / rises[0])
                further, _ = side(direction, rises[1], inside, step)
            else:
                further = found
            ends[1].append(further)
    except _Lower as lower:
        none = Side(math.nan, False, False)
        return Profile(none, none, (none, none), lower.x, steps)
    finally:
        problem.previous, problem.partner_changes = kept
    return Profile(ends[0][0], ends[0][1], (ends[1][0], ends[1][1]), None, steps)
