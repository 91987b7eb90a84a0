"""One case, both models: solve, sample shapes on shared points, pair, and tabulate errors."""
from __future__ import annotations

import math
import os
import time
from copy import copy
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Generic, Literal, Mapping, Protocol, TypeVar

import numpy as np

import results
from analytical.kinematics import PoseGeometry
from analytical.modal import leg_axis_displacements, leg_axis_twists, platform_motion
from analytical.model import analyse
from analytical.params import ModelOptions, Pose
from analytical.substructure import model_coordinates
from common.settings import as_dict
from fem_reference.model import legs_for
from runtime.cache import ResultCache
from scene import Scene
from solvers.pairing import pair_modes

# Shared points for MAC: eleven stations along every leg axis, joint centres included.
STATIONS = np.linspace(0.0, 1.0, 11)
# what a station holds for the pairing: the axis translation, and the sections' twist times the
# leg radius (the wall's displacement by it): a leg's torsion modes move no point of its axis
STATION_COMPONENTS = ("x", "y", "z", "radius x twist")
EXTRA_MODES = 4  # asked beyond the reported ones, so a pair split across the cut is found


def station_vector(translations: np.ndarray, twists: np.ndarray, radius: float) -> np.ndarray:
    """(legs * stations * 4, modes) from translations (legs, stations, 3, modes) and twists
    (legs, stations, modes): the shapes the pairing compares (STATION_COMPONENTS)."""
    both = np.concatenate([translations, radius * twists[:, :, None, :]], axis=2)
    return both.reshape(-1, both.shape[-1])


R = TypeVar("R", results.AnalyticalRecord, results.FemRecord)


@dataclass(frozen=True)
class Solve(Generic[R]):
    """One model's modes at one pose: its results record (every computed mode) and its shapes
    sampled at the STATIONS of every leg axis, (legs * stations * 4, modes), for the pairing
    (`station_vector`)."""

    record: R  # results.AnalyticalRecord or results.FemRecord
    station_shapes: np.ndarray
    vtu: Path | None = None  # the FEM's mode file in the cache

    def reported(self, count: int) -> R:
        """The record cut to the first `count` modes."""
        cut = copy(self.record)
        cut["frequencies_hz"] = self.record["frequencies_hz"][:count]
        cut["platform_motion"] = [row[:count] for row in self.record["platform_motion"]]
        return cut

    def leg_axis_shapes(self, count: int) -> list:
        """[leg][station][xyz][mode] of the first `count` modes."""
        shapes = self.station_shapes[:, :count]
        return shapes.reshape(-1, len(STATIONS), len(STATION_COMPONENTS),
                              shapes.shape[-1])[:, :, :3].tolist()


def scene_coordinates(scene: Scene, options: ModelOptions) -> int:
    """The analytical model's coordinates (its number of modes) with these options: the
    joints' free rotations and six per interior node of every leg, plus the platform's six."""
    return model_coordinates(scene.manipulator, options)


class Posed(Protocol):
    """What `analytical_case` reads of a case: its pose (a scene case, or a study's pose)."""

    @property
    def pose(self) -> Pose: ...


def analytical_case(scene: Scene, case: Posed,
                    options: ModelOptions) -> Solve[results.AnalyticalRecord]:
    """Frequencies, platform motion, sampled shapes and wall time of the substructure model."""
    opts = replace(options,
                   modes=min(options.modes + EXTRA_MODES, scene_coordinates(scene, options)))
    start = time.perf_counter()
    res = analyse(scene.manipulator, case.pose, opts)
    seconds = time.perf_counter() - start
    shapes = station_vector(
        leg_axis_displacements(res.model, res.geometry.leg_frames, res.modal.shapes, STATIONS),
        leg_axis_twists(res.model, res.geometry.leg_frames, res.modal.shapes, STATIONS),
        0.5 * scene.manipulator.leg_diameter)
    record = results.AnalyticalRecord(
        elements=options.elements, beam=options.beam, shear=options.shear,
        joint_ends=options.joint_ends, legs=options.legs,
        platform_inertia=options.platform_inertia,
        frequencies_hz=[float(f) for f in res.frequencies_hz],
        timings={"total": seconds}, dofs=int(res.model.stiffness.shape[0]),
        platform_motion=platform_motion(res.model, res.modal.shapes).tolist())
    return Solve(record, shapes)


