"""Modes from FRFs with sdypy-EMA: LSCF poles over a stabilisation chart, picked automatically,
then LSFD residues (no GUI, no plot, no progress bar).

1. sdypy's LSCF fits the receptances in the band at the polynomial orders 2, 4, ...,
   2 * model_order (sdypy's `pol_order_high` is this `model_order`: one chart row per even
   order).
2. A pole is kept if it is physical: positive frequency in the band, damping ratio in
   (0, max_damping_ratio].
3. It is stable if it continues a chain of poles over `stable_orders` consecutive orders, each
   within `frequency_tolerance` (relative) in frequency and `damping_tolerance` (relative) in
   damping of one of the previous order.
4. The stable poles are clustered by frequency (consecutive, sorted, relative gap below
   `frequency_tolerance`; `common.modes.clusters`): one cluster, one physical mode, if it spans
   at least `cluster_share` of the orders the largest cluster spans (a physical mode
   stabilises early and stays; a noise pole stabilises briefly, at high orders); its pole is
   the member closest to the cluster's median frequency and damping ratio. Two modes closer
   than `frequency_tolerance` are therefore reported as one.
5. sdypy's LSFD (with lower and upper residuals) gives the residues of these poles in every
   FRF; the shape of a mode is the column of the reference dof (the one most FRFs share) made
   real by the best common phase rotation (`uff.complex_to_real_shape`), scaled to a largest
   component of +1, at those FRFs' response dofs.

The frequency is |lambda| / 2 pi (undamped natural frequency), the damping ratio
-Re lambda / |lambda|. sdypy's LSCF needs an evenly spaced frequency axis that continues down
to 0 Hz (it pads the missing lines with zeros), so other axes are refused.
"""
from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass
from typing import Any

import numpy as np

from common.errors import ComputeError, InputError
from common.messages import one_line
from common.modes import clusters

from . import uff


class EmaError(InputError):
    """Identification refused: the band, the settings or the FRFs; one line."""


@dataclass(frozen=True)
class EmaSettings:
    """The band and the automatic reading of the stabilisation chart.

    Defaults: 1 % in frequency and 5 % in damping between consecutive orders are the usual
    stabilisation-chart criteria (the damping estimate scatters more than the frequency); five
    consecutive stable orders (four successive checks) reject the wandering noise poles yet
    leave room, within the 60 rows of the default chart, for modes that appear only at high
    orders; a damping ratio above 20 % is not a structural mode one reads from a chart but a
    computational pole that models noise or out-of-band residue; a cluster spanning less than
    40 % of the orders of the best one is a noise pole that stabilised late (on synthetic FRFs
    with 2 % noise: physical modes span 52 of 60 orders, noise poles 5-13).
    """

    lower_hz: float
    upper_hz: float
    model_order: int = 60  # highest polynomial order / 2 of LSCF (sdypy's pol_order_high)
    frequency_tolerance: float = 0.01  # relative change between consecutive orders
    damping_tolerance: float = 0.05  # relative change between consecutive orders
    stable_orders: int = 5  # consecutive orders a pole must persist over
    max_damping_ratio: float = 0.2
    cluster_share: float = 0.4  # orders a cluster spans / orders the largest one spans

    def __post_init__(self) -> None:
        if not (math.isfinite(self.lower_hz) and math.isfinite(self.upper_hz)
                and 0.0 <= self.lower_hz < self.upper_hz):
            raise EmaError(f"EMA band {self.lower_hz:g}-{self.upper_hz:g} Hz: expected "
                           "0 <= lower < upper, finite")
        if not 2 <= self.stable_orders <= self.model_order:
            raise EmaError(f"EMA model_order {self.model_order}, stable_orders "
                           f"{self.stable_orders}: expected 2 <= stable_orders <= model_order")
        for name in ("frequency_tolerance", "damping_tolerance", "max_damping_ratio",
                     "cluster_share"):
            value = getattr(self, name)
            if not 0.0 < value <= 1.0:
                raise EmaError(f"EMA {name} {value:g}: expected in (0, 1]")


def identify_modes(frfs: uff.Frfs, settings: EmaSettings) -> uff.Modes:
    """Natural frequencies, damping ratios and real shapes (at the response dofs of the
    reference dof's FRFs) of the modes stable in the band; EmaError if the band leaves the FRFs'
    axis, the axis does not suit LSCF, or no pole is stable."""
    poles, residues = poles_and_residues(frfs, settings)
    hz = np.abs(poles) / (2.0 * np.pi)
    zeta = -poles.real / np.abs(poles)
    rows = _reference_rows(frfs.reference)
    shapes = np.empty((len(rows), len(poles)))
    for r in range(len(poles)):
        real = uff.complex_to_real_shape(residues[rows, r])
        shapes[:, r] = real / np.max(np.abs(real))
    dofs = uff.Dofs(frfs.dofs.node[rows], frfs.dofs.direction[rows])
    return uff.Modes(hz, zeta, dofs, shapes)


