"""Case study: the FEM's own idealisations against its default (an elastic plate, distributing
joint faces, tetrahedral legs), each paired by shape with the default FEM and with its own
two-mesh error (results.cases[].fem_variants; a variant that cannot be solved is named with
its reason)."""
from __future__ import annotations

from dataclasses import replace
from typing import Any

import results
from solvers.compare import error_table
from solvers.refinement import coarse_size, prefetch_fem, two_mesh

from .registry import CaseContext, Context, Study, own

# An idealisation is a side study: its solve gets a budget. Estimated raw dofs of the shipped
# scenes' variants at their refinement sizes: tetrahedral legs 11-235k, the elastic plate
# 14-517k (slender's finest, 6 mm); at the sizes the runs choose, at most about 100k (seconds to
# a minute: slender's plate at 9.6 mm, 11 s and 1.3 GB). A random machine's 41 mm plate on
# 19 mm legs at 7.6 mm is 374k, and two such solves side by side took ~10 GB each for more than
# ten minutes. Above the budget a variant is reported as not solved, with the estimate.
MAX_DOFS = 200_000

FEM_VARIANTS: dict[str, dict[str, Any]] = {
    "elastic platform": {"platform": "elastic", "legs": "tetrahedra"},
    "distributing coupling": {"coupling": "distributing"},
    "tetrahedral legs": {"legs": "tetrahedra"}}


def run(ctx: Context, cc: CaseContext) -> results.FemIdealisations:
    scene, count = ctx.scene, ctx.scene.analytical.modes
    cc.step("FEM joint and platform idealisations")
    variants: dict[str, results.FemVariant] = {}
    errors: dict[str, str] = {}
    for label, kwargs in FEM_VARIANTS.items():
        try:
            both = two_mesh(scene, cc.geometry, ctx.cache, scene.fem.mesh_size, count,
                            **kwargs, max_dofs=MAX_DOFS)
        except (ValueError, RuntimeError) as exc:
            errors[label] = " ".join(str(exc).split())
            if f"above max_dofs = {MAX_DOFS}" in errors[label]:
                errors[label] += " (the budget of this side study: not solved)"
            continue
        # paired by shape with the default FEM: an elastic plate adds modes of its own
        shifted = error_table(both.fine, cc.fem, count)
        variants[label] = results.FemVariant(
            **both.fine.reported(count), pairs=shifted,
            shift_percent=[r["error_percent"] for r in shifted],
            estimated_error_percent=both.estimated_error_percent,
            gci_percent=both.gci_percent)
    return results.FemIdealisations(variants=variants, unsolved=errors)


def prefetch(ctx: Context, geometries: list) -> None:
    """Every case's idealisations solved on the workers, before the cases read them."""
    scene = ctx.scene
    for idealisation in FEM_VARIANTS.values():
        prefetch_fem(replace(scene, fem=replace(scene.fem, **idealisation)), geometries,
                     (scene.fem.mesh_size, coarse_size(scene, scene.fem.mesh_size)), ctx.cache,
                     ctx.workers, ctx.scheduler, max_dofs=MAX_DOFS)


STUDY = Study(own("fem_variants", "case"), "case", run, prefetch=prefetch)
