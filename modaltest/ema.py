"""Modes from FRFs: poly-reference LSCF poles over a stabilisation chart, picked automatically,
then sdypy-EMA's LSFD residues (no GUI, no plot, no progress bar).

1. The poles of every model order come from the FRFs of every reference together
   (`modaltest.plscf`, pLSCF: a right matrix-fraction model with an m x m denominator for m
   references; one reference: the scalar common-denominator LSCF), orders 1 ..
   2 * model_order / m (the chart's top holds 2 * model_order poles whatever m). The outputs
   are the response dofs measured for every reference; with no such dof, every FRF is an
   output of one scalar denominator.
2. A pole is kept if it is physical: positive frequency in the band, damping ratio in
   (0, max_damping_ratio].
3. It is stable if it continues a chain of poles over `stable_orders` consecutive orders, each
   within `frequency_tolerance` (relative) in frequency and `damping_tolerance` (relative) in
   damping of one of the previous order.
4. The stable poles are clustered by frequency (consecutive, sorted, relative gap below
   CLUSTER_SHARE_OF_TOLERANCE x `frequency_tolerance`; `common.modes.clusters`), and a cluster
   that holds two or more poles of one order in `stable_orders` or more of its orders is split
   at its largest gaps into as many (a mode has one pole an order: two modes 1 % apart stay
   two). A cluster is one physical mode if it spans at least `cluster_share` of the orders the
   longest one spans and its members scatter (robust standard deviation) within
   `scatter_share` x `frequency_tolerance` in frequency and DAMPING_SCATTER in damping (a
   physical mode stabilises early and stays put; a noise pole stabilises briefly or wanders);
   its pole has the cluster's median frequency and median damping ratio, and that scatter is
   stated. The clusters dropped are said (`Extraction.dropped`), never silently.
5. sdypy's LSFD (with lower and upper residuals for the modes outside the band) gives the
   residues of these poles in every FRF. A mode's shape at the outputs: the residues of every
   reference combined by least squares (the first singular vector of the outputs x references
   residue matrix: the reference that drives the mode most weighs most), made real by the best
   common phase rotation (`uff.complex_to_real_shape`), scaled to a largest component of +1, at
   the response dofs of the reference dof most FRFs share.

The frequency is |lambda| / 2 pi (undamped natural frequency), the damping ratio
-Re lambda / |lambda|. Any frequency axis serves (the pLSCF basis is z = exp(i w pi / w_top)).
"""
from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass

import numpy as np

from common.errors import ComputeError, InputError
from common.messages import one_line
from common.modes import clusters

from . import uff

# stable poles cluster at this share of the frequency tolerance: a mode's poles agree across
# orders far closer than the tolerance that links them (measured 1e-5-1e-3 relative), a noise
# pole's wander (1-10 %), so a noise cluster beside a mode stays apart and spans few orders
CLUSTER_SHARE_OF_TOLERANCE = 0.2
# a mode's damping ratios over its stable orders scatter within this, relative (measured with
# 1.5 % FRF noise: physical modes 0.2-6 %, clusters of wandering noise poles 15-30 % and more)
DAMPING_SCATTER = 0.12
SAY_DROPPED = 3
_DEBUG = False  # the longest dropped clusters named


class EmaError(InputError):
    """Identification refused: the band, the settings or the FRFs; one line."""


@dataclass(frozen=True)
class EmaSettings:
    """The band and the automatic reading of the stabilisation chart.

    Defaults: 1 % in frequency and 10 % in damping between consecutive orders (the usual
    stabilisation-chart criteria are 1 % and 5-10 %; the damping estimate scatters more than
    the frequency, and with 1.5 % FRF noise 5 % broke the chains of real modes); five
    consecutive stable orders (four successive checks) reject the wandering noise poles yet
    leave room for modes that appear only at high orders; a damping ratio above 20 % is not a
    structural mode one reads from a chart but a computational pole that models noise or
    out-of-band residue; `cluster_share` and `scatter_share`: module docstring, step 4.
    """

    lower_hz: float
    upper_hz: float
    model_order: int = 60  # the chart's top holds 2 x model_order poles (pLSCF: orders up to
    # 2 x model_order / references)
    frequency_tolerance: float = 0.01  # relative change between consecutive orders
    damping_tolerance: float = 0.1  # relative change between consecutive orders
    stable_orders: int = 5  # consecutive orders a pole must persist over
    max_damping_ratio: float = 0.2
    cluster_share: float = 0.25  # orders a mode's cluster spans / the longest one's (measured
    # with 1.5 % FRF noise and two references: modes 29-53 of 53, noise clusters 5-16)
    scatter_share: float = 0.3  # a mode's frequencies over its orders scatter within this
    # share of frequency_tolerance, robust standard deviation (measured: physical modes
    # 1e-5-1.1e-3 relative with 1.5 % FRF noise, wandering noise clusters 1e-2)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.lower_hz) and math.isfinite(self.upper_hz)
                and 0.0 <= self.lower_hz < self.upper_hz):
            raise EmaError(f"EMA band {self.lower_hz:g}-{self.upper_hz:g} Hz: expected "
                           "0 <= lower < upper, finite")
        if not 2 <= self.stable_orders <= self.model_order:
            raise EmaError(f"EMA model_order {self.model_order}, stable_orders "
                           f"{self.stable_orders}: expected 2 <= stable_orders <= model_order")
        for name in ("frequency_tolerance", "damping_tolerance", "max_damping_ratio",
                     "cluster_share", "scatter_share"):
            value = getattr(self, name)
            if not 0.0 < value <= 1.0:
                raise EmaError(f"EMA {name} {value:g}: expected in (0, 1]")


