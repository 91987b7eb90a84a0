"""Semi-discretization of the regenerative milling equation (Insperger & Stepan, IJNME 55:503,
2002 and 61:117, 2004; in the full-discretization form of Ding et al., IJMTM 50:502, 2010),
with a cubic Hermite force: the stability of one spindle speed from the monodromy matrix of a
tooth period.

In modal coordinates y = (q_1, q_1', ..., q_m, q_m') the cut is

    y' = A0 y + B F(t),   F(t) = b K(t) (r(t) - r(t - tau)),   r = C y,  r' = Cv y,

(chatter.milling). A tooth period is cut into intervals whose ends fall on every tooth's entry
and exit (K(t) is smooth inside each), a part where no tooth cuts is one interval. On each
interval the free vibration is exact (the modes' own exponential) and the force is its cubic
Hermite interpolant from its values and slopes at the interval's ends,

    F(t_i + s) = h00 F_i + h h10 F_i' + h01 F_i+1 + h h11 F_i+1',
    y_i+1 = e^{A0 h} y_i + int_0^h e^{A0 (h - s)} B F(t_i + s) ds,

the slopes F' = b (K' dr + K dr') read from the same states (dr' = r'(t) - r'(t - tau)): the
scheme is fourth order in the interval (a linear force, the classic full discretization,
second; `order` = 2 keeps it for the convergence test). The end of an interval is implicit in
y_i+1 (a 2m solve). The delayed values are the previous period's at the same nodes (the delay
is the period), so the monodromy maps z = (y_0, (r, r') at the cut's nodes) over one period;
the cut is stable when its spectral radius is below 1. The critical depth is the least b where
it reaches 1: scanned up from a depth the small-gain theorem holds stable in steps of 1.2 (a
pocket of instability narrower than a step may be missed), then Illinois' regula falsi on
log rho. The critical multiplier says the kind: real and negative, a flip (period doubling);
complex, a Hopf (secondary) bifurcation.

The intervals of a cut segment follow the work: at most ANGLE_STEP of the cutter's turn and
PHASE_STEP radians of the highest mode's vibration each (measured convergence in
docs/lobes.md). Each speed is solved at these intervals and at twice as many; the record keeps
the finer depth, and a third of the difference of the two as its stated error (chatter.lobes:
Richardson's estimate for a second-order scheme; at fourth order the finer one's true error is
about 1/15 of the difference, so the stated error bounds it about fivefold)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from common.errors import ComputeError

from .milling import ToolModes, breakpoints, tooth_matrix, tooth_matrix_slope

ANGLE_STEP = math.radians(24.0)  # of the cutter's turn a scout interval spans at most
PHASE_STEP = 2.4  # radians of the highest mode's vibration a scout interval spans at most
MIN_INTERVALS = 2  # a cut segment's least scout intervals
LEVELS = (1, 2, 4)  # the scout (finds the first crossing), the coarse and the fine level
LADDER = 1.2  # depth ratio of the scan up from a stable depth
NEAR = 1.03  # the finer level's bracket: a coarser level's depth / NEAR and * NEAR
TOLERANCE = 1e-5  # relative width of the final bracket
MAX_ITERATIONS = 60
UNSTABLE_LOG = 50.0  # log rho said for a radius that is not a finite number (unstable)
CEILING_FACTOR = 1e3  # no loss of stability below this many times the small-gain depth: none
# one depth trial of one speed, s: a + b n^2 for a monodromy of size n (numpy's eigvals on one
# core: 0.35, 2.5, 11 and 47 ms at n = 48, 96, 192, 384, near n^2 there; the whole diagram's
# estimate measured against its time on three diagrams of 40-400 speeds: 0.9-2.7 times it)
EIG_SECONDS = (1e-5, 2e-7)
EVALUATIONS = (35, 8, 8)  # depth trials a speed takes at each level (measured: 28-36, 6-8)


@dataclass(frozen=True)
class Cut:
    """The milling cut in SI: teeth, engagement angles (rad), coefficients (N/m^2)."""

    teeth: int
    start: float
    exit: float
    kt: float
    kn: float


@dataclass(frozen=True)
class SpeedResult:
    depth: np.ndarray  # m, inf: stable up to the ceiling
    frequency_hz: np.ndarray  # nan where none
    flip: np.ndarray  # bool: the critical multiplier is real and negative
    intervals: np.ndarray  # the cut's intervals a tooth period at this level


def segment_intervals(cut: Cut, modes: ToolModes, speeds_hz, refine: int = 1) -> np.ndarray:
    """Intervals (ns, segments) of each engagement segment of a tooth period (1 where no tooth
    cuts): the module docstring's rule, times `refine`."""
    period, ends = breakpoints(cut.teeth, cut.start, cut.exit)
    starts = [0.0, *ends[:-1]]
    omega = 2 * math.pi * np.asarray(speeds_hz, float)
    wmax = float(modes.omega.max())
    out = []
    for a, b in zip(starts, ends, strict=True):
        if not _cutting(cut, cut.start + 0.5 * (a + b)):
            out.append(np.ones(len(omega), int))
            continue
        span = b - a
        need = np.maximum(span / ANGLE_STEP, wmax * span / omega / PHASE_STEP)
        out.append(refine * np.maximum(MIN_INTERVALS, np.ceil(need)).astype(int))
    return np.stack(out, 1)