def poles_and_residues(frfs: uff.Frfs, settings: EmaSettings) -> tuple[np.ndarray, np.ndarray]:
    """The stable poles lambda (m,), ascending in frequency, and their LSFD residues A (k, m)
    in every FRF (steps 1-5 of the module docstring): H_jk(w) = sum_r A_jk,r /
    (i w - lambda_r) + conjugate, so that a mass-normalised real mode has phi_j phi_k =
    (lambda_r - conj lambda_r) A_jk,r = Re(2 i omega_d A_jk,r) (omega_d = Im lambda_r > 0).
    EmaError as identify_modes."""
    f = frfs.frequency_hz
    lower, upper = settings.lower_hz, settings.upper_hz
    df = float(f[1] - f[0])
    if lower < f[0] or upper > f[-1]:
        raise EmaError(f"EMA band {lower:g}-{upper:g} Hz: outside the FRFs' frequency axis "
                       f"{f[0]:g}-{f[-1]:g} Hz")
    if np.max(np.abs(np.diff(f) - df)) > 1e-6 * df or abs(f[0] / df - round(f[0] / df)) > 1e-6:
        raise EmaError(f"FRF frequency axis {f[0]:g}-{f[-1]:g} Hz: LSCF needs even spacing on a "
                       "grid that continues down to 0 Hz")
    if np.count_nonzero((f >= lower) & (f <= upper)) < 10:
        raise EmaError(f"EMA band {lower:g}-{upper:g} Hz: fewer than 10 frequency lines")
    lower = max(lower, df)  # never the 0 Hz line: LSFD's lower residual divides by omega

    from sdypy import EMA  # late: it loads matplotlib (about a second)

    band = f"{settings.lower_hz:g}-{upper:g} Hz"
    try:
        model = EMA.Model(frf=np.array(frfs.values), freq=np.array(f), lower=lower, upper=upper,
                          pol_order_high=settings.model_order, frf_form="receptance")
        model.get_poles(method="lscf", show_progress=False)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise ComputeError(f"sdypy-EMA LSCF failed in {band}: {one_line(exc)}") from None
    picked = _pick(model.all_poles, settings, lower, upper)
    if not picked:
        raise EmaError(f"EMA band {band}: no pole stable over {settings.stable_orders} "
                       f"consecutive orders up to LSCF order {2 * settings.model_order}")
    model.pole_ind = np.array(picked, dtype=int)
    try:  # f_upper: the model's last line (sdypy cut its axis just below `upper`)
        _, residues = model.get_constants(method="lsfd", whose_poles="own", f_lower=lower,
                                          f_upper=float(model.freq[-1]))
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise ComputeError(f"sdypy-EMA LSFD failed in {band}: {one_line(exc)}") from None
    poles = np.array([model.all_poles[o][i] for o, i in picked])
    order = np.argsort(np.abs(poles))
    return poles[order], np.asarray(residues)[:, order]


def _pick(all_poles: list[Any], s: EmaSettings, lower: float,
          upper: float) -> list[tuple[int, int]]:
    """(order index, pole index) of one pole per cluster of stable poles."""
    stable: list[tuple[float, float, int, int]] = []  # frequency, damping, order, index
    previous: list[tuple[float, float, int]] = []  # frequency, damping, chain length
    for o, row in enumerate(all_poles):
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
                stable.append((fi, zi, o, int(i)))
        previous = current
    if not stable:
        return []
    stable.sort()
    groups = [[stable[k] for k in g]
              for g in clusters(np.array([p[0] for p in stable]), s.frequency_tolerance)]
    spans = [len({m[2] for m in members}) for members in groups]
    picked = []
    for members, span in zip(groups, spans):
        if span < s.cluster_share * max(spans):
            continue
        f_mid = float(np.median([m[0] for m in members]))
        z_mid = float(np.median([m[1] for m in members]))
        best = min(members, key=lambda m: abs(m[0] - f_mid) / f_mid + abs(m[1] - z_mid) / z_mid)
        picked.append((best[2], best[3]))
    return picked


def _reference_rows(reference: uff.Dofs) -> list[int]:
    """The FRFs of the reference dof most of them share (the first such, on a tie)."""
    keys = [(int(n), tuple(np.round(d, 9).tolist())) for n, d in
            zip(reference.node, reference.direction)]
    counts = Counter(keys)
    best = max(keys, key=lambda k: counts[k])  # max keeps the first of equal counts
    return [i for i, k in enumerate(keys) if k == best]