def identify_modes(frfs: uff.Frfs, settings: EmaSettings) -> uff.Modes:
    """Natural frequencies, damping ratios and real shapes (at the response dofs of the
    reference dof's FRFs, every reference combined) of the modes stable in the band; EmaError
    if the band leaves the FRFs' axis or no pole is stable."""
    return extract(frfs, settings).modes


@dataclass(frozen=True)
class Extraction:
    """What the extraction found (module docstring): the modes, their poles (rad/s) and
    residues (FRFs x modes), the scatter of each mode over its stable orders, and the pole
    clusters the stabilisation rule dropped, in words."""

    modes: uff.Modes
    poles: np.ndarray
    residues: np.ndarray
    frequency_scatter: np.ndarray  # relative standard deviation over the stable orders
    damping_scatter: np.ndarray  # relative standard deviation over the stable orders
    references: int  # the references the poles came from together (1: a scalar denominator)
    dropped: tuple[str, ...]

    def describe(self) -> str:
        """One line: references, the scatter at worst, what was dropped."""
        text = (f"poles from {self.references} reference{'s' if self.references > 1 else ''}"
                " together (pLSCF), "
                f"{len(self.poles)} modes; over their stable orders the frequencies scatter "
                f"{100 * self.frequency_scatter.max(initial=0):.2g} % and the damping ratios "
                f"{100 * self.damping_scatter.max(initial=0):.2g} % at most")
        if self.dropped:
            text += "; dropped as noise: " + "; ".join(self.dropped)
        return text


def poles_and_residues(frfs: uff.Frfs, settings: EmaSettings) -> tuple[np.ndarray, np.ndarray]:
    """The stable poles lambda (m,), ascending in frequency, and their LSFD residues A (k, m)
    in every FRF (module docstring): H_jk(w) = sum_r A_jk,r / (i w - lambda_r) + conjugate,
    so that a mass-normalised real mode has phi_j phi_k = (lambda_r - conj lambda_r) A_jk,r =
    Re(2 i omega_d A_jk,r) (omega_d = Im lambda_r > 0). EmaError as identify_modes."""
    found = extract(frfs, settings)
    return found.poles, found.residues


def extract(frfs: uff.Frfs, settings: EmaSettings) -> Extraction:
    """The extraction of the module docstring."""
    from .plscf import poles_by_order

    f = frfs.frequency_hz
    lower, upper = settings.lower_hz, settings.upper_hz
    if lower < f[0] or upper > f[-1]:
        raise EmaError(f"EMA band {lower:g}-{upper:g} Hz: outside the FRFs' frequency axis "
                       f"{f[0]:g}-{f[-1]:g} Hz")
    band = (f >= max(lower, 1e-9)) & (f <= upper)  # never the 0 Hz line (residuals / omega)
    if np.count_nonzero(band) < 10:
        raise EmaError(f"EMA band {lower:g}-{upper:g} Hz: fewer than 10 frequency lines")
    said = f"{lower:g}-{upper:g} Hz"
    live = np.abs(frfs.values[:, band]).max(axis=1) > 0.0  # a dead channel is left out
    if not live.any():
        raise EmaError(f"EMA band {said}: every FRF is zero in the band")
    refs = _reference_keys(frfs.reference)
    grid, m = _output_grid(frfs, refs, live)
    order = max(settings.stable_orders + 1, int(round(2 * settings.model_order / m)))
    try:
        chart = poles_by_order(f[band], frfs.values[grid][..., band] if m > 1
                               else frfs.values[live][:, None, band], m, order)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise ComputeError(f"pLSCF failed in {said}: {one_line(exc)}") from None
    picked, scatter_f, scatter_z, dropped = _pick(chart, settings, lower, upper)
    if not len(picked):
        raise EmaError(f"EMA band {said}: no pole stable over {settings.stable_orders} "
                       f"consecutive orders up to order {order}")
    from sdypy.EMA.EMA import LSFD  # late: sdypy loads matplotlib (about a second)

    lines = int(np.count_nonzero(band))
    try:
        with np.errstate(divide="ignore", invalid="ignore"):
            residues, _, _, _ = LSFD(picked, frfs.values[:, band], f[band], True, True, 0,
                                     lines, "receptance")
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise ComputeError(f"sdypy-EMA LSFD failed in {said}: {one_line(exc)}") from None
    residues = np.asarray(residues)
    rows = _reference_rows(frfs.reference)
    shapes = np.empty((len(rows), len(picked)))
    columns = _reference_columns(frfs, rows, refs)
    for r in range(len(picked)):
        real = uff.complex_to_real_shape(_combined(residues[:, r], columns))
        shapes[:, r] = real / np.max(np.abs(real))
    dofs = uff.Dofs(frfs.dofs.node[rows], frfs.dofs.direction[rows])
    hz = np.abs(picked) / (2.0 * np.pi)
    modes = uff.Modes(hz, -picked.real / np.abs(picked), dofs, shapes)
    left = int((~live).sum())
    if left:
        dropped = (f"{left} FRF{'s' if left > 1 else ''} zero in the band (a dead channel) "
                   "left out",) + dropped
    return Extraction(modes, picked, residues, scatter_f, scatter_z, m, dropped)


