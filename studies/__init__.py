"""The studies of a validation run, one module each, registered once (README.md).

    from studies import STUDIES, Context
    for study in STUDIES: ...            # key, title, anchor, stage, run, profiles

A study is a function of a `Context` (and, for a case study, a `CaseContext`) returning its
records in the results schema. The run calls the registered studies of its profile at their
stage; the report titles its sections from the same list. Adding a study is one module with a
`STUDY` declaration and one line below.
"""
from __future__ import annotations

from . import (
    calibration,
    conventions,
    couplings,
    element_convergence,
    fem_idealisations,
    fem_verification,
    hard_cases,
    joint_orders,
    lowest_modes,
    model_variants,
    reachable,
    speed_vs_error,
    workspace_map,
    workspace_validation,
)
from .registry import STAGES, CaseContext, Context, Study

STUDIES: tuple[Study, ...] = (
    reachable.STUDY,
    workspace_validation.STUDY,
    model_variants.STUDY,
    element_convergence.STUDY,
    fem_idealisations.STUDY,
    speed_vs_error.STUDY,
    calibration.STUDY,
    conventions.STUDY,
    workspace_map.STUDY,
    joint_orders.STUDY,
    couplings.STUDY,
    hard_cases.STUDY,
    lowest_modes.STUDY,
    fem_verification.STUDY,
)


def at(stage: str, profile: str) -> tuple[Study, ...]:
    """The registered studies that run at `stage` in `profile`, in registration order."""
    return tuple(s for s in STUDIES if s.stage == stage and profile in s.profiles)


__all__ = ["STAGES", "STUDIES", "CaseContext", "Context", "Study", "at"]
