"""The records of `make bench` (bench/bench.json), typed once: what each benchmark reports, in
seconds (medians of repeated runs), mesh sizes in mm."""
from __future__ import annotations

from typing import Any

from pydantic import with_config
from typing_extensions import NotRequired, TypedDict  # pydantic reads it on Python < 3.12

from results.outputs import Output
from results.types import STRICT


@with_config(STRICT)
class Timing(TypedDict):
    median_seconds: float
    min_seconds: float
    runs: int
    plain_eigh_seconds: float  # scipy.linalg.eigh(K, M) of the pose's own matrices, median
    vs_plain_eigh: float  # median_seconds / plain_eigh_seconds, timed alternately


Timings = dict[str, Timing]  # setting ("s=3", "s=5, solid ends") -> its time per pose


@with_config(STRICT)
class Peak(TypedDict):
    """One core's peak double-precision rate: clock times flops a cycle."""
    gflops: float
    clock_ghz: float
    flops_per_cycle: int
    vector_units: str  # the flags that set it ("avx2 fma")


@with_config(STRICT)
class BestModel(TypedDict):
    """The most accurate analytical setting, batched over the map's poses on one core, per
    stage (pipeline/bench_kernel.py), with its flops and the ratio to the flop floor."""
    setting: str
    poses: int
    matrix_size: int
    modes: int
    runs: int
    pose_seconds: float  # the whole: assembly, standard form, eigenvalues
    assembly_pose_seconds: float
    standard_form_pose_seconds: float
    eigenvalues_pose_seconds: float
    flops_per_pose: float  # standard form and eigenvalues (assembly not counted)
    gflops_per_core: float  # flops_per_pose / pose_seconds
    solve_gflops_per_core: float | None  # flops_per_pose / (standard form + eigenvalues)
    standard_form_gflops: float | None
    eigenvalues_gflops: float | None
    kernel: str  # the eigenvalues' ("lanes": analytical/lanes.py; LAPACK without numba)
    lapack_eigenvalues_pose_seconds: float  # LAPACK's ?syevd one pose a call, same run
    eigenvalues_vs_lapack: float | None
    peak: Peak | None
    floor_pose_seconds: float | None  # flops_per_pose at the core's peak
    vs_floor: float | None  # pose_seconds / floor_pose_seconds


@with_config(STRICT)
class DynamicMapBench(TypedDict):
    """The least dynamic stiffness at the tool over the 10,000-pose map's reachable poses (the
    scene's modes, LINES lines) against the frequency map of the same grid, both on one core,
    and against the poses' frequencies alone (assembly, standard form, eigenvalues), timed
    alternately; medians."""
    poses: int
    lines: int
    modes: int
    modes_summed: int
    runs: int
    dynamic_median_seconds: float
    dynamic_seconds: list[float]
    frequency_map_median_seconds: float
    frequency_map_seconds: list[float]
    frequencies_only_median_seconds: float
    frequencies_only_seconds: list[float]
    vs_frequency_map: float
    vs_frequencies_only: float


@with_config(STRICT)
class Grid(TypedDict):
    heights: int
    rings: int
    azimuths: int
    poses: int
    distinct_poses: int


@with_config(STRICT)
class MapBench(TypedDict):
    """The 10,000-pose map against as many plain eigh calls, timed alternately."""
    grid: Grid
    modes: int
    matrix_size: int
    workers: int
    openblas_num_threads: str | None
    map_median_seconds: float
    map_seconds: list[float]
    plain_eigh_calls: int
    plain_eigh_median_seconds: float
    plain_eigh_seconds: list[float]
    ratio: float
    poses_with_shapes: int
    steps_matched_by_shape: int
    steps: int
    crossings: int
    runs: int


