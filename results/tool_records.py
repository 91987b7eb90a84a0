"""The records of the dynamic compliance at the tool (issue 38): a case's tool response
against the solid's direct frequency response (`cases[].tool_response`,
studies/tool_response.py) and the least dynamic stiffness over the workspace map
(`studies.dynamic_stiffness`, studies/dynamic_stiffness.py). Units in the field names; None
in a grid where a pose is not reached (or nothing moves the tool that way)."""
from __future__ import annotations

from pydantic import FiniteFloat, with_config
from typing_extensions import NotRequired, TypedDict  # pydantic reads it on Python < 3.12

from .types import STRICT

__all__ = ["DynamicStiffnessMap", "FrfFile", "FrfLeast", "FrfMode", "FrfPeak", "FrfRecord",
           "LeastPose", "OutputPose", "Receptance", "ToolCurves", "ToolPeak", "ToolResponse",
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


@with_config(STRICT)
class OutputPose(TypedDict):
    """The pose a command computed, as typed or as the case gives it."""
    height_mm: FiniteFloat
    azimuth_deg: FiniteFloat
    tilt_deg: FiniteFloat


@with_config(STRICT)
class Receptance(TypedDict):
    """One entry of the 3x3 receptance over the band's lines (m/N)."""
    re: list[FiniteFloat]
    im: list[FiniteFloat]


@with_config(STRICT)
class FrfMode(TypedDict):
    """One summed mode at the tool: along x, y, z its modal stiffness omega^2 / phi_d^2 and
    effective mass 1 / phi_d^2 (null: the mode leaves the tool still that way), and its
    mass-normalised displacement phi_d (signed, 1/sqrt(kg), base frame)."""
    frequency_hz: FiniteFloat
    damping_ratio: FiniteFloat
    modal_stiffness_n_per_m: dict[str, FiniteFloat | None]
    effective_mass_kg: dict[str, FiniteFloat | None]
    tool_shape_per_sqrt_kg: dict[str, FiniteFloat]


@with_config(STRICT)
class FrfPeak(TypedDict):
    """A peak of |H_dd| and the mode (1-based) it is near."""
    frequency_hz: FiniteFloat
    magnitude_m_per_n: FiniteFloat
    mode: int


@with_config(STRICT)
class FrfLeast(TypedDict):
    """The least dynamic stiffness along one direction: 1 / max |H_dd| over the band (null:
    nothing moves the tool that way), where, and the mode (1-based) dominating there."""
    stiffness_n_per_m: FiniteFloat | None
    frequency_hz: FiniteFloat
    mode: int


@with_config(STRICT)
class FrfRecord(TypedDict):
    """The dynamic compliance at the tool of one pose (solvers.tool_frf.frf_record)."""
    model: str  # the model and its settings, in words
    convention: str  # the formula of the receptance, in words
    point_mm: list[FiniteFloat]  # the tool point, platform frame
    damping: str
    frequency_hz: list[FiniteFloat]  # the band's lines
    receptance_m_per_n: dict[str, Receptance]  # "xx", "yy", "zz", "xy", "xz", "yz"
    static_compliance_m_per_n: list[list[FiniteFloat]]  # 3x3
    modes_superposed: int
    residual_flexibility_m_per_n: list[list[FiniteFloat]]  # 3x3, of the modes not summed
    modes: list[FrfMode]
    peaks: dict[str, list[FrfPeak]]  # per direction x, y, z
    least_dynamic_stiffness: dict[str, FrfLeast]  # per direction x, y, z


@with_config(STRICT)
class FrfFile(FrfRecord):
    record: str
    schema: int
    scene: str
    case: str
    pose: OutputPose
    settings: NotRequired[str]  # the analytical model's settings (--model analytical)
    settings_from: NotRequired[str]  # where they come from
    mesh_size_mm: NotRequired[FiniteFloat]  # the FEM's (--model fem)
    mesh_size_from: NotRequired[str]
    dofs: NotRequired[int]
    point_base_mm: list[FiniteFloat]  # the tool point, base frame at this pose
    platform_rotation: NotRequired[list[list[FiniteFloat]]]  # platform -> base at this pose
    seconds: FiniteFloat
    warnings: list[str]