def _cutting(cut: Cut, phi0: float) -> bool:
    return any(math.fmod(phi0 + 2 * math.pi * j / cut.teeth - cut.start + 4 * math.pi,
                         2 * math.pi) < cut.exit - cut.start for j in range(cut.teeth))


def state_size(modes: ToolModes, intervals: np.ndarray, cut: Cut) -> np.ndarray:
    """The monodromy's size per speed: 2 m + 4 (the cut's nodes but the period's last)."""
    period, ends = breakpoints(cut.teeth, cut.start, cut.exit)
    starts = [0.0, *ends[:-1]]
    cutting = np.array([_cutting(cut, cut.start + 0.5 * (a + b))
                        for a, b in zip(starts, ends, strict=True)])
    nodes = np.where(cutting[None, :], intervals + 1, 0).sum(1)
    nodes -= cutting.all() * len(ends)  # all cut: each segment's last node is the next's
    return 2 * modes.count + 4 * nodes


def estimate_seconds(modes: ToolModes, cut: Cut, speeds_hz) -> float:
    """Seconds a diagram takes: per speed and level, the depth trials (EVALUATIONS) times one
    monodromy's eigenvalues (EIG_SECONDS; measured on one core of the shared machine)."""
    total = 0.0
    for refine, trials in zip(LEVELS, EVALUATIONS, strict=True):
        n = state_size(modes, segment_intervals(cut, modes, speeds_hz, refine), cut)
        total += trials * float(np.sum(EIG_SECONDS[0] + EIG_SECONDS[1] * n.astype(float) ** 2))
    return total


def _grid(cut: Cut, intervals: tuple[int, ...]):
    """Node angles from the first tooth's entry, each interval's cut flag, and the nodes kept
    in the history (indices, last node excluded: it is the next period's first)."""
    period, ends = breakpoints(cut.teeth, cut.start, cut.exit)
    starts = [0.0, *ends[:-1]]
    angles, cutting = [0.0], []
    for a, b, n in zip(starts, ends, intervals, strict=True):
        flag = _cutting(cut, cut.start + 0.5 * (a + b))
        angles += list(np.linspace(a, b, n + 1)[1:])
        cutting += [flag] * n
    angles_a = np.array(angles)
    flags = np.array(cutting)
    last = len(angles_a) - 1
    used = sorted({i for k, f in enumerate(flags) if f for i in (k, k + 1)} - {last})
    return angles_a, flags, used


def _forces(cut: Cut, phi, mid):
    """K and dK/dphi (..., 2, 2) at angles phi with the teeth in the cut as at angles mid."""
    k = np.zeros(np.shape(phi) + (2, 2))
    dk = np.zeros_like(k)
    for j in range(cut.teeth):
        shift = 2 * math.pi * j / cut.teeth
        on = np.mod(mid + shift - cut.start, 2 * math.pi) < cut.exit - cut.start
        k += np.where(on[..., None, None], tooth_matrix(phi + shift, cut.kt, cut.kn), 0.0)
        dk += np.where(on[..., None, None], tooth_matrix_slope(phi + shift, cut.kt, cut.kn),
                       0.0)
    return k, dk


