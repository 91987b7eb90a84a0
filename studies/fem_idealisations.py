"""Case study: the FEM's own idealisations against its default (an elastic plate, distributing
joint faces, tetrahedral legs), each paired by shape with the default FEM
(results.cases[].fem_variants; a variant that cannot be solved is named with its reason)."""
from __future__ import annotations

import results
from solvers.compare import error_table, fem_case

from .registry import CaseContext, Context, Study

FEM_VARIANTS = {"elastic platform": {"platform": "elastic", "legs": "tetrahedra"},
                "distributing coupling": {"coupling": "distributing"},
                "tetrahedral legs": {"legs": "tetrahedra"}}


def run(ctx: Context, cc: CaseContext) -> dict:
    scene, count = ctx.scene, ctx.scene.analytical.modes
    cc.step("FEM joint and platform idealisations")
    variants, errors = {}, {}
    for label, kwargs in FEM_VARIANTS.items():
        try:
            v = fem_case(scene, cc.geometry, ctx.cache, scene.fem.mesh_size, **kwargs)
        except (ValueError, RuntimeError) as exc:
            errors[label] = " ".join(str(exc).split())
            continue
        # paired by shape with the default FEM: an elastic plate adds modes of its own
        shifted = error_table(v, cc.fem, count)
        variants[label] = results.FemVariant(
            **v.reported(count), pairs=shifted,
            shift_percent=[r["error_percent"] for r in shifted])
    return {"fem_variants": variants, "fem_variant_errors": errors}


STUDY = Study("fem_variants", "FEM idealisations", None, "case", run)
