"""What a study is, and what it is given: the one shape every study of a run has.

A study is a function from a `Context` (the scene at the chosen fidelity, the result cache, the
workers) to its records in the results schema, declared as a `Study` beside it. The run calls
every registered study of its profile and stores the record under `results.studies[key]` (a
scene study) or in each case (a case study, which also gets the case's FEM solves:
`CaseContext`); the report titles its sections from the same declarations.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

from analytical.kinematics import PoseGeometry
from common.errors import InputError
from results.sections import SECTIONS
from runtime.cache import ResultCache
from scene import Case, Scene
from solvers.compare import Solve

# When a study runs in a validation: "check" (the up-front workspace check, before any
# expensive work), "fidelity" (inside the fidelity step, whose choice it informs), "case" (once
# per case, after the case's FEM), "scene" (once, after every case).
STAGES = ("check", "fidelity", "case", "scene")


@dataclass(frozen=True)
class Context:
    """What every study receives."""

    scene: Scene  # at the chosen fidelity (analytical options, FEM size)
    cache: ResultCache
    workers: int = 1
    scheduler: str | None = None
    chosen_setting: str | None = None  # the fidelity step's chosen analytical label


@dataclass(frozen=True)
class CaseContext:
    """What a case study receives besides the `Context`: the case and its FEM at the run's
    size, with the refinement study's limit and estimated error when the run refines."""

    case: Case
    geometry: PoseGeometry
    fem: Solve
    fem_error: Any  # (modes,) estimated error of `fem`, %, or None
    reference: Any  # (modes,) the FEM limit, Hz, or None
    refinement: dict | None  # results.Refinement
    step: Callable[[str], None] = lambda text: None


@dataclass(frozen=True)
class Study:
    """A study of a run, declared once: at `stage`, in `profiles`, its record goes under `key`
    (results.studies[key], or each case's [key] for a case study) and the report shows it in
    the section `results.sections.SECTIONS[key]` names. `run` computes it: (Context) for a
    scene study, (Context, CaseContext) for a case study. The "check" and "fidelity" stages are
    the run's own steps (the up-front workspace check, the fidelity choice), which call their
    modules directly; their declarations here give the record its key and its section.
    `prefetch(ctx, geometries)`, when given, fills the result cache for every case on the
    workers before the cases are run one by one."""

    key: str
    stage: str
    run: Callable[..., Any] | None
    profiles: tuple[str, ...] = ("full",)
    prefetch: Callable[[Context, list], None] | None = None

    def __post_init__(self):
        if self.stage not in STAGES:
            raise InputError(f"study {self.key}: stage {self.stage!r} is not one of {STAGES}")
        if self.key not in SECTIONS:
            raise InputError(f"study {self.key}: no section in results.sections.SECTIONS")
        if (self.run is None) != (self.stage in ("check", "fidelity")):
            raise InputError(f"study {self.key}: the run calls `run` at the case and scene "
                             "stages, and only there")


def floats(values) -> list[float]:
    """Plain floats for a record (numpy scalars are not JSON)."""
    return [float(v) for v in values]