def _reference_keys(reference: uff.Dofs) -> list[tuple]:
    """The distinct reference dofs, in order of appearance."""
    keys = [(int(n), tuple(np.round(d, 9).tolist())) for n, d in
            zip(reference.node, reference.direction)]
    return list(dict.fromkeys(keys))


def _dof_keys(dofs: uff.Dofs) -> list[tuple]:
    return [(int(n), tuple(np.round(d, 9).tolist())) for n, d in zip(dofs.node, dofs.direction)]


def _output_grid(frfs: uff.Frfs, refs: list[tuple], live: np.ndarray
                 ) -> tuple[np.ndarray, int]:
    """(rows (outputs, m), m): the FRF rows of every response dof measured (live) for all m
    references, when they are at least 2 m (the matrix denominator's m x m from fewer would
    invent poles) and hold at least half the live FRFs; else ([], 1): every live FRF one
    output of a scalar denominator."""
    if len(refs) < 2:
        return np.zeros((0, 1), int), 1
    by_output: dict[tuple, dict[tuple, int]] = {}
    for (out, ref), i in _frf_index(frfs).items():
        if live[i]:
            by_output.setdefault(out, {})[ref] = i
    grid = [[row[r] for r in refs] for row in by_output.values() if all(r in row for r in refs)]
    if len(grid) < 2 * len(refs) or 2 * len(grid) * len(refs) < int(live.sum()):
        return np.zeros((0, 1), int), 1
    return np.array(grid, int), len(refs)


def _frf_index(frfs: uff.Frfs) -> dict[tuple[tuple, tuple], int]:
    """(response dof, reference dof) -> the first FRF row that holds it."""
    at: dict[tuple[tuple, tuple], int] = {}
    for i, key in enumerate(zip(_dof_keys(frfs.dofs), _dof_keys(frfs.reference))):
        at.setdefault(key, i)
    return at


def _reference_columns(frfs: uff.Frfs, rows: list[int], refs: list[tuple]) -> np.ndarray:
    """(outputs, references) FRF rows: for the response dofs of `rows`, those of every
    reference whose FRFs reach all of them (one column: `rows` alone)."""
    at = _frf_index(frfs)
    keys = _dof_keys(frfs.dofs)
    outputs = [keys[i] for i in rows]
    columns = [[at[(o, r)] for o in outputs] for r in refs if all((o, r) in at for o in outputs)]
    return np.array(columns, int).T if len(columns) >= 2 else np.array(rows, int)[:, None]


