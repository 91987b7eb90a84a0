"""The records of milling stability (issue 52): one pose's stability lobe diagram (lobes.json,
chatter.lobes.lobes) and the cut's least critical depth over the workspace map
(`studies.stability_map`). Units in the field names; null where a speed keeps stable up to the
search's ceiling (or a pose is not reached)."""
from __future__ import annotations

from pydantic import FiniteFloat, with_config
from typing_extensions import NotRequired, TypedDict

from .tool_records import Grid, OutputPose
from .types import STRICT

__all__ = ["CaseLobes", "LobeBand", "LobeBest", "LobeCurve", "LobeLeast", "LobeMode", "LobeSummary",
           "LobesFile", "LobesRecord", "ModalShapeXY", "StabilityLeast", "StabilityMap"]


@with_config(STRICT)
class ModalShapeXY(TypedDict):
    x: FiniteFloat
    y: FiniteFloat


@with_config(STRICT)
class LobeMode(TypedDict):
    """A tool mode in the cut's plane (x along the feed): mass-normalised displacement."""
    frequency_hz: FiniteFloat
    damping_ratio: FiniteFloat
    shape_per_sqrt_kg: ModalShapeXY
    used: bool  # false: it leaves the tool still in the cut's plane (left out)


@with_config(STRICT)
class LobeLeast(TypedDict):
    """The least critical depth over the diagram's speeds, and where."""
    spindle_rpm: FiniteFloat
    depth_mm: FiniteFloat
    chatter_frequency_hz: FiniteFloat
    kind: str  # "hopf" or "flip"


@with_config(STRICT)
class LobeBest(TypedDict):
    """The speed with the largest critical depth (null depth: stable up to the ceiling)."""
    spindle_rpm: FiniteFloat
    depth_mm: FiniteFloat | None


@with_config(STRICT)
class LobesRecord(TypedDict):
    """One pose's stability lobe diagram (chatter.lobes.lobes)."""
    method: str  # "sdm" or "zoa"
    spindle_rpm: list[FiniteFloat]
    critical_depth_mm: list[FiniteFloat | None]  # the least axial depth that chatters
    chatter_frequency_hz: list[FiniteFloat | None]
    kind: list[str | None]  # "hopf" (secondary Hopf) or "flip" (period doubling)
    intervals: NotRequired[list[int]]  # sdm: the cut's intervals a tooth period (fine level)
    coarse_intervals: NotRequired[list[int]]  # sdm: half of them
    coarse_depth_mm: NotRequired[list[FiniteFloat | None]]  # sdm: the depth at half
    error_percent: NotRequired[list[FiniteFloat]]  # sdm: the stated discretisation error
    max_error_percent: NotRequired[FiniteFloat]
    zoa_depth_mm: list[FiniteFloat | None]  # the zero-order estimate at the same speeds
    absolute_limit_mm: FiniteFloat | None  # the zero-order least depth over every speed
    ceiling_mm: FiniteFloat  # the deepest cut searched
    least: LobeLeast | None
    best: LobeBest
    cutting: dict[str, int | FiniteFloat | str | list[FiniteFloat]]  # the [cutting] table
    modes: list[LobeMode]
    seconds: FiniteFloat


@with_config(STRICT)
class LobesFile(LobesRecord):
    record: str
    schema: int
    source: str  # what the modes are: the scene's model at a case, or a tool-modes file
    scene: NotRequired[str]
    case: NotRequired[str]
    pose: NotRequired[OutputPose]
    model: NotRequired[str]  # the model that gave the modes, in words
    warnings: list[str]


@with_config(STRICT)
class LobeCurve(TypedDict):
    """One model's lobes at a case (the scene's speeds and method)."""
    model: str
    critical_depth_mm: list[FiniteFloat | None]
    chatter_frequency_hz: list[FiniteFloat | None]
    kind: list[str | None]
    max_error_percent: FiniteFloat | None  # sdm: the stated discretisation error; zoa: None


@with_config(STRICT)
class LobeSummary(TypedDict):
    """A row of a case's lobes: one model's least depth and best speed."""
    model: str
    least_depth_mm: FiniteFloat | None  # None: stable at every speed up to the ceiling
    least_rpm: FiniteFloat | None
    kind: str | None
    chatter_frequency_hz: FiniteFloat | None
    best_rpm: FiniteFloat
    best_depth_mm: FiniteFloat | None
    error_percent: FiniteFloat | None  # the least depth against the FEM's (the FEM: None)
    fem_error_percent: FiniteFloat | None  # the FEM's: two meshes; the models': None


