"""The results file's schema (`out/results.json`), declared once: the pipeline writes it, the
reports read it, the report test fixture is built through it.

Every object is a TypedDict whose keys are all required (a value the run did not compute is
null, never a missing key), checked by pydantic in strict mode with unknown keys rejected:
`validated(results)` before writing, `read(path)` when reading. A file of another schema
version gets one line naming its version. Change a field here and bump SCHEMA_VERSION.

Units are in the key names (_hz, _mm, _m, _deg, _percent, seconds); modes are 1-based in
`pairs` and 0-based in lists. Every frequency is finite, positive and at most
MAX_FREQUENCY_HZ; the frequencies of one solve ascend (`Hz`; limits extrapolated from several
solves, and the paper's rows, need not: `Frequencies`). A case name is a name `common.paths`
turns into file names, and no two give the same one; a mode file is named by a relative
path inside the results' folder. Mode shapes are mass-normalised; a platform motion is
[6][mode]: the translation of the platform centre o (m) then the rotation (rad), base axes.
"""
from __future__ import annotations

import json
import re
from pathlib import Path, PurePosixPath
from typing import Annotated, Any, Literal

import numpy as np
from typing_extensions import TypedDict  # pydantic reads it on Python < 3.12

from pydantic import (AfterValidator, ConfigDict, Field, FiniteFloat, TypeAdapter,
                      ValidationError, with_config)

from common.paths import UnsafeName, distinct_stems, name_problem

SCHEMA_VERSION = 6
LOW_MODES = 3  # the paper reads its errors in two ranges: modes 1-3 and the modes above
# No structural mode of a machine the scene ranges admit comes near 1 GHz; a larger value in
# a results file is a doctored or corrupted one (1e308 Hz), never a result.
MAX_FREQUENCY_HZ = 1e9
# A results file nests 9 deep (a case's leg_axis_shapes [leg][station][xyz][mode], the
# workspace maps); one nested deeper than this is refused before it is parsed (`read`), so no
# input reaches the parser's or the validator's recursion limit.
MAX_DEPTH = 32


def _ascending(values: list[float]) -> list[float]:
    for k in range(1, len(values)):
        if values[k] < values[k - 1]:
            raise ValueError(f"frequencies must ascend, but [{k}] = {values[k]!r} comes after "
                             f"{values[k - 1]!r}")
    return values


def _file_name(name: str) -> str:
    why = name_problem(name)
    if why is not None:
        raise ValueError(f"case name {why}, so it cannot name the case's files")
    return name


def _relative(path: str | None) -> str | None:
    if path is not None and (not path or "\\" in path or "\0" in path
                             or PurePosixPath(path).is_absolute()
                             or ".." in PurePosixPath(path).parts):
        raise ValueError("expected a path relative to the results file, inside its folder")
    return path


Frequency = Annotated[FiniteFloat, Field(gt=0.0, le=MAX_FREQUENCY_HZ)]
Frequencies = list[Frequency]  # several solves' extrapolated limits, the paper's rows
Hz = Annotated[list[Frequency], AfterValidator(_ascending)]  # the modes of one solve
CaseName = Annotated[str, AfterValidator(_file_name)]
RelativePath = Annotated[str | None, AfterValidator(_relative)]
Motion = list[list[FiniteFloat]]  # [6][mode]: translation of o (m), rotation (rad)
_STRICT = ConfigDict(extra="forbid", strict=True)


@with_config(_STRICT)
class Manipulator(TypedDict):
    base_radius_mm: FiniteFloat
    platform_radius_mm: FiniteFloat
    leg_diameter_mm: FiniteFloat
    platform_thickness_mm: FiniteFloat
    platform_shape: str
    leg_angles_deg: list[FiniteFloat]
    actuator_range_mm: list[FiniteFloat]
    s_joint_max_deg: FiniteFloat
    r_joint_max_deg: FiniteFloat
    base_joint: str
    platform_joint: str
    youngs_modulus_gpa: FiniteFloat
    shear_modulus_gpa: FiniteFloat
    poisson_ratio: FiniteFloat
    density_kg_m3: FiniteFloat


