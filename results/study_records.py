"""The records of the studies and the fidelity choice (`results.schema` assembles the file)."""
from __future__ import annotations

from typing import Any, Literal

from pydantic import FiniteFloat, with_config
from typing_extensions import NotRequired, TypedDict  # pydantic reads it on Python < 3.12

from .tool_records import DynamicStiffnessMap
from .types import STRICT, Frequencies, Frequency, Hz
from .uncertainty_records import UncertaintyPath


@with_config(STRICT)
class HeightCalibration(TypedDict):
    case: str  # the case whose paper row the height is fitted to
    computed_height_mm: FiniteFloat
    scene_height_mm: FiniteFloat | None
    worst_deviation_percent: FiniteFloat
    deviation_percent: list[FiniteFloat]
    settings: str


@with_config(STRICT)
class ConventionReading(TypedDict):
    reading: str
    azimuth_deg: FiniteFloat
    tilt_deg: FiniteFloat
    frequencies_hz: Hz | None  # None: the reading's pose is not reachable
    deviation_percent: list[FiniteFloat] | None
    worst_percent: FiniteFloat | None
    note: str | None


@with_config(STRICT)
class AngleConventions(TypedDict):
    case: str
    azimuth_deg: FiniteFloat  # as printed
    tilt_deg: FiniteFloat
    readings: list[ConventionReading]


@with_config(STRICT)
class Crossing(TypedDict):
    """Where two mode families of the workspace map cross (their frequencies swap order)."""
    families: list[int]  # 1-based
    height_mm: FiniteFloat
    tilt_deg: FiniteFloat
    azimuth_deg: FiniteFloat
    frequency_hz: Frequency
    along: Literal["azimuth", "tilt", "height"]  # the direction of the map's step


@with_config(STRICT)
class Tracking(TypedDict):
    """How the workspace map's families were followed from pose to pose (MAC)."""
    families: str  # what a family is, in words
    root_height_mm: FiniteFloat  # the layer whose level pose numbers the families
    modes_followed: int
    steps: int
    steps_matched_by_shape: int
    poses_with_shapes: int
    min_mac: FiniteFloat | None  # None: no step needed the shapes
    open_rings: int
    lost_families: list[int]  # 1-based


@with_config(STRICT)
class Workspace(TypedDict):
    heights_mm: list[FiniteFloat]
    regular_tilt_deg: list[FiniteFloat]
    tilts_deg: list[list[FiniteFloat]]
    azimuths_deg: list[FiniteFloat]
    frequencies_hz: list[list[list[list[Frequency | None] | None]]]  # [z][tilt][azimuth][mode]
    # per family: mode k followed by its shape (MAC) from pose to pose, so a crossing shows
    tracked_frequencies_hz: list[list[list[list[Frequency | None] | None]]]
    # per leg at every map pose ([z][tilt][azimuth][leg]; None where unreachable): the locked
    # actuator (leg length of a 3-RPS, slider travel of a 3-PRS) and the joint angles of Eq. (25)
    actuation_mm: list[list[list[list[FiniteFloat] | None]]]
    s_joint_angles_deg: list[list[list[list[FiniteFloat] | None]]]
    r_joint_angles_deg: list[list[list[list[FiniteFloat] | None]]]
    crossings: list[Crossing]
    tracking: Tracking
    settings: str


@with_config(STRICT)
class ModelReading(TypedDict):
    """A model's modes against the FEM of the same variant (joint order, coupling), per FEM
    mode, paired by shape."""
    frequencies_hz: Hz
    error_percent: list[FiniteFloat]  # vs that FEM (joint orders) or its limit (couplings)
    mac: list[FiniteFloat]


@with_config(STRICT)
class JointOrderReading(TypedDict):
    base_joint: str
    platform_joint: str
    scene_order: bool
    error: str | None  # why this order could not be solved
    fem_hz: Hz | None
    fem_estimated_error_percent: list[FiniteFloat] | None  # two-mesh: max(Richardson, GCI)
    fem_gci_percent: list[FiniteFloat] | None  # two-mesh GCI (factor 3), per mode
    models: dict[str, ModelReading] | None


@with_config(STRICT)
class JointOrderCase(TypedDict):
    case: str
    readings: list[JointOrderReading]


@with_config(STRICT)
class CouplingReading(TypedDict):
    coupling: str  # "rigid" or "distributing" joint faces, in both models
    scene_coupling: bool  # the coupling of the scene's FEM
    error: str | None  # why this coupling could not be solved
    mesh_sizes_mm: list[FiniteFloat]  # the refinement study behind the limit
    fem_limit_hz: Frequencies | None  # Richardson limit h -> 0
    fem_finest_error_percent: list[FiniteFloat] | None  # stated error of the finest mesh
    fem_finest_gci_percent: list[FiniteFloat] | None  # its grid convergence index
    models: dict[str, ModelReading] | None


@with_config(STRICT)
class CouplingCase(TypedDict):
    case: str
    readings: list[CouplingReading]


