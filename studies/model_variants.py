"""Case study: every compared analytical setting (the paper's and ours) against the case's FEM,
with its time per pose (results.cases[].models)."""
from __future__ import annotations

import results
from solvers.compare import analytical_case, error_table
from solvers.settings import model_variants
from solvers.timing import seconds_per_pose

from .registry import CaseContext, Context, Study, own


def run(ctx: Context, cc: CaseContext) -> results.ModelVariants:
    scene, count = ctx.scene, ctx.scene.analytical.modes
    cc.step("model variants")
    models: results.ModelVariants = {}
    for label, opts in model_variants(scene).items():
        a = analytical_case(scene, cc.case, opts)
        models[label] = results.ModelVariant(
            **a.reported(count), median_seconds=seconds_per_pose(scene, cc.case, opts, ctx.cache),
            pairs=error_table(a, cc.fem, count, cc.fem_error, cc.reference))
    return models


STUDY = Study(own("models", "case"), "case", run)