@with_config(_STRICT)
class AnalyticalSettings(TypedDict):
    elements: int
    beam: str
    platform_inertia: str
    modes: int


@with_config(_STRICT)
class FemSettings(TypedDict):
    mesh_size_mm: FiniteFloat
    refinement_mm: list[FiniteFloat]
    rim_factor: FiniteFloat
    rim_zone_mm: FiniteFloat
    platform: str
    coupling: str
    legs: str  # "harmonic" (Fourier harmonics on a meridian mesh) or "tetrahedra"


@with_config(_STRICT)
class Calibrated(TypedDict):
    name: str
    value: str
    reason: str


@with_config(_STRICT)
class SceneSummary(TypedDict):
    name: str
    path: str
    sha256: str
    manipulator: Manipulator
    analytical: AnalyticalSettings
    fem: FemSettings
    calibrated: list[Calibrated]


@with_config(_STRICT)
class Environment(TypedDict):
    project_version: str | None  # the installed package's version
    git_commit: str | None  # of the source tree, "+ local changes" when it was not clean
    python: str
    platform: str
    machine: str
    cpu_count: int | None
    date: str
    versions: dict[str, str | None]


@with_config(_STRICT)
class Pose(TypedDict):
    height_mm: FiniteFloat
    height_origin: Literal["calibrated", "scene"]
    azimuth_deg: FiniteFloat
    tilt_deg: FiniteFloat
    centre_mm: list[FiniteFloat]
    base_points_mm: list[list[FiniteFloat]]  # base joint centres B_i
    platform_points_mm: list[list[FiniteFloat]]  # platform joint centres A_i
    leg_lengths_mm: list[FiniteFloat]
    s_joint_angles_deg: list[FiniteFloat]
    r_joint_angles_deg: list[FiniteFloat]


@with_config(_STRICT)
class Pair(TypedDict):
    """FEM mode `fem_mode` and the analytical mode of the same shape."""
    fem_mode: int
    analytical_mode: int
    f_fem_hz: Frequency
    f_analytical_hz: Frequency
    error_percent: FiniteFloat  # analytical vs this FEM mesh
    mac: FiniteFloat  # or cos^2 of the largest principal angle of a repeated group
    repeated: bool
    group: int
    fem_estimated_error_percent: FiniteFloat | None  # the FEM's own, from its refinement
    f_reference_hz: Frequency | None  # the FEM extrapolated to h -> 0
    error_vs_reference_percent: FiniteFloat | None


@with_config(_STRICT)
class AnalyticalRecord(TypedDict):
    elements: int
    beam: str
    shear: str  # Timoshenko shear coefficient: cowper | hutchinson
    joint_ends: str  # beam | solid (end zones condensed from a solid, joint_ends/)
    platform_inertia: str
    frequencies_hz: Hz
    timings: dict[str, FiniteFloat]  # seconds; "total": one pose
    dofs: int
    platform_motion: Motion


@with_config(_STRICT)
class FemRecord(TypedDict):
    frequencies_hz: Hz
    dofs: int
    raw_dofs: int
    mesh_size_m: FiniteFloat
    platform: str
    coupling: str
    timings: dict[str, FiniteFloat]  # seconds: mesh, assemble, solve, total
    mesh_cache_hit: bool  # then "mesh" timed a cache read
    cache_hit: bool  # the whole result came from the result cache
    platform_motion: Motion
    min_scaled_jacobian: FiniteFloat | None  # worst curved element of the mesh (1 = ideal)


@with_config(_STRICT)
class CaseAnalytical(AnalyticalRecord):
    leg_axis_stations: list[FiniteFloat]  # fractions of B_i -> A_i
    leg_axis_shapes: list[list[list[list[FiniteFloat]]]]  # [leg][station][xyz][mode], m


