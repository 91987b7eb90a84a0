"""A stability lobe diagram from the tool's modes and the cut (`lobes`): per spindle speed the
least axial depth at which the cut chatters, its chatter frequency and kind, by the method the
[cutting] table names, with the zero-order estimate beside it and, for semi-discretization,
its own discretisation error (the depth at twice the intervals). Edge units in the record
(mm, rpm, Hz); SI inside."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from common.errors import InputError
from common.settings import edge_values

from .cutting import Cutting
from .milling import ToolModes, force_matrix, mean_force_matrix
from .sdm import CEILING_FACTOR, LEVELS, Cut, critical_depths, estimate_seconds
from .zoa import absolute_limit, zoa_depths

MAX_SECONDS = 1800.0  # a diagram estimated longer is refused (fewer speeds or modes)
# the fine level's stated error: |fine - coarse| / 3, Richardson's estimate for a second-order
# scheme (the scheme is fourth order, so it bounds the fine level's error about fivefold;
# checked against eight times the intervals in tests/test_lobes.py)
ERROR_DIVISOR = 3.0
NEGLIGIBLE = 1e-9  # a mode whose peak flexibility at the tool is below this share: left out


def cut_of(cutting: Cutting) -> Cut:
    start, exit_ = cutting.engagement
    return Cut(cutting.teeth, start, exit_, cutting.kt, cutting.kn)


def relevant(modes: ToolModes) -> tuple[ToolModes, np.ndarray]:
    """The modes that move the tool in the cut's plane (peak flexibility |U_j|^2 /
    (2 zeta_j omega_j^2) above NEGLIGIBLE of the largest), and their indices."""
    flex = (modes.shape**2).sum(0) / (2 * modes.zeta * modes.omega**2)
    keep = np.flatnonzero(flex > NEGLIGIBLE * flex.max())
    return ToolModes(modes.omega[keep], modes.zeta[keep], modes.shape[:, keep]), keep


def small_gain_depth(modes: ToolModes, cut: Cut) -> float:
    """1 / (2 max |K(t)| max |G(w)|) (m): below it the loop b K(t) (1 - e^{-s tau}) G has gain
    below 1, so the cut is stable (the small-gain theorem holds for a time-varying loop); the
    scan starts there and stops at CEILING_FACTOR times it. |G| is read about every mode's
    peak (a sampled maximum: the scan checks the start anyway)."""
    phi = np.linspace(0, 2 * math.pi, 1441)
    kmax = float(np.linalg.norm(force_matrix(phi, cut.teeth, cut.start, cut.exit, cut.kt,
                                             cut.kn), ord=2, axis=(-2, -1)).max())
    w = (modes.omega[:, None] * (1 + np.linspace(-3, 3, 61)[None, :] * modes.zeta[:, None]))
    gmax = float(np.linalg.norm(modes.receptance(w.ravel()), ord=2, axis=(-2, -1)).max())
    return 1.0 / (2.0 * kmax * gmax)


@dataclass(frozen=True)
class Plan:
    """What a diagram will take, said before it starts."""

    speeds: int
    modes: int
    seconds: float


def plan(modes: ToolModes, cutting: Cutting) -> Plan:
    """The diagram's cost estimate; InputError when beyond MAX_SECONDS."""
    used, _ = relevant(modes)
    speeds = cutting.speeds_hz()
    seconds = (estimate_seconds(used, cut_of(cutting), speeds) if cutting.method == "sdm"
               else 1e-3 * len(speeds))
    if seconds > MAX_SECONDS:
        raise InputError(f"cutting: {len(speeds)} speeds with {used.count} tool modes up to "
                         f"{used.omega.max() / (2 * math.pi):.4g} Hz, estimated "
                         f"{seconds / 60:.0f} min by semi-discretization (at most "
                         f"{MAX_SECONDS / 60:.0f}): give fewer speeds, a higher lowest speed, "
                         "or method = 'zoa'")
    return Plan(len(speeds), used.count, seconds)


@dataclass(frozen=True)
class Diagram:
    """One diagram's arrays (SI; depth inf: stable up to the ceiling)."""

    speeds_hz: np.ndarray
    depth: np.ndarray  # m
    frequency_hz: np.ndarray  # nan where none
    kind: np.ndarray  # "hopf", "flip", "" (none)
    zoa_depth: np.ndarray  # m
    absolute_limit: float  # m (inf: none)
    ceiling: float  # m
    used: np.ndarray  # the modes' indices that entered
    coarse_depth: np.ndarray | None = None  # sdm: at half the intervals
    error_percent: np.ndarray | None = None  # sdm: the stated error of depth
    intervals: np.ndarray | None = None
    coarse_intervals: np.ndarray | None = None

    @property
    def least(self) -> int | None:
        """The speed of the least depth (None: stable everywhere)."""
        finite = np.isfinite(self.depth)
        return int(np.argmin(np.where(finite, self.depth, np.inf))) if finite.any() else None

    @property
    def best(self) -> int:
        """The speed of the largest depth (a stable one first)."""
        return int(np.argmax(self.depth))