def _combined(residue: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """A mode's complex shape from its residues at the FRF rows `columns` (outputs x
    references): the first singular vector (one reference: its residues)."""
    if columns.shape[1] < 2:
        return residue[columns[:, 0]]
    u, _, _ = np.linalg.svd(residue[columns], full_matrices=False)
    return u[:, 0]


def _pick(chart: list[np.ndarray], s: EmaSettings, lower: float, upper: float
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[str, ...]]:
    """(poles, frequency scatter, damping scatter, dropped): one pole per mode of the chart
    (steps 2-4 of the module docstring), ascending in frequency."""
    stable: list[tuple[float, float, int, complex]] = []  # frequency, damping, order, pole
    dropped: list[tuple[int, float]] = []  # span, frequency
    previous: list[tuple[float, float, int]] = []  # frequency, damping, chain length
    for o, row in enumerate(chart):
        p = np.asarray(row, dtype=np.complex128)
        with np.errstate(divide="ignore", invalid="ignore"):
            hz, zeta = np.abs(p) / (2.0 * np.pi), -p.real / np.abs(p)
        physical = (np.isfinite(p) & (p.imag > 0.0) & (zeta > 0.0)
                    & (zeta <= s.max_damping_ratio) & (hz >= lower) & (hz <= upper))
        current = []
        for i in np.flatnonzero(physical):
            fi, zi = float(hz[i]), float(zeta[i])
            match = [(abs(fi - fq), c) for fq, zq, c in previous
                     if abs(fi - fq) <= s.frequency_tolerance * fq
                     and abs(zi - zq) <= s.damping_tolerance * zq]
            chain = 1 + min(match)[1] if match else 1
            current.append((fi, zi, chain))
            if chain >= s.stable_orders:
                stable.append((fi, zi, o, complex(p[i])))
        previous = current
    if not stable:
        return np.zeros(0, complex), np.zeros(0), np.zeros(0), ()
    stable.sort(key=lambda m: m[0])
    groups: list[list[tuple[float, float, int, complex]]] = []
    for g in clusters(np.array([m[0] for m in stable]), CLUSTER_SHARE_OF_TOLERANCE
                      * s.frequency_tolerance):
        groups += _split(sorted((stable[k] for k in g), key=lambda m: m[0]), s.stable_orders)
    spans = [len({m[2] for m in members}) for members in groups]
    poles, spread_f, spread_z = [], [], []
    for members, span in zip(groups, spans):
        f_all = np.array([m[0] for m in members])
        z_all = np.array([m[1] for m in members])
        f_mid, z_mid = float(np.median(f_all)), float(np.median(z_all))
        f_scatter, z_scatter = _scatter(f_all) / f_mid, _scatter(z_all) / z_mid
        if (span < max(s.stable_orders, s.cluster_share * max(spans))
                or f_scatter > s.scatter_share * s.frequency_tolerance
                or z_scatter > DAMPING_SCATTER):
            dropped.append((span, f_mid))
            continue
        w = 2 * math.pi * f_mid  # the medians over its stable orders: one order's jitter out
        poles.append(complex(-z_mid * w, w * math.sqrt(1.0 - z_mid**2)))
        spread_f.append(float(f_scatter))
        spread_z.append(float(z_scatter))
    order = np.argsort(np.abs(poles))
    said: tuple[str, ...] = ()
    if dropped:
        longest = sorted(dropped, reverse=True)[:SAY_DROPPED]
        said = (f"{len(dropped)} clusters of poles stable over too few orders or wandering "
                "(the longest: "
                + ", ".join(f"{f:.4g} Hz over {n} of {len(chart)}" for n, f in longest) + ")",)
    return (np.array(poles)[order], np.array(spread_f)[order], np.array(spread_z)[order],
            said)


def _scatter(values: np.ndarray) -> float:
    """A robust standard deviation: 1.4826 times the median absolute deviation (a few stray
    poles in a mode's cluster do not inflate it; a wandering cluster's is large)."""
    return float(1.4826 * np.median(np.abs(values - np.median(values))))


def _split(members: list[tuple[float, float, int, complex]], stable_orders: int
           ) -> list[list[tuple[float, float, int, complex]]]:
    """A frequency cluster (sorted) that holds k poles of one order in at least
    `stable_orders` of its orders: k modes, split at its k - 1 largest relative gaps (a
    close pair holds two poles in nearly every order; a mode with a stray pole beside it at
    a few orders stays one)."""
    counts = Counter(m[2] for m in members).values()
    k = max((c for c in counts if sum(1 for d in counts if d >= c) >= stable_orders),
            default=1)
    if k < 2:
        return [members]
    f = np.array([m[0] for m in members])
    cuts = [0, *sorted(int(c) + 1 for c in np.argsort(np.diff(f) / f[:-1])[-(k - 1):]),
            len(members)]
    return [members[a:b] for a, b in zip(cuts[:-1], cuts[1:]) if b > a]


def _reference_rows(reference: uff.Dofs) -> list[int]:
    """The FRFs of the reference dof most of them share (the first such, on a tie)."""
    keys = [(int(n), tuple(np.round(d, 9).tolist())) for n, d in
            zip(reference.node, reference.direction)]
    counts = Counter(keys)
    best = max(keys, key=lambda k: counts[k])  # max keeps the first of equal counts
    return [i for i, k in enumerate(keys) if k == best]