@with_config(_STRICT)
class CaseFem(FemRecord):
    vtu: RelativePath  # mode shapes of the solid, relative to results.json
    pvd: RelativePath  # ParaView collection stepping through the modes, relative


@with_config(_STRICT)
class Paper(TypedDict):
    fea_hz: Frequencies | None
    theory_hz: Frequencies | None
    error_percent: list[FiniteFloat] | None  # recomputed: theory / FEA - 1
    printed_error_percent: list[FiniteFloat] | None
    printed_error_note: str | None  # where the printed errors do not follow from the rows


@with_config(_STRICT)
class Refinement(TypedDict):
    """The FEM at a sequence of mesh sizes, extrapolated to h -> 0 (Richardson)."""
    sizes_m: list[FiniteFloat]
    effective_sizes_m: list[FiniteFloat]
    frequencies_hz: list[Hz]  # [size][mode]
    dofs: list[int]
    raw_dofs: list[int]
    timings: list[dict[str, FiniteFloat]]
    seconds: list[FiniteFloat]
    mesh_cache_hit: list[bool]
    observed_order: list[FiniteFloat | None]
    orders_by_triplet: list[list[FiniteFloat | None]]
    status: list[str]  # ok, order bounded by theory, non-monotone, order out of range, converged
    extrapolated_hz: Frequencies
    estimated_error_percent: list[list[FiniteFloat]]  # [size][mode]
    estimated_error_percent_max: list[FiniteFloat]


@with_config(_STRICT)
class ModelVariant(AnalyticalRecord):
    median_seconds: FiniteFloat
    pairs: list[Pair]


@with_config(_STRICT)
class FemVariant(FemRecord):
    pairs: list[Pair]  # against the case's FEM: "analytical" here is the variant
    shift_percent: list[FiniteFloat]


@with_config(_STRICT)
class ElementConvergence(TypedDict):
    elements: list[int]
    beam: str
    frequencies_hz: list[Hz]  # [s][mode]


@with_config(_STRICT)
class SpeedPoint(TypedDict):
    model: Literal["analytical", "fem"]
    setting: str
    seconds: FiniteFloat  # analytical: median; FEM: one run
    worst_error_percent: FiniteFloat
    single_run: bool
    mesh_from_cache: bool | None


@with_config(_STRICT)
class Case(TypedDict):
    name: CaseName
    description: str
    pose: Pose
    analytical: CaseAnalytical
    fem: CaseFem
    pairs: list[Pair]
    paper: Paper | None
    mac_matrix: list[list[FiniteFloat]]  # [analytical mode][FEM mode]
    fem_estimated_error_percent: list[FiniteFloat] | None
    fem_reference_hz: Frequencies | None
    fem_refinement: Refinement | None
    models: dict[str, ModelVariant] | None
    element_convergence: dict[str, ElementConvergence] | None
    fem_variants: dict[str, FemVariant] | None
    fem_variant_errors: dict[str, str] | None  # variants that could not be solved, and why
    speed_vs_error: list[SpeedPoint] | None


@with_config(_STRICT)
class HeightCalibration(TypedDict):
    case: str  # the case whose paper row the height is fitted to
    computed_height_mm: FiniteFloat
    scene_height_mm: FiniteFloat | None
    worst_deviation_percent: FiniteFloat
    deviation_percent: list[FiniteFloat]
    settings: str


@with_config(_STRICT)
class ConventionReading(TypedDict):
    reading: str
    azimuth_deg: FiniteFloat
    tilt_deg: FiniteFloat
    frequencies_hz: Hz | None  # None: the reading's pose is not reachable
    deviation_percent: list[FiniteFloat] | None
    worst_percent: FiniteFloat | None
    note: str | None


@with_config(_STRICT)
class AngleConventions(TypedDict):
    case: str
    azimuth_deg: FiniteFloat  # as printed
    tilt_deg: FiniteFloat
    readings: list[ConventionReading]


