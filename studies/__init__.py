"""The studies of a validation run, one module each, registered once (README.md).

    from studies import STUDIES, RECORDS, Context
    for study in STUDIES: ...            # record (key, type, section, tables), stage, run

A study is a function of a `Context` (and, for a case study, a `CaseContext`) returning its
record, of the type its `results.Record` declares. The run calls the registered studies of its
profile at their stage; the results stub, the report's sections and the CSV tables come from
the same list (`RECORDS`). Adding a study is one module with a `STUDY` declaration and one line
below.
"""
from __future__ import annotations

from results import Record, unique

from . import (
    calibration,
    conventions,
    couplings,
    dynamic_stiffness,
    element_convergence,
    fem_idealisations,
    fem_verification,
    hard_cases,
    joint_orders,
    lobes,
    lowest_modes,
    model_variants,
    reachable,
    speed_vs_error,
    stability_map,
    tool_response,
    uncertainty,
    uncertainty_path,
    workspace_map,
    workspace_validation,
)
from .registry import STAGES, CaseContext, Context, Study

# registration order is the report's order of their sections (and the run's, within a stage)
STUDIES: tuple[Study, ...] = (
    reachable.STUDY,
    model_variants.STUDY,
    element_convergence.STUDY,
    fem_idealisations.STUDY,
    speed_vs_error.STUDY,
    tool_response.STUDY,
    lobes.STUDY,
    uncertainty.STUDY,
    workspace_map.STUDY,
    dynamic_stiffness.STUDY,
    stability_map.STUDY,
    uncertainty_path.STUDY,
    workspace_validation.STUDY,
    lowest_modes.STUDY,
    joint_orders.STUDY,
    couplings.STUDY,
    hard_cases.STUDY,
    fem_verification.STUDY,
    calibration.STUDY,
    conventions.STUDY,
)
RECORDS: tuple[Record, ...] = unique(s.record for s in STUDIES)  # what a results file holds


def at(stage: str, profile: str) -> tuple[Study, ...]:
    """The registered studies that run at `stage` in `profile`, in registration order."""
    return tuple(s for s in STUDIES if s.stage == stage and profile in s.profiles)


__all__ = ["RECORDS", "STAGES", "STUDIES", "CaseContext", "Context", "Study", "at"]
