"""The records of input uncertainty (issue 39): a case's statistics of the frequencies (and of
the least dynamic stiffness at the tool) with Sobol' indices and the V&V 20 table of the
model against the FEM (`cases[].uncertainty`, studies/uncertainty.py), and the 95 % band of
f1 and of the least dynamic stiffness along the workspace map's worst path
(`studies.uncertainty_path`, studies/uncertainty_path.py). Units in the field names; every
statistic beside its 95 % sampling error (`*_error_*`, a half-width)."""
from __future__ import annotations

from pydantic import FiniteFloat, with_config
from typing_extensions import TypedDict  # pydantic reads it on Python < 3.12

from .tool_records import OutputPose
from .types import STRICT

__all__ = ["FrequencyStatistics", "PathPose", "SobolRow", "StiffnessStatistics",
           "UncertainInputRecord", "UncertaintyCase", "UncertaintyFile", "UncertaintyMode",
           "UncertaintyPath", "UncertaintyRecord", "UncertaintyStiffness", "ValidationRow"]


@with_config(STRICT)
class UncertainInputRecord(TypedDict):
    key: str  # the scene address, e.g. material.youngs_modulus_gpa
    distribution: str
    described: str
    unit: str
    nominal: FiniteFloat  # the scene's value, edge unit
    support: list[FiniteFloat]  # the distribution cut at its 1e-6 quantiles
    followers: list[str]
    source: str


@with_config(STRICT)
class UncertaintyMode(TypedDict):
    mode: int  # the k-th lowest frequency of each sample
    nominal_hz: FiniteFloat
    mean_hz: FiniteFloat
    mean_error_hz: FiniteFloat
    std_hz: FiniteFloat
    std_error_hz: FiniteFloat
    cv_percent: FiniteFloat
    q025_hz: FiniteFloat
    q025_error_hz: FiniteFloat
    q975_hz: FiniteFloat
    q975_error_hz: FiniteFloat


@with_config(STRICT)
class UncertaintyStiffness(TypedDict):
    direction: str
    nominal_n_per_m: FiniteFloat
    mean_n_per_m: FiniteFloat
    mean_error_n_per_m: FiniteFloat
    std_n_per_m: FiniteFloat
    cv_percent: FiniteFloat
    q025_n_per_m: FiniteFloat
    q975_n_per_m: FiniteFloat


@with_config(STRICT)
class SobolRow(TypedDict):
    output: str  # "f1".. or "least x" ..
    key: str
    first: FiniteFloat | None  # None where the output does not vary
    first_error: FiniteFloat | None
    total: FiniteFloat | None
    total_error: FiniteFloat | None


@with_config(STRICT)
class ValidationRow(TypedDict):
    """V&V 20 for one FEM mode: E = S - D (the model against the FEM, %), with the FEM's
    numerical uncertainty, the input uncertainty and the validation uncertainty (standard
    uncertainties, %)."""
    fem_mode: int
    analytical_mode: int
    e_percent: FiniteFloat
    u_num_percent: FiniteFloat | None  # the FEM's stated error / sqrt(3); None: not estimated
    u_input_percent: FiniteFloat
    u_d_percent: FiniteFloat | None  # a test's; None against the FEM
    u_val_percent: FiniteFloat
    verdict: str


@with_config(STRICT)
class UncertaintyCase(TypedDict):
    inputs: list[UncertainInputRecord]
    design: str
    model: str
    runs: int
    refused: str | None  # why nothing was propagated (a budget, a model that cannot)
    modes: list[UncertaintyMode]
    least: list[UncertaintyStiffness]  # [] without [tool] or [damping]
    sobol: list[SobolRow]
    validation: list[ValidationRow]
    seconds: FiniteFloat


@with_config(STRICT)
class PathPose(TypedDict):
    layer: int
    height_mm: FiniteFloat
    tilt_deg: FiniteFloat
    azimuth_deg: FiniteFloat
    f1_nominal_hz: FiniteFloat
    f1_q025_hz: FiniteFloat
    f1_median_hz: FiniteFloat
    f1_q975_hz: FiniteFloat
    least_nominal_n_per_m: FiniteFloat | None  # the least over x, y, z; None without [tool]
    least_q025_n_per_m: FiniteFloat | None
    least_median_n_per_m: FiniteFloat | None
    least_q975_n_per_m: FiniteFloat | None


@with_config(STRICT)
class UncertaintyPath(TypedDict):
    path: str  # how the path was chosen
    samples: int
    model: str
    refused: str | None
    poses: list[PathPose]
    skipped: list[str]  # a pose of the path where a sample cannot reach it: no band there
    seconds: FiniteFloat


Indices = dict[str, FiniteFloat | None]  # input key -> a Sobol' index (null: no variation)


@with_config(STRICT)
class FrequencyStatistics(TypedDict):
    """The k-th lowest frequency over the samples: statistics, each with its 95 % sampling
    error (a half-width), and the first-order and total Sobol' index of every input."""
    mode: int
    nominal_hz: FiniteFloat  # at the scene's values
    mean_hz: FiniteFloat
    std_hz: FiniteFloat
    q025_hz: FiniteFloat
    q975_hz: FiniteFloat
    mean_error_hz: FiniteFloat
    std_error_hz: FiniteFloat
    q025_error_hz: FiniteFloat
    q975_error_hz: FiniteFloat
    cv_percent: FiniteFloat | None
    sobol_first: Indices
    sobol_first_error: Indices
    sobol_total: Indices
    sobol_total_error: Indices


@with_config(STRICT)
class StiffnessStatistics(TypedDict):
    """The least dynamic stiffness at the tool along one direction over the samples."""
    nominal_n_per_m: FiniteFloat
    mean_n_per_m: FiniteFloat
    std_n_per_m: FiniteFloat
    q025_n_per_m: FiniteFloat
    q975_n_per_m: FiniteFloat
    mean_error_n_per_m: FiniteFloat
    std_error_n_per_m: FiniteFloat
    q025_error_n_per_m: FiniteFloat
    q975_error_n_per_m: FiniteFloat
    cv_percent: FiniteFloat | None
    sobol_first: Indices
    sobol_first_error: Indices
    sobol_total: Indices
    sobol_total_error: Indices


@with_config(STRICT)
class UncertaintyRecord(TypedDict):
    """The scene's [uncertainty] propagated at one pose (solvers.uncertainty.propagate)."""
    inputs: list[UncertainInputRecord]
    design: str  # the sampling design, in words
    samples: int  # base points N
    runs: int  # model runs, N (d + 2)
    model: str  # the model propagated through
    modes: list[FrequencyStatistics]
    least_dynamic_stiffness: dict[str, StiffnessStatistics] | None  # per x, y, z; null
    # without [tool] or [damping]
    model_seconds: FiniteFloat
    statistics_seconds: FiniteFloat


@with_config(STRICT)
class UncertaintyFile(UncertaintyRecord):
    record: str
    schema: int
    scene: str
    case: str
    pose: OutputPose
    settings_from: str  # where the model's settings come from
    seconds: FiniteFloat
    warnings: list[str]