@with_config(_STRICT)
class Workspace(TypedDict):
    heights_mm: list[FiniteFloat]
    regular_tilt_deg: list[FiniteFloat]
    tilts_deg: list[list[FiniteFloat]]
    azimuths_deg: list[FiniteFloat]
    frequencies_hz: list[list[list[list[Frequency | None] | None]]]  # [z][tilt][azimuth][mode]
    # per family: mode k followed by its shape (MAC) from pose to pose, so a crossing shows
    tracked_frequencies_hz: list[list[list[list[Frequency | None] | None]]]
    crossings: list[dict[str, Any]]  # families, height_mm, tilt_deg, azimuth_deg, frequency_hz
    tracking: dict[str, Any]  # how the families were followed (steps, lowest MAC, ...)
    settings: str


@with_config(_STRICT)
class JointOrderModel(TypedDict):
    frequencies_hz: Hz
    error_percent: list[FiniteFloat]  # vs the FEM of the same joint order
    mac: list[FiniteFloat]


@with_config(_STRICT)
class JointOrderReading(TypedDict):
    base_joint: str
    platform_joint: str
    scene_order: bool
    error: str | None  # why this order could not be solved
    fem_hz: Hz | None
    models: dict[str, JointOrderModel] | None


@with_config(_STRICT)
class JointOrderCase(TypedDict):
    case: str
    readings: list[JointOrderReading]


@with_config(_STRICT)
class CouplingModel(TypedDict):
    frequencies_hz: Hz
    error_percent: list[FiniteFloat]  # vs the FEM limit of the same coupling, per FEM mode
    mac: list[FiniteFloat]


@with_config(_STRICT)
class CouplingReading(TypedDict):
    coupling: str  # "rigid" or "distributing" joint faces, in both models
    scene_coupling: bool  # the coupling of the scene's FEM
    error: str | None  # why this coupling could not be solved
    fem_sizes_mm: list[FiniteFloat]  # the refinement study behind the limit
    fem_limit_hz: Frequencies | None  # Richardson limit h -> 0
    fem_finest_error_percent: list[FiniteFloat] | None  # stated error of the finest mesh
    models: dict[str, CouplingModel] | None


@with_config(_STRICT)
class CouplingCase(TypedDict):
    case: str
    readings: list[CouplingReading]


@with_config(_STRICT)
class ValidationPose(TypedDict):
    height_mm: FiniteFloat
    azimuth_deg: FiniteFloat
    tilt_deg: FiniteFloat
    kind: str  # which part of the design: layer, boundary ring, joint limit, Sobol interior
    error: str | None  # why the pose could not be solved (then the rest is null)
    fem_hz: Hz | None  # the finer of the two meshes
    fem_limit_hz: Frequencies | None  # Richardson's step between them at order 1.42
    fem_estimated_error_percent: list[FiniteFloat] | None  # two-mesh estimate, per mode
    fem_seconds: FiniteFloat | None
    slenderness: list[FiniteFloat] | None  # shortest and longest leg, in leg diameters
    models: dict[str, list[FiniteFloat | None]] | None  # error vs the FEM limit per mode, %;
    # null: unpaired


@with_config(_STRICT)
class ModeStatistics(TypedDict):
    median: list[FiniteFloat | None]  # of |error vs FEM| over the poses, %
    p95: list[FiniteFloat | None]
    max: list[FiniteFloat | None]
    unpaired: list[int]  # poses where the FEM mode had no partner (MAC below 0.5)


@with_config(_STRICT)
class WorstPose(TypedDict):
    height_mm: FiniteFloat
    azimuth_deg: FiniteFloat
    tilt_deg: FiniteFloat
    kind: str
    slenderness: list[FiniteFloat] | None
    fem_estimated_error_percent: list[FiniteFloat] | None
    error_percent: list[FiniteFloat | None]
    worst_error_percent: FiniteFloat


