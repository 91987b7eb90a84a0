"""The records of milling stability (issue 52): one pose's stability lobe diagram (lobes.json,
chatter.lobes.lobes) and the cut's least critical depth over the workspace map
(`studies.stability_map`). Units in the field names; null where a speed keeps stable up to the
search's ceiling (or a pose is not reached)."""
from __future__ import annotations

from pydantic import FiniteFloat, with_config
from typing_extensions import NotRequired, TypedDict

from .tool_records import OutputPose
from .types import STRICT

__all__ = ["LobeBest", "LobeLeast", "LobeMode", "LobesFile", "LobesRecord", "ModalShapeXY"]


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