@with_config(STRICT)
class ValidationPose(TypedDict):
    height_mm: FiniteFloat
    azimuth_deg: FiniteFloat
    tilt_deg: FiniteFloat
    kind: str  # which part of the design: layer, boundary ring, joint limit, Sobol interior
    error: str | None  # why the pose could not be solved (then the rest is null)
    fem_hz: Hz | None  # the finer of the two meshes
    fem_limit_hz: Frequencies | None  # Richardson's step between them at order 1.42
    fem_estimated_error_percent: list[FiniteFloat] | None  # max(two-mesh Richardson, GCI)
    fem_gci_percent: list[FiniteFloat] | None  # two-mesh GCI (safety factor 3), per mode
    fem_seconds: FiniteFloat | None
    slenderness: list[FiniteFloat] | None  # shortest and longest leg, in leg diameters
    models: dict[str, list[FiniteFloat | None]] | None  # error vs the FEM limit per mode, %;
    # null: unpaired


@with_config(STRICT)
class ModeStatistics(TypedDict):
    median: list[FiniteFloat | None]  # of |error vs FEM| over the poses, %
    p95: list[FiniteFloat | None]
    max: list[FiniteFloat | None]
    unpaired: list[int]  # poses where the FEM mode had no partner (MAC below 0.5)


@with_config(STRICT)
class WorstPose(TypedDict):
    height_mm: FiniteFloat
    azimuth_deg: FiniteFloat
    tilt_deg: FiniteFloat
    kind: str
    slenderness: list[FiniteFloat] | None
    fem_estimated_error_percent: list[FiniteFloat] | None
    error_percent: list[FiniteFloat | None]
    worst_error_percent: FiniteFloat


PerMode = dict[str, ModeStatistics]  # model label -> statistics


@with_config(STRICT)
class ValidationSweep(TypedDict):
    """The workspace validation's poses as the sweep computed them (studies.workspace_validation
    `run_study`), before the run's model is chosen."""
    poses: list[ValidationPose]
    per_mode: PerMode
    models: dict[str, dict[str, Any]]  # model label -> its analytical options
    mesh_size_mm: FiniteFloat  # the FEM's, and the coarser one of each pose's two meshes
    coarse_mesh_size_mm: FiniteFloat
    failed: int


@with_config(STRICT)
class WorkspaceValidation(ValidationSweep):
    default_model: str  # the run's chosen analytical model
    worst_pose: WorstPose | None


@with_config(STRICT)
class HardCase(TypedDict):
    """One claim of studies.hard_cases, measured on the scene's machine."""
    case: str
    claim: str
    tolerance: FiniteFloat
    measured: FiniteFloat
    unit: str
    note: str
    passed: bool


@with_config(STRICT)
class BenchmarkMode(TypedDict):
    """One reference mode of a published benchmark, solved at every size (verification)."""
    label: str
    reference_hz: Frequency
    hz: list[FiniteFloat]  # per size, coarse -> fine
    deviation_percent: FiniteFloat  # finest size against the reference, signed
    observed_order: FiniteFloat | None
    richardson_error_percent: FiniteFloat
    gci_percent: FiniteFloat
    stated_error_percent: FiniteFloat  # max(Richardson, GCI) of the finest size
    tolerance_percent: FiniteFloat  # the band of |deviation|: the mode's own, or the case's
    within_tolerance: bool
    bounded: bool  # |deviation| <= stated error
    counted: bool  # false: shown, left out of the benchmark's verdict (the note says why)
    passed: bool  # within tolerance, and bounded or explained by the reference's uncertainty
    note: str | None


@with_config(STRICT)
class BenchmarkCheck(TypedDict):
    what: str
    value: FiniteFloat | list[FiniteFloat]  # one value, or one per size (coarse -> fine)
    limit: FiniteFloat
    op: Literal["<=", ">=", "=="]  # value op limit
    passed: bool
    counted: bool  # false: a measured limitation, shown, left out of the verdict


@with_config(STRICT)
class Benchmark(TypedDict):
    """A published free-vibration benchmark run by the project's own FEM (verification/)."""
    name: str
    title: str
    source: str
    discretisation: str  # "tetrahedra" or "harmonic"
    what: str
    reference_uncertainty_percent: FiniteFloat | None
    tolerance_percent: FiniteFloat  # the case's band (a mode may declare its own)
    tolerance_reason: str
    mesh_sizes_mm: list[FiniteFloat]
    dofs: list[int]
    seconds: list[FiniteFloat]
    modes: list[BenchmarkMode]
    checks: list[BenchmarkCheck]
    bound_note: str | None
    passed: bool


@with_config(STRICT)
class FemVerification(TypedDict):
    """The solid FEM checked against published benchmarks (studies.fem_verification)."""
    cases: list[Benchmark]
    passed: bool
    seconds: FiniteFloat  # when computed (the record may come from the result cache)