def fem_options(scene: Scene, mesh_size: float | None = None, platform: str | None = None,
                coupling: str | None = None, modes: int | None = None,
                legs: str | None = None):
    """The scene's FEM options (built once, at load) at one mesh size, with optional
    platform/coupling/legs/mode-count overrides; EXTRA_MODES are added for the pairing."""
    options = scene.fem if mesh_size is None else scene.fem.with_size(mesh_size)
    legs = legs_for(platform, legs)
    changes: dict[str, Any] = {k: v for k, v in {"platform": platform, "coupling": coupling,
                                                 "legs": legs}.items() if v is not None}
    changes["modes"] = (modes if modes is not None else scene.analytical.modes) + EXTRA_MODES
    return replace(options, **changes)


def with_cache_dir(scene: Scene, directory: str | os.PathLike) -> Scene:
    """The scene whose analytical models keep their solid end zones under the run's cache
    directory (`ModelOptions.cache_dir`: every setting derived from scene.analytical, in this
    process and on the workers, carries it), as the FEM keeps its meshes there
    (`fem_runtime`)."""
    return replace(scene, analytical=replace(scene.analytical, cache_dir=str(directory)))


def in_parallel(scene: Scene, workers: int) -> Scene:
    """The scene whose FEM solves each take 1 / `workers` of the memory limit (`FemRuntime.
    memory_share`): `workers` of them run at once on a sweep's processes."""
    share = 1.0 / max(1, int(workers))
    return replace(scene, fem_runtime=replace(scene.fem_runtime, memory_share=share))


def fem_runtime(scene: Scene, cache: ResultCache | None = None, use_cache: bool = True):
    """How the scene's FEM solves run: its DOF guard, the mesh cache beside the result cache."""
    return replace(scene.fem_runtime, use_cache=use_cache,
                   cache_dir=None if cache is None else cache.directory / "meshes")


def fem_case(scene: Scene, geometry: PoseGeometry, cache: ResultCache, mesh_size: float,
             platform: str | None = None, coupling: str | None = None,
             legs: str | None = None,
             max_dofs: int | None = None) -> Solve[results.FemRecord]:
    """The FEM reference of one pose at one mesh size, through the result cache.

    The cache key is every input that changes the answer, taken whole: the manipulator, the
    pose geometry, the complete FEM options (`dataclasses.asdict`, so a new option can never be
    left out of the key) and the sampling stations. `max_dofs` lowers the scene's DOF guard
    for this solve (an optional study's budget), FemError when the mesh would exceed it.
    """
    from fem_reference import solve_pose

    options = fem_options(scene, mesh_size, platform=platform, coupling=coupling, legs=legs)
    payload = fem_cache_payload(scene.manipulator, geometry, options)

    def compute():
        runtime = fem_runtime(scene, cache)
        if max_dofs is not None:
            runtime = replace(runtime, max_dofs=min(runtime.max_dofs, max_dofs))
        result = solve_pose(scene.manipulator, geometry, options, runtime)
        shapes = station_vector(result.leg_axis_displacements(STATIONS),
                                result.leg_axis_twists(STATIONS),
                                0.5 * scene.manipulator.leg_diameter)
        vtu = cache.directory / "tmp" / f"mode-{os.getpid()}-{time.time_ns()}.vtu"
        vtu.parent.mkdir(parents=True, exist_ok=True)
        result.write_vtu(vtu)
        value = {
            "frequencies_hz": [float(f) for f in result.frequencies_hz],
            "dofs": int(result.dofs),
            "raw_dofs": int(result.raw_dofs),
            "mesh_size_m": float(result.mesh_size),
            "platform": options.platform,
            "coupling": options.coupling,
            "timings": {k: float(v) for k, v in result.timings.items()},
            "mesh_cache_hit": bool(result.cache_hit),  # then "mesh" timed a cache read
            "platform_motion": result.platform_motion.tolist(),
            "station_shapes": shapes.tolist(),
            "min_scaled_jacobian": (float(result.min_quality)
                                    if math.isfinite(result.min_quality) else None),
        }
        return value, {".vtu": vtu}

    try:
        value, key, hit = cache.get_or_compute("fem", payload, compute, required=FEM_CACHED)
    finally:
        for leftover in (cache.directory / "tmp").glob(f"mode-{os.getpid()}-*.vtu"):
            leftover.unlink(missing_ok=True)
    record = results.FemRecord(
        frequencies_hz=value["frequencies_hz"], dofs=value["dofs"], raw_dofs=value["raw_dofs"],
        mesh_size_mm=value["mesh_size_m"] * 1e3, platform=value["platform"],
        coupling=value["coupling"], timings=value["timings"],
        mesh_cache_hit=value["mesh_cache_hit"], platform_motion=value["platform_motion"],
        min_scaled_jacobian=value["min_scaled_jacobian"], cache_hit=hit)
    return Solve(record, np.asarray(value["station_shapes"]),
                 cache.side_file("fem", key, ".vtu"))


