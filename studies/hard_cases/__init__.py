"""Hard cases of the analytical model: physics and numerics claims, each with its tolerance,
measured (issue 12: "test numerical stability on hard cases").

Every claim is a function of a scene returning a `Row` (case, claim, tolerance, measured);
`evaluate(scene)` runs the ones that take seconds, for the report's "Hard cases" section.
tests/test_hard.py (marker `hard`) asserts every one of them on the paper's machine, and adds
the FEM's hard cases (repeated pairs over mesh sizes, residuals, retried eigen solves).
The machines are the scene's, changed with dataclasses.replace (slender or stocky legs, a thin
plate, other metals, turned layouts, lower joint limits).
"""
from __future__ import annotations

import math
from typing import Callable, cast

import results
from common.errors import ComputeError, RpsError
from common.settings import as_dict
from runtime.cache import ResultCache
from scene import Scene

from ..registry import OWN_TEMPLATE, Context, Section, Study, own
from .base import SEED, Row, random_rotation, turned, untestable  # noqa: F401
from .geometry import *  # noqa: F401,F403
from .geometry import aluminium_scaling, slender_legs, stocky_legs, thin_plate, titanium_scaling
from .limits import *  # noqa: F401,F403
from .limits import LIMITS, boundary_ring, joint_limit
from .paths import *  # noqa: F401,F403
from .paths import continuity, near_crossing
from .spectra import *  # noqa: F401,F403
from .spectra import (
    eigen_residuals,
    mode_count,
    no_spurious_zero_mode,
    repeated_pairs,
    turned_layout,
)

CHEAP = (repeated_pairs, turned_layout, eigen_residuals, mode_count, no_spurious_zero_mode,
         continuity, near_crossing, slender_legs, stocky_legs, thin_plate, aluminium_scaling,
         titanium_scaling, boundary_ring)


def _row(task) -> results.HardCase:
    """One claim's row. A claim whose own computation is refused (an eigen solve of the
    machine's highest modes less accurate than modal.RESIDUAL_LIMIT, a pose it cannot reach)
    has not held: it is a failed row that says why, never the end of the run."""
    claim, scene, argument = task
    try:
        row = claim(scene) if argument is None else claim(scene, argument)
    except RpsError as exc:
        name = claim.__name__.replace("_", " ") + ("" if argument is None else f" ({argument})")
        row = Row(name, "the claim could be evaluated on this machine", 0.0, 1.0,
                  "evaluations that failed", note=" ".join(str(exc).split()))
    return row.record()


def evaluate(scene: Scene, workers: int = 1) -> list[results.HardCase]:
    """The analytical hard cases of `scene` (about ten seconds of one core): rows for the
    report, in the order of CHEAP then LIMITS, the claims spread over `workers` processes."""
    from runtime.sweep import map_tasks

    tasks: list[tuple[Callable[..., Row], Scene, str | None]] = [
        (claim, scene, None) for claim in CHEAP]
    tasks += [(joint_limit, scene, limit) for limit in LIMITS]
    rows = map_tasks(_row, tasks, workers)
    for (claim, _, argument), row in zip(tasks, rows):
        if "error" in row and "claim" not in row:
            raise ComputeError(f"hard case {claim.__name__}"
                               f"{'' if argument is None else f' ({argument})'}: {row['error']}")
    return [cast(results.HardCase, row) for row in rows]  # _row's records: none failed


def hard_case_rows(scene: Scene, cache: ResultCache,
                   workers: int = 1) -> list[results.HardCase]:
    """The analytical hard cases of the scene's machine, cases and chosen setting
    (`evaluate`), through the result cache: recomputed when any of them or the
    code changes."""
    payload = {"manipulator": as_dict(scene.manipulator), "analytical": as_dict(scene.analytical),
               "poses": [as_dict(c.pose) for c in scene.cases.values()]}
    value, _, _ = cache.get_or_compute(
        "hard-cases", payload, lambda: ({"rows": evaluate(scene, workers)}, {}),
        required=("rows",), modules=("studies.hard_cases",))
    return value["rows"]


def run(ctx: Context) -> list[results.HardCase]:
    return hard_case_rows(ctx.scene, ctx.cache, ctx.workers)


STUDY = Study(own("hard_cases", "scene", section=Section(
    "hard-cases", "Hard cases: numerical stability and physics checks", "hard cases",
    OWN_TEMPLATE), tables=(results.Table(
        "claims", ("case", "claim", "measured", "tolerance", "unit", "passed", "note")),)),
    "scene", run)
