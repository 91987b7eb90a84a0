"""The records of one case: the scene summary, the pose, both models' frequencies and modes, the
pairs, the FEM refinement and the per-case studies (`results.schema` assembles the file)."""
from __future__ import annotations

from typing import Literal

from pydantic import FiniteFloat, with_config
from typing_extensions import TypedDict  # pydantic reads it on Python < 3.12

from .tool_records import ToolResponse
from .types import STRICT, CaseName, Frequencies, Frequency, Hz, Motion, RelativePath
from .uncertainty_records import UncertaintyCase


@with_config(STRICT)
class Manipulator(TypedDict):
    base_radius_mm: FiniteFloat
    platform_radius_mm: FiniteFloat
    leg_diameter_mm: FiniteFloat
    platform_thickness_mm: FiniteFloat
    platform_shape: str
    leg_angles_deg: list[FiniteFloat]
    architecture: str  # "3-RPS" or "3-PRS" (analytical.architecture)
    actuator: str  # the locked actuator's variable: "leg length" or "slider travel"
    actuator_range_mm: list[FiniteFloat]  # its [min, max]: Eq. (25)'s L, or a 3-PRS's stroke
    leg_length_range_mm: list[FiniteFloat]  # the legs' [shortest, longest], joint to joint
    rail_angle_deg: FiniteFloat | None  # a 3-PRS's rails from the base plane (None: 3-RPS)
    s_joint_max_deg: FiniteFloat
    r_joint_max_deg: FiniteFloat
    base_joint: str
    platform_joint: str
    youngs_modulus_gpa: FiniteFloat
    shear_modulus_gpa: FiniteFloat
    poisson_ratio: FiniteFloat
    density_kg_m3: FiniteFloat
    payload: Payload
    leg: LegProfile
    stiffness: Stiffness


@with_config(STRICT)
class LegProfile(TypedDict):
    """[leg]: all 0 for the uniform solid leg of leg_diameter_mm."""
    housing_length_mm: FiniteFloat
    housing_outer_diameter_mm: FiniteFloat
    housing_inner_diameter_mm: FiniteFloat
    rod_outer_diameter_mm: FiniteFloat
    rod_inner_diameter_mm: FiniteFloat


@with_config(STRICT)
class Stiffness(TypedDict):
    """[stiffness]: 0 is rigid."""
    actuator_axial_n_per_um: FiniteFloat
    base_joint_translational_n_per_um: FiniteFloat
    base_joint_rotational_nm_per_urad: FiniteFloat
    platform_joint_translational_n_per_um: FiniteFloat
    platform_joint_rotational_nm_per_urad: FiniteFloat


@with_config(STRICT)
class Payload(TypedDict):
    mass_kg: FiniteFloat  # 0: none
    centre_mm: list[FiniteFloat]  # platform frame, from o
    inertia_kg_m2: list[FiniteFloat]  # principal, about its own centre, platform axes


@with_config(STRICT)
class AnalyticalSettings(TypedDict):
    elements: int
    beam: str
    platform_inertia: str
    modes: int


@with_config(STRICT)
class FemSettings(TypedDict):
    mesh_size_mm: FiniteFloat
    refinement_mm: list[FiniteFloat]
    rim_factor: FiniteFloat
    rim_zone_mm: FiniteFloat
    platform: str
    coupling: str
    legs: str  # "harmonic" (Fourier harmonics on a meridian mesh) or "tetrahedra"


@with_config(STRICT)
class Calibrated(TypedDict):
    name: str
    value: str
    reason: str


@with_config(STRICT)
class SceneSummary(TypedDict):
    name: str
    path: str
    sha256: str
    manipulator: Manipulator
    analytical: AnalyticalSettings
    fem: FemSettings
    calibrated: list[Calibrated]
    warnings: list[str]  # a machine that strains a shared idealisation (plausibility rules)


@with_config(STRICT)
class Environment(TypedDict):
    project_version: str | None  # the installed package's version
    git_commit: str | None  # of the source tree, "+ local changes" when it was not clean
    python: str
    platform: str
    machine: str
    cpu_count: int | None
    date: str
    versions: dict[str, str | None]


@with_config(STRICT)
class Pose(TypedDict):
    height_mm: FiniteFloat
    height_origin: Literal["calibrated", "scene"]
    azimuth_deg: FiniteFloat
    tilt_deg: FiniteFloat
    centre_mm: list[FiniteFloat]
    base_points_mm: list[list[FiniteFloat]]  # base joint centres B_i
    platform_points_mm: list[list[FiniteFloat]]  # platform joint centres A_i
    leg_lengths_mm: list[FiniteFloat]
    actuation_mm: list[FiniteFloat]  # the locked actuators: leg lengths, or sliders' travels
    s_joint_angles_deg: list[FiniteFloat]
    r_joint_angles_deg: list[FiniteFloat]


@with_config(STRICT)
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


@with_config(STRICT)
class AnalyticalRecord(TypedDict):
    elements: int
    beam: str
    shear: str  # Timoshenko shear coefficient: cowper | hutchinson
    joint_ends: str  # beam | solid (end zones condensed from a solid, joint_ends/)
    legs: str  # beam | solid (every part condensed whole, joint_ends/leg_part.py)
    platform_inertia: str
    frequencies_hz: Hz
    timings: dict[str, FiniteFloat]  # seconds; "total": one pose
    dofs: int
    platform_motion: Motion


