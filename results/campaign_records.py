"""What correlation.json and identification.json hold: typed records, mm and degrees at this
edge as in every output (`rps correlate`, `rps identify`)."""
from __future__ import annotations

from pydantic import FiniteFloat, with_config
from typing_extensions import TypedDict  # pydantic reads it on Python < 3.12

from .types import STRICT

SCHEMA = 3  # 2: identification.json's V&V 20 rows; 3: the "record" key, checked on write


@with_config(STRICT)
class PairRecord(TypedDict):
    test_mode: int  # 1-based
    model_mode: int  # 1-based
    test_hz: FiniteFloat
    model_hz: FiniteFloat
    error_percent: FiniteFloat  # 100 (f_model / f_test - 1)
    mac: FiniteFloat  # or, against a repeated model group, the test shape's share in its subspace
    repeated: bool  # the model mode belongs to a group of (near-)repeated frequencies


@with_config(STRICT)
class UnpairedTest(TypedDict):
    test_mode: int
    test_hz: FiniteFloat
    reason: str


@with_config(STRICT)
class UnpairedModel(TypedDict):
    model_mode: int
    model_hz: FiniteFloat


@with_config(STRICT)
class NodeRecord(TypedDict):
    id: int
    xyz_mm: list[FiniteFloat]
    body: str
    distance_mm: FiniteFloat  # outside the body (0: inside)
    directions: list[str]


@with_config(STRICT)
class MachineRecord(TypedDict):
    base_joints_mm: list[list[FiniteFloat]]
    platform_joints_mm: list[list[FiniteFloat]]
    platform_centre_mm: list[FiniteFloat]
    platform_normal: list[FiniteFloat]
    platform_radius_mm: FiniteFloat
    leg_diameter_mm: FiniteFloat


@with_config(STRICT)
class PoseCorrelation(TypedDict):
    name: str
    height_mm: FiniteFloat
    azimuth_deg: FiniteFloat
    tilt_deg: FiniteFloat
    source: str
    data: str
    test_hz: list[FiniteFloat]
    test_damping_ratio: list[FiniteFloat] | None
    model_hz: list[FiniteFloat]
    mac: list[list[FiniteFloat]]  # rows: test modes, columns: model modes
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
    min_mac: FiniteFloat
    max_frequency_ratio: FiniteFloat
    rule: str


@with_config(STRICT)
class CorrelationSummary(TypedDict):
    pairs: int
    unpaired_test_modes: int
    mean_abs_error_percent: FiniteFloat | None
    max_abs_error_percent: FiniteFloat | None
    min_mac: FiniteFloat | None


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
    seconds: FiniteFloat


@with_config(STRICT)
class ParameterRecord(TypedDict):
    key: str
    unit: str
    initial: FiniteFloat
    value: FiniteFloat
    ci95: list[FiniteFloat]
    bounds: list[FiniteFloat]
    identifiable: bool
    at_bound: bool
    relative_std_percent: FiniteFloat | None
    reason: str


@with_config(STRICT)
class FitMode(TypedDict):
    test_mode: int
    test_hz: FiniteFloat
    before_hz: FiniteFloat
    after_hz: FiniteFloat
    error_before_percent: FiniteFloat
    error_after_percent: FiniteFloat
    mac_after: FiniteFloat


@with_config(STRICT)
class FitPose(TypedDict):
    pose: str
    modes: list[FitMode]


@with_config(STRICT)
class NoiseRecord(TypedDict):
    frequency_percent: FiniteFloat | None
    source: str  # "stated" or "residuals"
    degrees_of_freedom: int


@with_config(STRICT)
class ValidationRecord(TypedDict):
    """V&V 20 for one fitted test mode (solvers/vv20.py): the scene's model (its values as
    given) against the test, standard uncertainties in %."""
    pose: str
    test_mode: int
    model_mode: int
    test_hz: FiniteFloat
    model_hz: FiniteFloat
    e_percent: FiniteFloat  # the scene's model against the test
    e_identified_percent: FiniteFloat  # the identified model (fitted to these data: not a
    # validation)
    u_num_percent: FiniteFloat | None  # the beam model's change with its elements doubled,
    # / sqrt(3)
    u_input_percent: FiniteFloat | None  # the scene's [uncertainty] at the pose; None without one
    u_d_percent: FiniteFloat | None  # the identification's frequency noise
    u_val_percent: FiniteFloat
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
    residual_rms_percent_before: FiniteFloat
    residual_rms_percent_after: FiniteFloat
    noise: NoiseRecord
    singular_values: list[FiniteFloat]
    parameter_correlation: list[list[FiniteFloat]]
    fit: list[FitPose]
    evaluations: int
    seconds: FiniteFloat
    optimiser: str
    correlation_after: Correlation
    validation: list[ValidationRecord]
    validation_note: str