def _exponentials(modes: ToolModes, h: np.ndarray):
    """Per interval length h (...): e^{A h} (..., 2m, 2m) and the Hermite weights W00, W10,
    W01, W11 (..., 2m, 2), from one Van Loan exponential per mode (Van Loan, IEEE TAC 23:395,
    1978) of the free mode driven through the chain 1, s/h, (s/h)^2 / 2, (s/h)^3 / 6."""
    m = modes.count
    h = np.asarray(h, float)
    blk = np.zeros(h.shape + (m, 6, 6))
    w, z = modes.omega, modes.zeta
    hh = h[..., None]
    blk[..., 0, 1] = hh
    blk[..., 1, 0] = -(w**2) * hh
    blk[..., 1, 1] = -2 * z * w * hh
    blk[..., 1, 2] = hh
    blk[..., 2, 3] = 1.0
    blk[..., 3, 4] = 1.0
    blk[..., 4, 5] = 1.0
    e = scipy.linalg.expm(blk.reshape(-1, 6, 6)).reshape(blk.shape)
    m0, m1, m2, m3 = (e[..., :2, 2 + k] * f for k, f in enumerate((1.0, 1.0, 2.0, 6.0)))
    weights = (m0 - 3 * m2 + 2 * m3, m1 - 2 * m2 + m3, 3 * m2 - 2 * m3, m3 - m2)
    phi = np.zeros(h.shape + (2 * m, 2 * m))
    for r in range(m):
        phi[..., 2 * r:2 * r + 2, 2 * r:2 * r + 2] = e[..., r, :2, :2]
    shape = modes.shape  # (2, m)
    out = []
    for wk in weights:  # (..., m, 2) -> (..., 2m, 2): mode r's rows take U_r . F
        full = np.einsum("...ra,dr->...rad", wk, shape)
        out.append(full.reshape(h.shape + (2 * m, 2)))
    return phi, out


class Monodromy:
    """The monodromy of a group of speeds sharing one interval layout, at any depths."""

    def __init__(self, modes: ToolModes, cut: Cut, speeds_hz, intervals: tuple[int, ...],
                 order: int = 4):
        self.m = modes.count
        n = 2 * self.m
        speeds = np.asarray(speeds_hz, float)
        self.batch = len(speeds)
        angles, flags, used = _grid(cut, intervals)
        self.flags = flags
        self.last = len(angles) - 1
        self.slot = {node: 2 * self.m + 4 * k for k, node in enumerate(used)}
        self.size = n + 4 * len(used)
        rate = 2 * math.pi * speeds  # rad/s of the cutter
        self.tau = 1.0 / (cut.teeth * speeds)
        steps = np.diff(angles)
        h = steps[None, :] / rate[:, None]  # (B, K)
        self.h = h
        phi, (w00, w10, w01, w11) = _exponentials(modes, h)
        self.phi = phi
        mids = cut.start + 0.5 * (angles[:-1] + angles[1:])
        kl, dkl = _forces(cut, cut.start + angles[:-1], mids)  # (K, 2, 2) one-sided
        kr, dkr = _forces(cut, cut.start + angles[1:], mids)
        # left and right weights on (dr, dr') at the interval's ends: (B, K, 2m, 4)
        if order == 4:
            hq = h[..., None, None]
            spin = rate[:, None, None, None]  # dK/dt = Omega dK/dphi
            self.left = np.concatenate([w00 @ kl + hq * (w10 @ (dkl * spin)),
                                        hq * (w10 @ kl)], -1)
            self.right = np.concatenate([w01 @ kr + hq * (w11 @ (dkr * spin)),
                                         hq * (w11 @ kr)], -1)
        elif order == 2:  # a linear force: W0 = m0 - m1, W1 = m1
            m0, m1 = w00 + w01, _linear_m1(w10, w01, w11)
            self.left = np.concatenate([(m0 - m1) @ kl, 0.0 * (m0 @ kl)], -1)
            self.right = np.concatenate([m1 @ kr, 0.0 * (m1 @ kr)], -1)
        else:
            raise ValueError(f"order {order}: 2 or 4")
        u = modes.shape
        p = np.zeros((4, n))
        p[0:2, 0::2] = u
        p[2:4, 1::2] = u
        self.p = p  # (dr, dr') read from y

    def matrices(self, depth) -> np.ndarray:
        """The monodromy (B, size, size) at depths (B,), m."""
        b = np.asarray(depth, float)[:, None, None]
        n, size = 2 * self.m, self.size
        x = np.zeros((self.batch, n, size))
        x[:, :, :n] = np.eye(n)
        rows: list[np.ndarray] = [x] * (self.last + 1)
        rows[0] = x
        eye = np.eye(n)
        for i, flag in enumerate(self.flags):
            if not flag:
                x = self.phi[:, i] @ x
            else:
                left, right = b * self.left[:, i], b * self.right[:, i]
                rhs = self.phi[:, i] @ x + left @ (self.p @ x)
                s = self.slot[i]
                rhs[:, :, s:s + 4] -= left
                if i + 1 == self.last:
                    rhs[:, :, :n] -= right @ self.p
                else:
                    t = self.slot[i + 1]
                    rhs[:, :, t:t + 4] -= right
                x = np.linalg.solve(eye - right @ self.p, rhs)
            rows[i + 1] = x
        out = np.empty((self.batch, size, size))
        out[:, :n] = x
        for node, s in self.slot.items():
            out[:, s:s + 4] = self.p @ rows[node]
        return out

    def radius(self, depth) -> np.ndarray:
        """The spectral radius per speed (inf where the matrix overflowed: a depth far beyond
        any the search reaches from a stable start)."""
        mats = self.matrices(depth)
        try:
            return np.abs(np.linalg.eigvals(mats)).max(-1)
        except np.linalg.LinAlgError:  # a matrix with inf or nan entries
            bad = ~np.isfinite(mats).all((-2, -1))
            mats = np.where(bad[:, None, None], 0.0, mats)
            return np.where(bad, np.inf, np.abs(np.linalg.eigvals(mats)).max(-1))