@with_config(STRICT)
class LobeBand(TypedDict):
    """The critical depth's spread over the scene's [uncertainty] at a case (`studies.lobes`):
    plain scrambled Sobol' draws of the inputs, every draw's machine through the model at the
    case's pose and through the same cut; empirical quantiles (no interpolation: a draw's own
    depth; null where a draw stays stable up to the ceiling)."""
    samples: int
    model: str  # the model the draws went through (solvers.uncertainty.run_model)
    inputs: list[str]  # the uncertain keys (the cutting coefficients and damping: as declared)
    spindle_rpm: list[FiniteFloat]  # the band's speeds (the case's range, thinned)
    nominal_depth_mm: list[FiniteFloat | None]  # the scene's own machine, same model and speeds
    q025_depth_mm: list[FiniteFloat | None]
    median_depth_mm: list[FiniteFloat | None]
    q975_depth_mm: list[FiniteFloat | None]
    least_nominal_mm: FiniteFloat | None  # the least depth over the speeds, the scene's machine
    least_q025_mm: FiniteFloat | None  # ... its 2.5 % quantile over the draws
    least_q025_interval_mm: list[FiniteFloat | None]  # that quantile's distribution-free 95 %
    # interval: two order statistics of the draws (null: no draw bounds it on that side)
    least_median_mm: FiniteFloat | None
    least_q975_mm: FiniteFloat | None
    level_error_percent: FiniteFloat | None  # sdm: the draws' level of intervals (the coarse
    # one) against the fine level, on the scene's machine: the largest over the speeds
    refused: str | None  # why the band was not drawn (its budget, a draw out of reach)
    seconds: FiniteFloat


@with_config(STRICT)
class CaseLobes(TypedDict):
    """A case's stability lobes: the analytical model's and the FEM's tool modes through the
    same cut (`studies.lobes`), the FEM at the run's mesh and one size coarser."""
    method: str
    spindle_rpm: list[FiniteFloat]
    analytical: LobeCurve
    fem: LobeCurve
    fem_coarse: LobeCurve
    fem_mesh_size_mm: FiniteFloat
    coarse_mesh_size_mm: FiniteFloat
    error_percent: list[FiniteFloat | None]  # analytical against the FEM, per speed
    fem_error_percent: list[FiniteFloat | None]  # the FEM's two-mesh estimate, per speed
    median_error_percent: FiniteFloat | None
    max_error_percent: FiniteFloat | None
    summary: list[LobeSummary]
    band: LobeBand | None  # scenes with [uncertainty] (None: none)
    seconds: FiniteFloat


@with_config(STRICT)
class StabilityLeast(TypedDict):
    """The least critical depth over the map and the speeds, and where."""
    depth_mm: FiniteFloat
    spindle_rpm: FiniteFloat
    chatter_frequency_hz: FiniteFloat
    kind: str
    height_mm: FiniteFloat
    tilt_deg: FiniteFloat
    azimuth_deg: FiniteFloat


@with_config(STRICT)
class StabilityMap(TypedDict):
    """The cut's stability over the workspace map (`studies.stability_map`): per reachable
    pose the least critical depth over the speeds, the speed it occurs at, the best speed
    (largest depth) and the chatter frequency at the least; null where a pose is not reached
    or stays stable up to the ceiling."""
    point_mm: list[FiniteFloat]
    method: str
    analytical: str
    damping: str
    speeds: int
    spindle_rpm_range: list[FiniteFloat]  # the speeds' lowest and highest
    heights_mm: list[FiniteFloat]
    tilts_deg: list[list[FiniteFloat]]  # [layer][ring]
    azimuths_deg: list[FiniteFloat]
    least_depth_mm: Grid
    least_rpm: Grid
    best_rpm: Grid
    best_depth_mm: Grid
    chatter_frequency_hz: Grid
    max_error_percent: FiniteFloat | None  # sdm: the largest stated error over the map
    least: list[StabilityLeast]  # one row: the least over the map (empty: none)
    poses: int
    estimated_seconds: FiniteFloat
    seconds: FiniteFloat