@with_config(_STRICT)
class WorkspaceValidation(TypedDict):
    poses: list[ValidationPose]
    per_mode: dict[str, ModeStatistics]  # model label -> statistics
    models: dict[str, dict[str, Any]]  # model label -> its analytical options
    default_model: str  # the run's chosen analytical model
    fem_mesh_size_mm: FiniteFloat
    fem_coarse_size_mm: FiniteFloat
    failed: int
    worst_pose: WorstPose | None


@with_config(_STRICT)
class HardCase(TypedDict):
    """One claim of pipeline.hard_cases, measured on the scene's machine."""
    case: str
    claim: str
    tolerance: FiniteFloat
    measured: FiniteFloat
    unit: str
    note: str
    passed: bool


@with_config(_STRICT)
class ReachableWorkspace(TypedDict):
    """The machine's reachable workspace, computed before any expensive work (pipeline.envelope),
    and every way a study adapted its poses to it."""
    level_band_mm: list[FiniteFloat]  # [low, high]: heights whose level pose is reachable
    bounded_by: list[str]  # the limit binding just below and just above the band
    layer_band_mm: list[FiniteFloat]  # [low, high]: where the studies' height layers lie
    regular_tilt_deg: list[FiniteFloat]  # theta_r at the map's layer heights
    validation_poses: int  # workspace-validation poses kept
    validation_poses_dropped: int  # designed but unreachable, left out
    adaptations: list[str]  # what a study changed because the machine could not reach a pose


@with_config(_STRICT)
class Studies(TypedDict):
    reachable_workspace: ReachableWorkspace
    height_calibration: HeightCalibration | None
    angle_conventions: list[AngleConventions]
    workspace: Workspace | None
    joint_orders: list[JointOrderCase]
    joint_couplings: list[CouplingCase]  # empty: not run (the CI profile)
    workspace_validation: WorkspaceValidation | None
    hard_cases: list[HardCase]  # empty: not run (the CI profile)


@with_config(_STRICT)
class AnalyticalChoice(TypedDict):
    beam: str
    shear: str
    joint_ends: str
    elements: int
    platform_inertia: str
    setting: str  # label of the chosen candidate
    chosen: bool  # false: the scene's own [analytical], checked
    worst_error_percent: FiniteFloat
    seconds_per_pose: FiniteFloat
    met: bool


@with_config(_STRICT)
class FemChoice(TypedDict):
    mesh_size_mm: FiniteFloat
    chosen: bool  # false: the scene's own mesh_size_mm, checked
    estimated_error_percent: FiniteFloat | None  # null without a refinement study
    seconds_per_pose: FiniteFloat | None
    met: bool


@with_config(_STRICT)
class Candidate(TypedDict):
    setting: str
    worst_error_percent: FiniteFloat
    seconds_per_pose: FiniteFloat


@with_config(_STRICT)
class Fidelity(TypedDict):
    """What the scene asked ([fidelity]) and what the run chose to meet it."""

    modes: int
    tolerance_percent: FiniteFloat
    met: bool
    analytical: AnalyticalChoice
    fem: FemChoice
    reason: str
    candidates: list[Candidate]


@with_config(_STRICT)
class Results(TypedDict):
    schema: int
    profile: Literal["full", "ci"]
    scene: SceneSummary
    environment: Environment
    fidelity: Fidelity
    cases: list[Case]
    studies: Studies
    fixture_note: str | None  # set only by the report test fixture


_RESULTS = TypeAdapter(Results)