def _linear_m1(w10, w01, w11):
    """m1 = int e^{A (h - s)} B (s / h) ds from the Hermite weights."""
    # W01 = 3 m2 - 2 m3, W11 = m3 - m2  ->  m2 = W01 + 2 W11, m3 = W01 + 3 W11;
    # W10 = m1 - 2 m2 + m3  ->  m1 = W10 + 2 m2 - m3
    m2 = w01 + 2 * w11
    m3 = w01 + 3 * w11
    return w10 + 2 * m2 - m3


def critical_depths(modes: ToolModes, cut: Cut, speeds_hz, start: float, ceiling: float,
                    refine: int = 1, order: int = 4, near=None) -> SpeedResult:
    """The least depth (m) at which each speed loses stability, with the chatter frequency
    and kind there: scanned up from the stable depth `start` in steps of LADDER, or, given
    `near` (a coarser level's depths, m), bracketed from just below them."""
    speeds = np.asarray(speeds_hz, float)
    counts = segment_intervals(cut, modes, speeds, refine)
    depth = np.full(len(speeds), np.inf)
    freq = np.full(len(speeds), np.nan)
    flip = np.zeros(len(speeds), bool)
    for layout in sorted({tuple(int(v) for v in row) for row in counts}):
        idx = np.flatnonzero((counts == layout).all(1))
        mono = Monodromy(modes, cut, speeds[idx], layout, order)
        if near is None:
            bracket = _scan(mono, np.full(len(idx), start), LADDER, ceiling)
        else:
            bracket = _around(mono, np.asarray(near, float)[idx], ceiling)
        d, f, fl = _refine(mono, modes, *bracket)
        depth[idx], freq[idx], flip[idx] = d, f, fl
    return SpeedResult(depth, freq, flip, counts.sum(1))


def _log_radius(mono: Monodromy, mask, depth) -> np.ndarray:
    """log rho of the speeds in `mask` at `depth` (nan elsewhere); a radius that is not a
    finite number (the eigensolver overflowed at a huge depth) counts as unstable."""
    out = np.full(mono.batch, np.nan)
    if mask.any():
        v = np.log(_sub(mono, mask).radius(depth[mask]))
        out[mask] = np.where(np.isnan(v) | np.isposinf(v), UNSTABLE_LOG, v)
    return out


def _scan(mono: Monodromy, start, ratio: float, ceiling: float, mask=None):
    """(lo, hi, log rho at lo, at hi): the last stable and first unstable depth of a ladder up
    from `start` (down first where `start` is not stable; hi inf: stable up to `ceiling`),
    for the speeds in `mask` (default all; the others come back as (start, inf))."""
    nb = mono.batch
    every = np.ones(nb, bool) if mask is None else np.asarray(mask, bool)
    lo = np.minimum(np.asarray(start, float), ceiling)
    flo = np.where(every, _log_radius(mono, every, lo), -1.0)
    hi, fhi = np.full(nb, np.inf), np.full(nb, np.inf)
    for _ in range(MAX_ITERATIONS):  # down until stable
        bad = flo >= 0
        if not bad.any():
            break
        hi, fhi = np.where(bad, lo, hi), np.where(bad, flo, fhi)
        lo = np.where(bad, lo / LADDER**2, lo)
        flo = np.where(bad, _log_radius(mono, bad, lo), flo)
    else:
        raise ComputeError("semi-discretization: a speed is unstable at every depth tried "
                           f"(down to {float(lo.min()):.3g} m): the tool modes cannot be cut")
    for _ in range(10 * MAX_ITERATIONS):  # up until unstable (or the ceiling)
        up = every & np.isinf(hi) & (lo < ceiling)
        if not up.any():
            break
        trial = np.minimum(lo * ratio, ceiling)
        f = _log_radius(mono, up, trial)
        stable, unstable = up & (f < 0), up & (f >= 0)
        lo, flo = np.where(stable, trial, lo), np.where(stable, f, flo)
        hi, fhi = np.where(unstable, trial, hi), np.where(unstable, f, fhi)
    return lo, hi, flo, fhi


