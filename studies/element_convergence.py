"""Case study: frequencies against the elements per leg, s = 1..10, per beam theory (the paper's
Fig. 3; results.cases[].element_convergence)."""
from __future__ import annotations

from dataclasses import replace

import results
from analytical.model import natural_frequencies
from scene import Case, Scene

from .registry import OWN_TEMPLATE, CaseContext, Context, Section, Study, floats, own

ELEMENT_RANGE = tuple(range(1, 11))


def element_convergence(scene: Scene, case: Case,
                        beam: str = "euler-bernoulli") -> results.ElementConvergence:
    """Frequencies for s = 1..10 elements per leg, for one beam theory."""
    rows = []
    for s in ELEMENT_RANGE:
        opts = replace(scene.analytical, elements=s, beam=beam)
        rows.append(floats(natural_frequencies(scene.manipulator, case.pose, opts)))
    return results.ElementConvergence(elements=list(ELEMENT_RANGE), beam=beam,
                                      frequencies_hz=rows)


def run(ctx: Context, cc: CaseContext) -> results.ElementConvergences:
    cc.step("element convergence")
    return {beam: element_convergence(ctx.scene, cc.case, beam)
            for beam in ("euler-bernoulli", "timoshenko")}


STUDY = Study(own("element_convergence", "case", section=Section(
    "convergence", "Convergence", "convergence studies", OWN_TEMPLATE)), "case", run)
