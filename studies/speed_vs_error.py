"""Case study: wall time per pose against the worst |error| of the compared modes, for every
analytical setting (beam theories at s = 1..10, solid end zones) and every FEM size of the
refinement study (results.cases[].speed_vs_error; medians over repeated runs: `make bench`)."""
from __future__ import annotations

import numpy as np

import results as schema
from runtime.cache import ResultCache
from scene import Case, Scene
from solvers.compare import Solve, analytical_case, error_table
from solvers.settings import speed_settings
from solvers.timing import seconds_per_pose

from .registry import OWN_TEMPLATE, CaseContext, Context, Section, Study, own


def speed_vs_error(scene: Scene, case: Case, fem: Solve, reference, refinement,
                   cache: ResultCache | None = None) -> list[schema.SpeedPoint]:
    """Wall time per pose against the worst |error| of f1..f6, for every setting (times
    through the cache: `timing.seconds_per_pose`)."""
    count = scene.analytical.modes
    ref = np.asarray(reference if reference is not None else fem.record["frequencies_hz"][:count])
    out = []
    for label, opts in speed_settings(scene).items():
        rows = error_table(analytical_case(scene, case, opts), fem, count, None, ref)
        out.append(schema.SpeedPoint(
            model="analytical", setting=label, seconds=seconds_per_pose(scene, case, opts, cache),
            worst_error_percent=max(abs(schema.best_error(r)) for r in rows),
            single_run=False, mesh_from_cache=None))
    if refinement:
        for size, secs, err, cached in zip(refinement["mesh_sizes_mm"], refinement["seconds"],
                                           refinement["estimated_error_percent_max"],
                                           refinement["mesh_cache_hit"]):
            # one run, as computed when the result cache was filled (medians: make bench)
            out.append(schema.SpeedPoint(
                model="fem", setting=f"h = {size:g} mm", seconds=secs,
                worst_error_percent=err, single_run=True, mesh_from_cache=cached))
    return out


def run(ctx: Context, cc: CaseContext) -> list[schema.SpeedPoint]:
    cc.step("speed vs error")
    return speed_vs_error(ctx.scene, cc.case, cc.fem, cc.reference, cc.refinement, ctx.cache)


STUDY = Study(own("speed_vs_error", "case", section=Section(
    "speed", "Speed vs error", "speed vs error", OWN_TEMPLATE), tables=(schema.Table(
        "points", ("model", "setting", "seconds", "worst_error_percent", "single_run")),)),
    "case", run)