@with_config(STRICT)
class ReachableWorkspace(TypedDict):
    """The machine's reachable workspace, computed before any expensive work (studies.reachable),
    and every way a study adapted its poses to it."""
    level_band_mm: list[FiniteFloat]  # [low, high]: heights whose level pose is reachable
    bounded_by: list[str]  # the limit binding just below and just above the band
    layer_band_mm: list[FiniteFloat]  # [low, high]: where the studies' height layers lie
    regular_tilt_deg: list[FiniteFloat]  # theta_r at the map's layer heights
    validation_poses: int  # workspace-validation poses kept
    validation_poses_dropped: int  # designed but unreachable, left out
    adaptations: list[str]  # what a study changed because the machine could not reach a pose


@with_config(STRICT)
class SweepPoint(TypedDict):
    """Both models with the drive's stiffness scaled (studies.lowest_modes)."""
    factor: FiniteFloat | None  # k_a / the scene's k_a; None: a rigid drive
    actuator_n_per_um: FiniteFloat  # 0: rigid
    analytical_hz: Frequencies  # the run's model, ascending
    fem_hz: Frequencies  # the FEM at the run's mesh size, ascending
    fem_estimated_error_percent: list[FiniteFloat]  # two-mesh: max(Richardson, GCI), per mode
    fem_gci_percent: list[FiniteFloat]  # two-mesh GCI (factor 3), per mode
    error_percent: list[FiniteFloat]  # analytical vs FEM, per FEM mode, paired by shape


@with_config(STRICT)
class EnergyShares(TypedDict):
    """Where one mode's strain energy lies, percent (the run's analytical model)."""
    mode: int
    frequency_hz: Frequency
    legs_percent: FiniteFloat
    joints_percent: FiniteFloat
    drive_percent: FiniteFloat
    platform_percent: FiniteFloat  # 0: the platform is rigid in both models
    largest: str  # "legs", "joints", "drive" or "platform"


@with_config(STRICT)
class LowestModes(TypedDict):
    """What sets the lowest modes of one case (studies.lowest_modes)."""
    case: str
    mesh_size_mm: FiniteFloat  # the FEM's
    sweep: list[SweepPoint]  # empty: the drive is rigid
    rigid_drive: SweepPoint | None
    knee_factors: list[FiniteFloat | None]  # per mode: f = f(rigid drive) / sqrt(2) there
    knee_n_per_um: list[FiniteFloat | None]  # the same in N/um; None: not crossed in the sweep
    shares: list[EnergyShares]  # at the scene's stiffness
    sets_lowest: str  # the part holding most of mode 1's strain energy


@with_config(STRICT)
class Studies(TypedDict, total=False):
    """The scene studies' records, each declared by its study (`results.declare.Record`,
    registry `studies.RECORDS`); the project's own typed here."""
    reachable_workspace: ReachableWorkspace
    height_calibration: HeightCalibration | None
    angle_conventions: list[AngleConventions]
    workspace: Workspace | None
    dynamic_stiffness: DynamicStiffnessMap | None  # None: the scene asks no dynamic compliance
    uncertainty_path: UncertaintyPath | None  # None: the scene declares no [uncertainty]
    joint_orders: list[JointOrderCase]
    joint_couplings: list[CouplingCase]  # empty: not run (the CI profile)
    workspace_validation: WorkspaceValidation | None
    hard_cases: list[HardCase]  # empty: not run (the CI profile)
    lowest_modes: list[LowestModes]  # empty: no spring in the scene, or the CI profile
    fem_verification: FemVerification | None  # None: not run (the CI profile)


@with_config(STRICT)
class BatchedModel(TypedDict):
    """How maps and every study over many poses solve the chosen solid legs (issue 51): each
    part's interior reduced to its own modes, and what that costs in accuracy."""

    part_modes: int  # modal coordinates a part keeps
    coordinates: int  # n a pose, batched
    coordinates_kept: int  # n a pose with every station (the per-pose model's)
    error_percent: FiniteFloat  # worst |batched / per-pose - 1| at the cases, f1..f_modes
    check_error_percent: FiniteFloat  # the same at the poses the reduction was chosen on
    check_poses: int


@with_config(STRICT)
class AnalyticalChoice(TypedDict):
    beam: str
    shear: str
    joint_ends: str
    legs: str  # beam | solid
    elements: int
    platform_inertia: str
    setting: str  # label of the chosen candidate
    chosen: bool  # false: the scene's own [analytical], checked
    worst_error_percent: FiniteFloat
    seconds_per_pose: FiniteFloat
    met: bool
    batched: NotRequired[BatchedModel]  # solid legs reduced for maps (`analytical.batch_model`)


@with_config(STRICT)
class FemChoice(TypedDict):
    mesh_size_mm: FiniteFloat
    chosen: bool  # false: the scene's own mesh_size_mm, checked
    estimated_error_percent: FiniteFloat | None  # null without a refinement study
    seconds_per_pose: FiniteFloat | None
    met: bool


@with_config(STRICT)
class Candidate(TypedDict):
    setting: str
    worst_error_percent: FiniteFloat
    seconds_per_pose: FiniteFloat


@with_config(STRICT)
class Fidelity(TypedDict):
    """What the scene asked ([fidelity]) and what the run chose to meet it."""

    modes: int
    tolerance_percent: FiniteFloat
    met: bool
    analytical: AnalyticalChoice
    fem: FemChoice
    reason: str
    candidates: list[Candidate]
