"""Model only what a scene needs: the cheapest models that meet the scene's tolerance.

The scene says how many modes it compares and the largest error it accepts on each of them
(`[fidelity]`). From measurements of this run, never from a fixed rule:
- the FEM size is the cheapest of the refinement sequence whose estimated discretisation error
  is at most FEM_ERROR_SHARE of the tolerance on every compared mode of every case (so the
  reference's own error cannot eat the tolerance);
- the analytical setting is the one with the least measured time per pose among those whose
  worst |error| against the FEM limit, over every case, is within the tolerance.
When nothing meets it, the most accurate candidate is taken and `met` is false: the run says so
and the verdict claims no agreement. Explicit `[analytical]` / `[fem] mesh_size_mm` in a scene
override the choice (and are still checked against the tolerance).
"""
from __future__ import annotations

from dataclasses import dataclass

from typing_extensions import TypedDict

from common.errors import InputError

FEM_ERROR_SHARE = 0.2  # the reference may use a fifth of the tolerance
TIE = 0.10  # measured times within 10 % are a tie, broken by the smaller error


@dataclass(frozen=True)
class FemChoice:
    size: float  # m
    worst_error_percent: float | None  # estimated, over cases and compared modes
    met: bool
    reason: str


@dataclass(frozen=True)
class AnalyticalChoice:
    setting: str  # label of the candidate
    worst_error_percent: float
    seconds_per_pose: float
    met: bool
    reason: str


def choose_fem_size(sizes, errors_by_case, tolerance_percent: float) -> FemChoice:
    """sizes (m, coarse -> fine); errors_by_case[c][k][mode] estimated error (%) of size k.

    The coarsest size whose worst estimated error over every case and mode is at most
    FEM_ERROR_SHARE * tolerance; else the finest, not met.
    """
    budget = FEM_ERROR_SHARE * tolerance_percent
    worst = [max(max(case[k]) for case in errors_by_case) for k in range(len(sizes))]
    for size, w in sorted(zip(sizes, worst), key=lambda sw: -sw[0]):
        if w <= budget:
            return FemChoice(size, w, True,
                             f"h = {size * 1e3:.3g} mm is the coarsest mesh of the sequence "
                             f"whose estimated error ({w:.3g} %) is within a fifth of the "
                             f"tolerance ({budget:.3g} %)")
    k = min(range(len(sizes)), key=lambda i: sizes[i])
    return FemChoice(sizes[k], worst[k], False,
                     f"even the finest mesh of the sequence, h = {sizes[k] * 1e3:.3g} mm, has "
                     f"an estimated error of {worst[k]:.3g} %, above a fifth of the tolerance "
                     f"({budget:.3g} %): refine the sequence or raise the tolerance")


class Where(TypedDict):
    """A candidate's largest error over the compared modes at one case or study pose, %."""
    case: str
    worst_error_percent: float


class Measured(Where):
    """... with its time per pose there, s."""
    seconds: float


Rows = dict[str, list[Measured]]  # candidate label -> one row per case (and study pose)
Places = dict[str, list[Where]]  # candidate label -> its errors at study poses


def choose_analytical(candidates: Rows, tolerance_percent: float) -> AnalyticalChoice:
    """candidates[label] = one row per case: {"seconds", "worst_error_percent"}.

    The least measured time per pose (median over cases) among the candidates whose worst
    error over every case is within the tolerance; else the most accurate, not met.
    """
    rows = []
    for label, per_case in candidates.items():
        worst = max(r["worst_error_percent"] for r in per_case)
        seconds = sorted(r["seconds"] for r in per_case)[len(per_case) // 2]
        rows.append((label, worst, seconds))
    if not rows:
        raise InputError("no analytical candidate was evaluated")
    meeting = [r for r in rows if r[1] <= tolerance_percent]
    if meeting:
        fastest = min(r[2] for r in meeting)
        tied = [r for r in meeting if r[2] <= (1 + TIE) * fastest]
        label, worst, seconds = min(tied, key=lambda r: r[1])
        return AnalyticalChoice(label, worst, seconds, True,
                                f"{label} is the fastest setting measured ({seconds * 1e3:.2g} "
                                f"ms a pose) whose worst error over every case and study pose "
                                f"({worst:.2f} %) is within the tolerance "
                                f"({tolerance_percent:g} %)")
    label, worst, seconds = min(rows, key=lambda r: r[1])
    return AnalyticalChoice(label, worst, seconds, False,
                            f"no analytical setting meets the tolerance ({tolerance_percent:g} "
                            f"%); the most accurate, {label}, is off by up to {worst:.2f} %")
