"""The records of the dynamic compliance at the tool (issue 38): a case's tool response
against the solid's direct frequency response (`cases[].tool_response`,
studies/tool_response.py) and the least dynamic stiffness over the workspace map
(`studies.dynamic_stiffness`, studies/dynamic_stiffness.py). Units in the field names; None
in a grid where a pose is not reached (or nothing moves the tool that way)."""
from __future__ import annotations

from pydantic import FiniteFloat, with_config
from typing_extensions import TypedDict  # pydantic reads it on Python < 3.12

from .types import STRICT

__all__ = ["DynamicStiffnessMap", "LeastPose", "ToolCurves", "ToolPeak", "ToolResponse",
           "ToolStatic", "ToolUnmatched"]


@with_config(STRICT)
class ToolStatic(TypedDict):
    direction: str
    fem_m_per_n: FiniteFloat
    fem_error_percent: FiniteFloat  # two-mesh (the larger of Richardson's step and the GCI)
    analytical_m_per_n: FiniteFloat
    error_percent: FiniteFloat  # analytical against the FEM


@with_config(STRICT)
class ToolPeak(TypedDict):
    direction: str
    fem_mode: int  # 1-based, the mode (of a repeated group: the one standing out) it is near
    fem_direct_hz: FiniteFloat
    fem_direct_m_per_n: FiniteFloat
    fem_frequency_error_percent: FiniteFloat | None  # the run's estimate for the mode
    fem_magnitude_error_percent: FiniteFloat  # two-mesh, of the FEM's modal sum
    fem_modal_hz: FiniteFloat
    fem_modal_m_per_n: FiniteFloat
    fem_modal_magnitude_error_percent: FiniteFloat  # FEM modal sum against its direct response
    analytical_hz: FiniteFloat
    analytical_m_per_n: FiniteFloat
    frequency_error_percent: FiniteFloat  # analytical against the direct response
    magnitude_error_percent: FiniteFloat


@with_config(STRICT)
class ToolUnmatched(TypedDict):
    direction: str
    reason: str


@with_config(STRICT)
class ToolCurves(TypedDict):
    frequency_hz: list[FiniteFloat]
    analytical_m_per_n: dict[str, list[FiniteFloat]]  # |H_dd|, d = x, y, z
    fem_m_per_n: dict[str, list[FiniteFloat]]


@with_config(STRICT)
class ToolResponse(TypedDict):
    point_mm: list[FiniteFloat]
    damping: str
    check_damping: str
    analytical: str
    fem_mesh_size_mm: FiniteFloat
    coarse_mesh_size_mm: FiniteFloat
    static: list[ToolStatic]
    peaks: list[ToolPeak]
    unmatched: list[ToolUnmatched]
    curves: ToolCurves
    seconds: FiniteFloat


@with_config(STRICT)
class LeastPose(TypedDict):
    direction: str
    stiffness_n_per_m: FiniteFloat
    frequency_hz: FiniteFloat
    mode: int
    height_mm: FiniteFloat
    tilt_deg: FiniteFloat
    azimuth_deg: FiniteFloat


Grid = list[list[list[FiniteFloat | None]]]  # [layer][ring][azimuth]


@with_config(STRICT)
class DynamicStiffnessMap(TypedDict):
    point_mm: list[FiniteFloat]
    damping: str
    analytical: str
    lines: int
    modes_summed: int
    heights_mm: list[FiniteFloat]
    tilts_deg: list[list[FiniteFloat]]  # [layer][ring]
    azimuths_deg: list[FiniteFloat]
    stiffness_n_per_m: dict[str, Grid]  # per direction x, y, z
    peak_hz: dict[str, Grid]
    mode: dict[str, list[list[list[int | None]]]]  # 1-based, the dominant mode at the peak
    least: list[LeastPose]
    poses: int
    seconds: FiniteFloat
