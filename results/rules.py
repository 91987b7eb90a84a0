"""Reading rules shared by the run, the terminal summary and the report: the error a pair is
judged by, and the paper's two mode ranges."""
from __future__ import annotations

from typing import Callable, Iterable

from .case_records import Pair
from .types import LOW_MODES


def best_error(pair: Pair) -> float:
    """A pair's error against the best FEM value there is: the h -> 0 limit when the run has
    one, else the FEM at the compared mesh."""
    vs_limit = pair["error_vs_reference_percent"]
    return pair["error_percent"] if vs_limit is None else vs_limit


def worst_in_mode_ranges(errors: Iterable[tuple[int, float]]
                         ) -> tuple[float | None, float | None]:
    """Worst |error| of modes 1..LOW_MODES and of the modes above, from (1-based mode, error)
    items (None where a range has none): the paper's way of reading its errors."""
    low: list[float] = []
    high: list[float] = []
    for mode, value in errors:
        (low if mode <= LOW_MODES else high).append(abs(value))
    return (max(low) if low else None), (max(high) if high else None)


def worst_by_mode_range(pairs: list[Pair], error: Callable[[Pair], float] = best_error
                        ) -> tuple[float | None, float | None]:
    """worst_in_mode_ranges of the pairs, by FEM mode."""
    return worst_in_mode_ranges((p["fem_mode"], error(p)) for p in pairs)


def mode_ranges(pairs: list[Pair]) -> tuple[str, str]:
    """Labels of the two ranges, e.g. ("f1–f3", "f4–f6")."""
    top = max((p["fem_mode"] for p in pairs), default=LOW_MODES + 1)
    return f"f1–f{LOW_MODES}", (f"f{LOW_MODES + 1}–f{top}" if top > LOW_MODES + 1
                                else f"f{LOW_MODES + 1}")
