"""What correlation.json and identification.json hold: typed records, mm and degrees at this
edge as in every output (`rps correlate`, `rps identify`)."""
from __future__ import annotations

from pydantic import with_config
from typing_extensions import TypedDict  # pydantic reads it on Python < 3.12

from .types import STRICT

SCHEMA = 3  # 2: identification.json's V&V 20 rows; 3: the "record" key, checked on write


@with_config(STRICT)
class PairRecord(TypedDict):
    test_mode: int  # 1-based
    model_mode: int  # 1-based
    test_hz: float
    model_hz: float
    error_percent: float  # 100 (f_model / f_test - 1)
    mac: float  # or, against a repeated model group, the test shape's share in its subspace
    repeated: bool  # the model mode belongs to a group of (near-)repeated frequencies


@with_config(STRICT)
class UnpairedTest(TypedDict):
    test_mode: int
    test_hz: float
    reason: str


@with_config(STRICT)
class UnpairedModel(TypedDict):
    model_mode: int
    model_hz: float


@with_config(STRICT)
class NodeRecord(TypedDict):
    id: int
    xyz_mm: list[float]
    body: str
    distance_mm: float  # outside the body (0: inside)
    directions: list[str]


@with_config(STRICT)
class MachineRecord(TypedDict):
    base_joints_mm: list[list[float]]
    platform_joints_mm: list[list[float]]
    platform_centre_mm: list[float]
    platform_normal: list[float]
    platform_radius_mm: float
    leg_diameter_mm: float


@with_config(STRICT)
class PoseCorrelation(TypedDict):
    name: str
    height_mm: float
    azimuth_deg: float
    tilt_deg: float
    source: str
    data: str
    test_hz: list[float]
    test_damping_ratio: list[float] | None
    model_hz: list[float]
    mac: list[list[float]]  # rows: test modes, columns: model modes
    pairs: list[PairRecord]
    unpaired_test_modes: list[UnpairedTest]
    unpaired_model_modes: list[UnpairedModel]
    nodes: list[NodeRecord]
    machine: MachineRecord


@with_config(STRICT)
class ModelRecord(TypedDict):
    kind: str  # "analytical" or "fem"
    description: str


@with_config(STRICT)
class PairingRecord(TypedDict):
    min_mac: float
    max_frequency_ratio: float
    rule: str


@with_config(STRICT)
class CorrelationSummary(TypedDict):
    pairs: int
    unpaired_test_modes: int
    mean_abs_error_percent: float | None
    max_abs_error_percent: float | None
    min_mac: float | None


@with_config(STRICT)
class Correlation(TypedDict):
    record: str  # "correlation" (results.outputs.CORRELATION)
    schema: int
    campaign: str
    scene: str
    model: ModelRecord
    pairing: PairingRecord
    poses: list[PoseCorrelation]
    summary: CorrelationSummary
    seconds: float


@with_config(STRICT)
class ParameterRecord(TypedDict):
    key: str
    unit: str
    initial: float
    value: float
    ci95: list[float]
    bounds: list[float]
    identifiable: bool
    at_bound: bool
    relative_std_percent: float | None
    reason: str


@with_config(STRICT)
class FitMode(TypedDict):
    test_mode: int
    test_hz: float
    before_hz: float
    after_hz: float
    error_before_percent: float
    error_after_percent: float
    mac_after: float


@with_config(STRICT)
class FitPose(TypedDict):
    pose: str
    modes: list[FitMode]


@with_config(STRICT)
class NoiseRecord(TypedDict):
    frequency_percent: float | None
    source: str  # "stated" or "residuals"
    degrees_of_freedom: int


@with_config(STRICT)
class ValidationRecord(TypedDict):
    """V&V 20 for one fitted test mode (solvers/vv20.py): the scene's model (its values as
    given) against the test, standard uncertainties in %."""
    pose: str
    test_mode: int
    model_mode: int
    test_hz: float
    model_hz: float
    e_percent: float  # the scene's model against the test
    e_identified_percent: float  # the identified model (fitted to these data: not a validation)
    u_num_percent: float | None  # the beam model's change with its elements doubled, / sqrt(3)
    u_input_percent: float | None  # the scene's [uncertainty] at the pose; None without one
    u_d_percent: float | None  # the identification's frequency noise
    u_val_percent: float
    verdict: str


@with_config(STRICT)
class Identification(TypedDict):
    record: str  # "identification" (results.outputs.IDENTIFICATION)
    schema: int
    campaign: str
    scene: str
    identified_scene: str
    identified_scene_check: str  # "accepted", with its warnings, or why the scene refuses it
    model: ModelRecord
    parameters: list[ParameterRecord]
    residual_rms_percent_before: float
    residual_rms_percent_after: float
    noise: NoiseRecord
    singular_values: list[float]
    parameter_correlation: list[list[float]]
    fit: list[FitPose]
    evaluations: int
    seconds: float
    optimiser: str
    correlation_after: Correlation
    validation: list[ValidationRecord]
    validation_note: str