def validated(results: dict, where: str = "results") -> Results:
    """The results checked against the schema; ValueError with one line naming the first
    offending field (and its value)."""
    version = results.get("schema") if isinstance(results, dict) else None
    if version != SCHEMA_VERSION:
        raise ValueError(f"{where}: results schema {version!r}, this version reads schema "
                         f"{SCHEMA_VERSION}: rerun `make` to regenerate it")
    try:
        out = _RESULTS.validate_python(results)
    except ValidationError as exc:
        errors = exc.errors(include_url=False)
        first = errors[0]
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        value = "" if first["type"] == "missing" else f", got {_short(first.get('input'))}"
        message = first["msg"].removeprefix("Value error, ")
        raise ValueError(f"{where}: {_location(first['loc'])}: {message[:1].lower()}"
                         f"{message[1:]}{value}{more}") from None
    if not out["cases"]:
        raise ValueError(f"{where}: cases: the results hold no case")
    try:
        distinct_stems((case["name"] for case in out["cases"]), "case name")
    except UnsafeName as exc:
        raise ValueError(f"{where}: cases: {exc}") from None
    return out


def read(path) -> Results:
    """Load and check a results file; ValueError (one line, naming the path) otherwise."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ValueError(f"{path}: results file not found") from None
    except OSError as exc:
        raise ValueError(f"{path}: cannot read results file ({exc.strerror})") from None
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path}: not a results file (byte {exc.start} is not UTF-8 text)") \
            from None
    depth = nesting_depth(text)
    if depth > MAX_DEPTH:
        raise ValueError(f"{path}: not a results file (JSON nested {depth} deep; a results "
                         f"file nests {MAX_DEPTH} at most)")
    try:
        raw = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path}: not valid JSON (line {exc.lineno}, column {exc.colno}: "
                         f"{exc.msg})") from None
    if not isinstance(raw, dict):
        raise ValueError(f"{path}: expected a JSON object at the top level")
    return validated(raw, str(path))


def nesting_depth(text: str) -> int:
    """How deep the arrays and objects of a JSON text nest (brackets inside strings ignored),
    found in one linear scan without parsing, so no nesting can exhaust the parser's stack."""
    bare = _STRINGS.sub("", text).encode("utf-8", "replace")
    codes = np.frombuffer(bare, np.uint8)
    step = np.isin(codes, _OPEN).astype(np.int64) - np.isin(codes, _CLOSE)
    return int(np.cumsum(step).max(initial=0))


_STRINGS = re.compile(r'"(?:[^"\\]|\\.)*"?', re.DOTALL)
_OPEN, _CLOSE = (np.frombuffer(b"[{", np.uint8), np.frombuffer(b"]}", np.uint8))


def dumps(results: Results) -> str:
    return json.dumps(results, indent=1, allow_nan=False) + "\n"


def _location(loc) -> str:
    text = ""
    for token in loc:
        text += f"[{token}]" if isinstance(token, int) else (f".{token}" if text else token)
    return text


def _short(value, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


# ---------------------------------------------------------------- reading rules, once
def best_error(pair: Pair) -> float:
    """A pair's error against the best FEM value there is: the h -> 0 limit when the run has
    one, else the FEM at the compared mesh."""
    vs_limit = pair["error_vs_reference_percent"]
    return pair["error_percent"] if vs_limit is None else vs_limit


def worst_in_mode_ranges(errors) -> tuple[float | None, float | None]:
    """Worst |error| of modes 1..LOW_MODES and of the modes above, from (1-based mode, error)
    items (None where a range has none): the paper's way of reading its errors."""
    low, high = [], []
    for mode, value in errors:
        (low if mode <= LOW_MODES else high).append(abs(value))
    return (max(low) if low else None), (max(high) if high else None)


def worst_by_mode_range(pairs: list[Pair], error=best_error
                        ) -> tuple[float | None, float | None]:
    """worst_in_mode_ranges of the pairs, by FEM mode."""
    return worst_in_mode_ranges((p["fem_mode"], error(p)) for p in pairs)


def mode_ranges(pairs: list[Pair]) -> tuple[str, str]:
    """Labels of the two ranges, e.g. ("f1–f3", "f4–f6")."""
    top = max((p["fem_mode"] for p in pairs), default=LOW_MODES + 1)
    return f"f1–f{LOW_MODES}", (f"f{LOW_MODES + 1}–f{top}" if top > LOW_MODES + 1
                                else f"f{LOW_MODES + 1}")