def diagram(modes: ToolModes, cutting: Cutting, speeds_hz=None, estimate: bool = True
            ) -> Diagram:
    """The critical depth at each speed (`speeds_hz`, default the cutting's) by the cutting's
    method, with the zero-order estimate beside it (`estimate` False: not computed, nan, when
    the method is semi-discretization)."""
    used, kept = relevant(modes)
    cut = cut_of(cutting)
    speeds = cutting.speeds_hz() if speeds_hz is None else np.asarray(speeds_hz, float)
    stable = small_gain_depth(used, cut)
    ceiling = CEILING_FACTOR * stable
    if estimate or cutting.method == "zoa":
        a0 = mean_force_matrix(cut.teeth, cut.start, cut.exit, cut.kt, cut.kn)
        zoa, zoa_hz = zoa_depths(a0, used, speeds, cut.teeth)
        zoa = np.where(zoa <= ceiling, zoa, np.inf)
        limit = absolute_limit(a0, used)
    else:
        zoa, zoa_hz, limit = np.full(len(speeds), np.nan), np.full(len(speeds), np.nan), math.nan
    if cutting.method == "zoa":
        return Diagram(speeds, zoa, np.where(np.isfinite(zoa), zoa_hz, np.nan),
                       np.where(np.isfinite(zoa), "hopf", ""), zoa, limit, ceiling, kept)
    scout = critical_depths(used, cut, speeds, stable, ceiling, refine=LEVELS[0])
    coarse = critical_depths(used, cut, speeds, stable, ceiling, refine=LEVELS[1],
                             near=scout.depth)
    fine = critical_depths(used, cut, speeds, stable, ceiling, refine=LEVELS[2],
                           near=coarse.depth)
    finite = np.isfinite(fine.depth)
    both = finite & np.isfinite(coarse.depth)
    error = np.zeros(len(speeds))
    error[both] = (np.abs(fine.depth[both] - coarse.depth[both]) / ERROR_DIVISOR
                   / fine.depth[both] * 100)
    kind = np.where(finite, np.where(fine.flip, "flip", "hopf"), "")
    return Diagram(speeds, fine.depth, fine.frequency_hz, kind, zoa, limit, ceiling, kept,
                   coarse.depth, error, fine.intervals, coarse.intervals)


def depths_near(modes: ToolModes, cutting: Cutting, speeds_hz, near,
                refine: int = LEVELS[1]) -> np.ndarray:
    """The critical depths (m; inf: stable up to the ceiling) of `modes` at one level of
    semi-discretization (default the coarse one), bracketed about `near`: a nearby modal
    model's depths at the same speeds and level (a machine's family, e.g. an uncertainty
    band's draws), at about a quarter of a full diagram's cost."""
    used, _ = relevant(modes)
    cut = cut_of(cutting)
    stable = small_gain_depth(used, cut)
    return critical_depths(used, cut, np.asarray(speeds_hz, float), stable,
                           CEILING_FACTOR * stable, refine=refine,
                           near=np.asarray(near, float)).depth


def lobes(modes: ToolModes, cutting: Cutting) -> dict:
    """The diagram's record (results.lobe_records.LobesRecord)."""
    start = time.perf_counter()
    plan(modes, cutting)
    d = diagram(modes, cutting)
    record: dict = {"method": cutting.method}
    if d.error_percent is not None and d.intervals is not None \
            and d.coarse_intervals is not None:
        record.update({
            "intervals": [int(v) for v in d.intervals],
            "coarse_intervals": [int(v) for v in d.coarse_intervals],
            "coarse_depth_mm": mm_list(d.coarse_depth),
            "error_percent": [float(v) for v in d.error_percent],
            "max_error_percent": float(d.error_percent.max(initial=0.0)),
        })
    least, best = d.least, d.best
    record.update({
        "spindle_rpm": [float(v * 60) for v in d.speeds_hz],
        "critical_depth_mm": mm_list(d.depth),
        "chatter_frequency_hz": [float(f) if math.isfinite(f) else None
                                 for f in d.frequency_hz],
        "kind": [str(k) or None for k in d.kind],
        "zoa_depth_mm": mm_list(d.zoa_depth),
        "absolute_limit_mm": finite_mm(d.absolute_limit),
        "ceiling_mm": d.ceiling * 1e3,
        "least": None if least is None else least_entry(d, least),
        "best": {"spindle_rpm": float(d.speeds_hz[best] * 60),
                 "depth_mm": finite_mm(float(d.depth[best]))},
        "cutting": edge_values(cutting),
        "modes": [{"frequency_hz": float(w / (2 * math.pi)), "damping_ratio": float(z),
                   "shape_per_sqrt_kg": {"x": float(u[0]), "y": float(u[1])},
                   "used": bool(j in d.used)}
                  for j, (w, z, u) in enumerate(zip(modes.omega, modes.zeta, modes.shape.T,
                                                    strict=True))],
        "seconds": time.perf_counter() - start,
    })
    return record


def least_entry(d: Diagram, k: int) -> dict:
    """results.lobe_records.LobeLeast of speed k."""
    return {"spindle_rpm": float(d.speeds_hz[k] * 60), "depth_mm": float(d.depth[k] * 1e3),
            "chatter_frequency_hz": float(d.frequency_hz[k]), "kind": str(d.kind[k])}


def mm_list(values) -> list[float | None]:
    return [float(v * 1e3) if math.isfinite(v) else None for v in np.asarray(values, float)]


def finite_mm(value: float) -> float | None:
    return float(value) * 1e3 if math.isfinite(value) else None