@with_config(STRICT)
class LobesBench(TypedDict):
    """Issue 52: one pose's lobe diagram against one pose of the frequency map of the same
    machine, one core, timed alternately; the workspace stability map once
    (pipeline/bench_lobes.py)."""
    scene: str
    case: str
    runs: int
    openblas_num_threads: str | None
    method: str
    speeds: int
    tool_modes: int
    lobes_seconds: list[float]
    lobes_median_seconds: float
    map_poses: int
    map_median_seconds: float
    map_pose_seconds: float
    ratio: float  # one pose's lobes / one pose of the frequency map
    stability_map_seconds: NotRequired[float]
    stability_map_poses: NotRequired[int]
    stability_map_speeds: NotRequired[int]
    stability_map_estimated_seconds: NotRequired[float]
    stability_map_announced: NotRequired[str]


@with_config(STRICT)
class RealLegsMap(TypedDict):
    """Issue 51: the 10,000-pose map of a real-leg machine with its solid legs against its
    beam legs, one core, timed alternately (pipeline/bench_real_legs.py); the one-off build."""
    scene: str
    poses: int
    modes: int
    runs: int
    openblas_num_threads: str | None
    solid_setting: str
    beam_setting: str
    part_modes: int  # modal coordinates a solid part keeps (0: every station)
    coordinates_kept: int  # n a pose with every station
    coordinates_reduced: int  # n a pose as the map solves it
    beam_coordinates: int
    reduction_error: float  # the reduction's own, at its check poses (relative)
    build_seconds: float  # every piece, the housing and the reduction's choice, empty cache
    cache_entries: int
    announced: str  # what the run said before building
    solid_median_seconds: float
    solid_seconds: list[float]
    beam_median_seconds: float
    beam_seconds: list[float]
    solid_pose_seconds: float
    beam_pose_seconds: float
    ratio: float  # solid / beam, the "at most 3x"


@with_config(STRICT)
class FemTiming(TypedDict):
    mesh_size_mm: float
    dofs: int
    median_seconds: float
    min_seconds: float
    median_timings: dict[str, float]  # per stage of the solve
    runs: int


FemTimings = dict[str, FemTiming]  # "<h>mm" -> the FEM's time per pose at that mesh size


@with_config(STRICT)
class SweepBench(TypedDict):
    """The CI-size workspace-validation sweep from an empty cache, per worker count (keyed by
    the count, "1", "2"; until schema 14's change it was workers_<n>_median_seconds)."""
    poses: int
    runs: int
    models: int
    median_seconds: dict[str, float]  # worker count -> median wall time
    seconds: dict[str, list[float]]
    speedup: float  # fewest workers' median / most workers'


EstimatedErrors = dict[str, float]  # "<h>mm" -> the refinement study's worst estimated error, %


@with_config(STRICT)
class UncertaintyBench(TypedDict):
    """One model run of the input-uncertainty propagation against one pose of the batched
    frequencies of the scene's own machine, at the case; medians of alternate runs."""
    case: str
    inputs: int
    samples: int
    model_runs: int
    runs: int
    run_seconds: float
    batched_pose_seconds: float
    propagated_seconds: list[float]
    batched_seconds: list[float]
    run_vs_batched_pose: float


@with_config(STRICT)
class KilledWorker(TypedDict):
    """The cluster's sweep with one worker killed part-way (pipeline/bench_distributed.py)."""
    kill_after_results: int
    stored_before_kill: int
    stored_before_kill_computed_again: int  # must be 0
    computed_again: int  # tasks lost with the killed worker, computed again
    never_computed: int  # must be 0
    difference: float  # largest relative difference from the one-process results
    rerun_to_compute: int  # the same sweep again on the same cache: must be 0


