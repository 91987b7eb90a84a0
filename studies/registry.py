"""What a study is, and what it is given: the one shape every study of a run has.

A study is a function from a `Context` (the scene at the chosen fidelity, the result cache, the
workers) to its record, declared as a `Study` beside it: its stage and profiles here, its record
(key, type, report section, CSV tables) as a `results.Record`. The run calls every registered
study of its profile and stores the record, checked against its type as soon as it is returned,
under `results.studies[key]` (a scene study) or in each case (a case study, which also gets the
case's FEM solves: `CaseContext`); the results stub, the report's sections and the tables are
made from the same declarations.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, get_origin

from analytical.kinematics import PoseGeometry
from common.errors import InputError
from results import Record, Refinement, Section, study_type
from results.declare import Scope
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
    refinement: Refinement | None
    step: Callable[[str], None] = lambda text: None


@dataclass(frozen=True)
class Study:
    """A study of a run, declared once: at `stage`, in `profiles`, its `record` goes under
    `record.key` (results.studies[key], or each case's [key] for a case study) and the report
    shows it in `record.section`. `run` computes the record: (Context) for a scene study,
    (Context, CaseContext) for a case study. The "check" and "fidelity" stages are the run's
    own steps (the up-front workspace check, the fidelity choice), which call their modules
    directly; their declarations here give the record its key, its type and its section.
    `prefetch(ctx, geometries)`, when given, fills the result cache for every case on the
    workers before the cases are run one by one."""

    record: Record
    stage: str
    run: Callable[..., Any] | None
    profiles: tuple[str, ...] = ("full",)
    prefetch: Callable[[Context, list], None] | None = None

    def __post_init__(self):
        if self.stage not in STAGES:
            raise InputError(f"study {self.key}: stage {self.stage!r} is not one of {STAGES}")
        if (self.record.scope == "case") != (self.stage == "case"):
            raise InputError(f"study {self.key}: a {self.stage}-stage study has a "
                             f"{'case' if self.stage == 'case' else 'scene'} record")
        if (self.run is None) != (self.stage in ("check", "fidelity")):
            raise InputError(f"study {self.key}: the run calls `run` at the case and scene "
                             "stages, and only there")

    @property
    def key(self) -> str:
        return self.record.key

    def compute(self, ctx: Context, *case: CaseContext) -> Any:
        """The study's record, computed (`run`) and checked against its declared type as soon
        as it returns, so a wrong record is refused before the run's next expensive step."""
        if self.run is None:
            raise InputError(f"study {self.key}: the {self.stage} stage's record is the run's "
                             "own step")
        where = "results" if not case else f"case {case[0].case.name}"
        return self.record.checked(self.run(ctx, *case), where)


def own(key: str, scope: Scope, **declared: Any) -> Record:
    """The record of one of the project's own studies, its type as `results` types it (a
    list's empty value []; anything else's None)."""
    kind = study_type(scope, key)
    return Record(key, scope, kind, [] if get_origin(kind) is list else None, **declared)


def floats(values) -> list[float]:
    """Plain floats for a record (numpy scalars are not JSON)."""
    return [float(v) for v in values]


# drawn by a block of the report's own template (reports/templates/report.html.j2), which knows
# the record; a study without one (Section.template None) is drawn as its declared tables
OWN_TEMPLATE = "report.html.j2"
PAPER_READING = Section("studies", "Reading the paper: angle conventions and height calibration",
                        None, OWN_TEMPLATE)