@with_config(STRICT)
class FemRecord(TypedDict):
    frequencies_hz: Hz
    dofs: int
    raw_dofs: int
    mesh_size_mm: FiniteFloat
    platform: str
    coupling: str
    timings: dict[str, FiniteFloat]  # seconds: mesh, assemble, solve, total
    mesh_cache_hit: bool  # then "mesh" timed a cache read
    cache_hit: bool  # the whole result came from the result cache
    platform_motion: Motion
    min_scaled_jacobian: FiniteFloat | None  # worst curved element of the mesh (1 = ideal)


@with_config(STRICT)
class CaseAnalytical(AnalyticalRecord):
    leg_axis_stations: list[FiniteFloat]  # fractions of B_i -> A_i
    leg_axis_shapes: list[list[list[list[FiniteFloat]]]]  # [leg][station][xyz][mode], m


@with_config(STRICT)
class CaseFem(FemRecord):
    vtu: RelativePath  # mode shapes of the solid, relative to results.json
    pvd: RelativePath  # ParaView collection stepping through the modes, relative


@with_config(STRICT)
class Paper(TypedDict):
    fea_hz: Frequencies | None
    theory_hz: Frequencies | None
    error_percent: list[FiniteFloat] | None  # recomputed: theory / FEA - 1
    printed_error_percent: list[FiniteFloat] | None
    printed_error_note: str | None  # where the printed errors do not follow from the rows


@with_config(STRICT)
class Refinement(TypedDict):
    """The FEM at a sequence of mesh sizes, extrapolated to h -> 0 (Richardson)."""
    mesh_sizes_mm: list[FiniteFloat]
    effective_mesh_sizes_mm: list[FiniteFloat]
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
    richardson_error_percent: list[list[FiniteFloat]]  # [size][mode], Richardson's estimate
    gci_percent: list[list[FiniteFloat]]  # [size][mode], grid convergence index (Roache)
    gci_order: list[FiniteFloat]  # per mode: the order the GCI used
    gci_observed_order: list[FiniteFloat | None]  # per mode: Celik's, from the 3 finest sizes
    gci_safety_factor: list[FiniteFloat]  # per mode: 1.25 (observed order) or 3 (assumed)
    gci_extrapolated_hz: Frequencies
    gci_percent_max: list[FiniteFloat]  # per size, over the modes
    estimated_error_percent: list[list[FiniteFloat]]  # [size][mode]: max(Richardson, GCI)
    estimated_error_percent_max: list[FiniteFloat]


@with_config(STRICT)
class ModelVariant(AnalyticalRecord):
    median_seconds: FiniteFloat
    pairs: list[Pair]


@with_config(STRICT)
class FemVariant(FemRecord):
    pairs: list[Pair]  # against the case's FEM: "analytical" here is the variant
    shift_percent: list[FiniteFloat]
    estimated_error_percent: list[FiniteFloat]  # its own, two meshes: max(Richardson, GCI)
    gci_percent: list[FiniteFloat]  # its two-mesh GCI (factor 3), per mode


@with_config(STRICT)
class ElementConvergence(TypedDict):
    elements: list[int]
    beam: str
    frequencies_hz: list[Hz]  # [s][mode]


@with_config(STRICT)
class SpeedPoint(TypedDict):
    model: Literal["analytical", "fem"]
    setting: str
    seconds: FiniteFloat  # analytical: median; FEM: one run
    worst_error_percent: FiniteFloat
    single_run: bool
    mesh_from_cache: bool | None


ModelVariants = dict[str, ModelVariant]  # setting label -> the model against the case's FEM
ElementConvergences = dict[str, ElementConvergence]  # beam theory -> its convergence in s


@with_config(STRICT)
class FemIdealisations(TypedDict):
    """The FEM's own idealisations against its default (studies.fem_idealisations)."""
    variants: dict[str, FemVariant]  # the solved ones, by label
    unsolved: dict[str, str]  # the ones that could not be solved, and why


@with_config(STRICT)
class CaseCore(TypedDict):
    """What every case holds, whatever studies ran."""
    name: CaseName
    description: str
    pose: Pose
    analytical: CaseAnalytical
    fem: CaseFem
    pairs: list[Pair]
    paper: Paper | None
    mac_matrix: list[list[FiniteFloat]]  # [analytical mode][FEM mode]
    fem_estimated_error_percent: list[FiniteFloat] | None  # max(Richardson, GCI) of its size
    fem_gci_percent: list[FiniteFloat] | None  # grid convergence index of its size, per mode
    fem_reference_hz: Frequencies | None
    fem_refinement: Refinement | None


@with_config(STRICT)
class Case(CaseCore, total=False):
    """A case: its core and the records of the case studies, each declared by its study
    (`results.declare.Record`, registry `studies.RECORDS`); the records of the project's own
    case studies typed here, None where a study did not run."""
    models: ModelVariants | None
    element_convergence: ElementConvergences | None
    fem_variants: FemIdealisations | None
    speed_vs_error: list[SpeedPoint] | None
    tool_response: ToolResponse | None  # None: the scene asks no dynamic compliance
    uncertainty: UncertaintyCase | None  # None: the scene declares no [uncertainty]