def _around(mono: Monodromy, near, ceiling: float):
    """_scan's bracket about a coarser level's depths: near / NEAR stable and near * NEAR
    not, or else a scan in steps of NEAR from near / NEAR (down first if not stable)."""
    known = np.isfinite(near)
    lo = np.where(known, near / NEAR, ceiling)
    hi = np.where(known, near * NEAR, np.inf)
    flo = _log_radius(mono, np.ones(mono.batch, bool), lo)
    fhi = np.where(known, _log_radius(mono, known & (flo < 0), hi), np.inf)
    ok = (flo < 0) & ((fhi >= 0) | ~known)
    if ok.all():
        return lo, hi, flo, fhi
    scan = _scan(mono, lo, NEAR, ceiling, mask=~ok)
    return tuple(np.where(ok, a, b) for a, b in zip((lo, hi, flo, fhi), scan, strict=True))


def _refine(mono: Monodromy, modes: ToolModes, lo, hi, flo, fhi):
    """Illinois' regula falsi on log rho within each bracket (log rho flo < 0 at lo, fhi >= 0
    at hi), all speeds in step; the critical multiplier's kind and chatter frequency at the
    top of the final bracket."""
    nb = mono.batch
    found = np.isfinite(hi)
    side = np.zeros(nb)
    for _ in range(MAX_ITERATIONS):
        act = found & ((hi - lo) > TOLERANCE * hi)
        if not act.any():
            break
        t = np.clip(flo / np.where(act, flo - fhi, -1.0), 0.02, 0.98)
        trial = lo + t * (np.where(act, hi, lo) - lo)
        ft = _log_radius(mono, act, trial)
        stable = act & (ft < 0)
        unstable = act & (ft >= 0)
        fhi = np.where(stable & (side < 0), fhi / 2, fhi)  # Illinois: halve the end value
        flo = np.where(unstable & (side > 0), flo / 2, flo)  # that stayed put twice
        lo, flo = np.where(stable, trial, lo), np.where(stable, ft, flo)
        hi, fhi = np.where(unstable, trial, hi), np.where(unstable, ft, fhi)
        side = np.where(stable, -1.0, np.where(unstable, 1.0, side))
    depth = np.where(found, 0.5 * (lo + hi), np.inf)
    freq = np.full(nb, np.nan)
    flip = np.zeros(nb, bool)
    if found.any():
        sub = _sub(mono, found)
        vals, vecs = np.linalg.eig(sub.matrices(hi[found]))
        top = np.abs(vals).argmax(-1)
        mu = vals[np.arange(len(top)), top]
        vec = vecs[np.arange(len(top)), :, top]
        flip[found] = (np.abs(mu.imag) <= 1e-12 * np.abs(mu)) & (mu.real < 0)
        freq[found] = _chatter_hz(mu, vec, modes, sub.tau)
    return depth, freq, flip


def _sub(mono: Monodromy, mask) -> Monodromy:
    """The monodromy of the speeds in `mask` (a view of the same data)."""
    sub = object.__new__(Monodromy)
    sub.__dict__.update(mono.__dict__)
    sub.batch = int(mask.sum())
    sub.phi, sub.left, sub.right = mono.phi[mask], mono.left[mask], mono.right[mask]
    sub.tau, sub.h = mono.tau[mask], mono.h[mask]
    return sub


def _chatter_hz(mu, vec, modes: ToolModes, tau) -> np.ndarray:
    """The chatter frequency of multiplier mu (+-angle + 2 pi k) / tau nearest to the mode
    the critical solution moves most (its start state's modal amplitudes)."""
    m = modes.count
    q, dq = vec[:, 0:2 * m:2], vec[:, 1:2 * m:2]
    amp = np.abs(q) ** 2 * modes.omega**2 + np.abs(dq) ** 2
    wdom = modes.omega[amp.argmax(-1)]
    base = np.abs(np.angle(mu)) / tau
    step = 2 * math.pi / tau
    cands = []
    for sign in (1.0, -1.0):
        k = np.round((wdom - sign * base) / step)
        cands.append(np.abs(sign * base + k * step))
    c = np.stack(cands, 1)
    best = c[np.arange(len(c)), np.abs(c - wdom[:, None]).argmin(1)]
    return best / (2 * math.pi)