# what a cached FEM value holds (an entry lacking any of them is recomputed)
FEM_CACHED = ("frequencies_hz", "dofs", "raw_dofs", "mesh_size_m", "platform", "coupling",
              "timings", "mesh_cache_hit", "platform_motion", "station_shapes",
              "min_scaled_jacobian")


def fem_cache_payload(manipulator, geometry: PoseGeometry, options) -> Mapping[str, object]:
    """Everything that determines a FEM result, whole (see `fem_case`): the options object
    entire, so a new option is in the key without a line here (tests/test_common.py). The rim
    grading (`rim_*`) shapes only tetrahedral meshes; changing it with harmonic legs costs a
    recompute, never a stale answer."""
    return {"manipulator": as_dict(manipulator), "geometry": as_dict(geometry),
            "options": as_dict(options), "stations": STATIONS.tolist(),
            "station_components": list(STATION_COMPONENTS)}


def reference_error(row: results.Pair) -> float:
    """A row's error against the FEM limit, % (the table was made with `reference_hz`)."""
    error = row["error_vs_reference_percent"]
    if error is None:
        raise ValueError("error_table: this row was made without the FEM limit")
    return error


def model_reading(rows: list[results.Pair],
                  error: Literal["error_percent", "error_vs_reference_percent"] = "error_percent"
                  ) -> results.ModelReading:
    """A model's frequencies, errors (the `error` column of `error_table`) and MACs, in the
    order of `rows`."""
    errors = [r[error] for r in rows]
    if any(e is None for e in errors):
        raise ValueError(f"model_reading: the rows have no {error} (no reference given)")
    return results.ModelReading(frequencies_hz=[r["f_analytical_hz"] for r in rows],
                                error_percent=[float(e) for e in errors if e is not None],
                                mac=[r["mac"] for r in rows])


def error_table(analytical: Solve, fem: Solve, count: int, fem_error_percent=None,
                reference_hz=None) -> list[results.Pair]:
    """Rows of the comparison (results.Pair): FEM mode k paired with the analytical mode of the
    same shape; against the FEM's h -> 0 limit too when `reference_hz` is given."""
    a_hz = np.asarray(analytical.record["frequencies_hz"])
    f_hz = np.asarray(fem.record["frequencies_hz"])
    pairs = pair_modes(analytical.station_shapes, a_hz, fem.station_shapes, f_hz, count)
    rows = []
    for p in pairs:
        k, j = p.reference_mode, p.model_mode
        rows.append(results.Pair(
            fem_mode=k + 1, analytical_mode=j + 1,
            f_fem_hz=float(f_hz[k]), f_analytical_hz=float(a_hz[j]),
            error_percent=float(p.error_percent(a_hz, f_hz)), mac=float(p.mac),
            repeated=bool(p.repeated), group=int(p.group),
            fem_estimated_error_percent=(None if fem_error_percent is None
                                         else float(fem_error_percent[k])),
            f_reference_hz=None if reference_hz is None else float(reference_hz[k]),
            error_vs_reference_percent=(None if reference_hz is None else
                                        float(100 * (a_hz[j] / reference_hz[k] - 1)))))
    return rows