@with_config(STRICT)
class DistributedBench(TypedDict):
    """A 10^5-pose sweep in tasks of >= 1,000 poses: one process against a local Dask cluster
    (each from an empty cache), and the cluster with a worker killed."""
    poses: int
    reached: int
    tasks: int
    poses_per_task: int
    workers: int
    modes: int
    one_process_seconds: float
    cluster_start_seconds: float
    cluster_seconds: float
    overhead: float  # workers * cluster_seconds / one_process_seconds - 1
    speedup: float  # one_process_seconds / cluster_seconds
    one_process_task_seconds: float  # the tasks' own time, summed, in one process
    cluster_task_seconds: float  # the same in the workers
    contention: float  # cluster_task_seconds / one_process_task_seconds - 1
    dask_overhead: float  # workers * cluster_seconds / cluster_task_seconds - 1
    difference: float  # largest relative difference from the one-process results
    killed: KilledWorker


@with_config(STRICT)
class Machine(TypedDict):
    """The machine a timing was taken on (two runs compare only on one machine)."""
    python: str
    platform: str
    processor: str
    cpu_model: str | None
    cpu_count: int | None


@with_config(STRICT)
class Revision(TypedDict):
    """The checkout's commit and whether its tracked files differ from it (None outside a
    checkout or without git)."""
    commit: str | None
    changed: bool | None


@with_config(STRICT)
class HistoryLine(Revision):
    """One run of `make bench` in bench/history.jsonl."""
    date: str | None
    machine: Machine
    figures: dict[str, float]  # the headline figures


@with_config(STRICT)
class Previous(TypedDict):
    """Each headline figure now over the newest earlier run of another commit, same machine."""
    commit: str | None
    changed: bool | None
    date: str | None
    ratios: dict[str, float]


@with_config(STRICT)
class Reference(TypedDict):
    """The per-pose model against each stored release (pipeline/bench_reference.json)."""
    measured: Any
    now_over_then: dict[str, dict[str, float]]


@with_config(STRICT)
class BenchFile(TypedDict):
    record: str
    schema: int
    machine: Machine
    date: str
    case: str
    analytical: Timings
    analytical_pose_seconds_median: float
    analytical_runs: int
    analytical_pose_vs_plain_eigh: float
    map: MapBench
    map_vs_plain_eigh: float
    map_scene_modes: MapBench
    map_scene_modes_vs_plain_eigh: float
    map_one_core: MapBench
    map_one_core_vs_plain_eigh: float
    best_model: BestModel
    best_model_pose_seconds: float
    dynamic_map: DynamicMapBench
    dynamic_map_vs_frequency_map: float
    real_legs_map: NotRequired[RealLegsMap]  # a checkout with scenes/actuator-legs.toml
    real_legs_map_vs_beam: NotRequired[float]
    lobes: NotRequired[LobesBench]  # a checkout with scenes/3prs-head.toml
    lobes_pose_vs_map_pose: NotRequired[float]
    uncertainty: NotRequired[UncertaintyBench]  # a scene with [uncertainty]
    uncertainty_run_vs_batched_pose: NotRequired[float]
    fem: NotRequired[FemTimings]  # without --skip-fem
    fem_pose_seconds_median: NotRequired[float]
    fem_runs: NotRequired[int]
    fem_legs: NotRequired[str]
    fem_tetrahedra: NotRequired[FemTimings]  # harmonic legs: the tetrahedra timed beside
    fem_pose_seconds_vs_tetrahedra: NotRequired[float]
    sweep: NotRequired[SweepBench]
    sweep_speedup: NotRequired[float]
    fem_estimated_error_percent: NotRequired[EstimatedErrors]  # a validation's, if left
    distributed: NotRequired[DistributedBench]
    distributed_overhead: NotRequired[float]
    commit: str | None
    changed: bool | None
    previous: Previous | None
    reference: Reference | None


BENCH = Output("bench.json", "bench", 1, BenchFile, "make bench",
               "Timings (medians of repeated runs, one core unless said) of the analytical "
               "model per pose against a plain eigh of its own matrices, the 10,000-pose maps, "
               "the best model's stages and flops, the dynamic-stiffness map, the uncertainty "
               "propagation, the FEM per mesh size and the distributed sweep; each headline "
               "figure against the previous commit's run on the same machine. Beside it, "
               "history.jsonl, one line a run.")
