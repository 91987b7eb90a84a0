"""One case, both models: solve, sample shapes on shared points, pair, and tabulate errors."""
from __future__ import annotations

import os
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from analytical.kinematics import PoseGeometry
from analytical.modal import leg_axis_displacements
from analytical.model import analyse
from analytical.params import ModelOptions

from common.settings import as_dict

from .cache import ResultCache
from .pairing import pair_modes
from .scene import Case, Scene

# Shared points for MAC: eleven stations along every leg axis, joint centres included.
STATIONS = np.linspace(0.0, 1.0, 11)
EXTRA_MODES = 4  # asked beyond the reported ones, so a pair split across the cut is found


def analytical_case(scene: Scene, case: Case, options: ModelOptions) -> dict:
    """Frequencies, sampled shapes and wall time of the substructure model."""
    opts = replace(options, modes=min(options.modes + EXTRA_MODES, 18 * options.elements))
    start = time.perf_counter()
    res = analyse(scene.manipulator, case.pose, opts)
    seconds = time.perf_counter() - start
    shapes = leg_axis_displacements(res.model, res.geometry.leg_frames, res.modal.shapes,
                                    STATIONS)
    return {
        "elements": options.elements,
        "beam": options.beam,
        "platform_inertia": options.platform_inertia,
        "frequencies_hz": [float(f) for f in res.frequencies_hz],
        "seconds": seconds,
        "timings": {"total": seconds},
        "dofs": int(res.model.stiffness.shape[0]),
        "station_shapes": shapes.reshape(-1, shapes.shape[-1]).tolist(),
    }


def fem_options(scene: Scene, mesh_size: float | None = None, platform: str | None = None,
                coupling: str | None = None, modes: int | None = None):
    """The scene's FEM options (built once, at load) at one mesh size, with optional
    platform/coupling/mode-count overrides; EXTRA_MODES are added for the pairing."""
    options = scene.fem if mesh_size is None else scene.fem.with_size(mesh_size)
    changes = {k: v for k, v in {"platform": platform, "coupling": coupling}.items()
               if v is not None}
    changes["modes"] = (modes if modes is not None else scene.analytical.modes) + EXTRA_MODES
    return replace(options, **changes)


def fem_runtime(scene: Scene, cache: ResultCache | None = None, use_cache: bool = True):
    """How the scene's FEM solves run: its DOF guard, the mesh cache beside the result cache."""
    return replace(scene.fem_runtime, use_cache=use_cache,
                   cache_dir=None if cache is None else cache.directory / "meshes")


def fem_case(scene: Scene, geometry: PoseGeometry, cache: ResultCache, mesh_size: float,
             platform: str | None = None, coupling: str | None = None) -> dict:
    """The FEM reference of one pose at one mesh size, through the result cache.

    The cache key is every input that changes the answer, taken whole: the manipulator, the
    pose geometry, the complete FEM options (`dataclasses.asdict`, so a new option can never be
    left out of the key) and the sampling stations.
    """
    from fem_reference import solve_pose

    options = fem_options(scene, mesh_size, platform=platform, coupling=coupling)
    payload = fem_cache_payload(scene.manipulator, geometry, options)

    def compute():
        result = solve_pose(scene.manipulator, geometry, options, fem_runtime(scene, cache))
        shapes = result.leg_axis_displacements(STATIONS)
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
            "station_shapes": shapes.reshape(-1, shapes.shape[-1]).tolist(),
        }
        return value, {".vtu": vtu}

    try:
        value, key, hit = cache.get_or_compute(
            "fem", payload, compute, required=("frequencies_hz", "station_shapes", "timings", "mesh_cache_hit"))
    finally:
        for leftover in (cache.directory / "tmp").glob(f"mode-{os.getpid()}-*.vtu"):
            leftover.unlink(missing_ok=True)
    value = dict(value, cache_hit=hit)
    value["vtu_cache_path"] = str(cache.side_file("fem", key, ".vtu"))
    return value


def fem_cache_payload(manipulator, geometry: PoseGeometry, options) -> dict:
    """Everything that determines a FEM result, whole (see `fem_case`)."""
    return {"manipulator": as_dict(manipulator), "geometry": as_dict(geometry),
            "options": as_dict(options), "stations": STATIONS.tolist()}


def error_table(analytical: dict, fem: dict, count: int, fem_error_percent=None,
                reference_hz=None) -> list[dict]:
    """Rows of the comparison: FEM mode k paired with the analytical mode of the same shape."""
    a_hz = np.asarray(analytical["frequencies_hz"])
    f_hz = np.asarray(fem["frequencies_hz"])
    pairs = pair_modes(np.asarray(analytical["station_shapes"]), a_hz,
                       np.asarray(fem["station_shapes"]), f_hz, count)
    rows = []
    for p in pairs:
        row = {
            "fem_mode": p.reference_mode + 1,
            "analytical_mode": p.model_mode + 1,
            "f_fem_hz": float(f_hz[p.reference_mode]),
            "f_analytical_hz": float(a_hz[p.model_mode]),
            "error_percent": p.error_percent(a_hz, f_hz),
            "mac": p.mac,
            "repeated": p.repeated,
            "group": p.group,
        }
        if fem_error_percent is not None:
            row["fem_estimated_error_percent"] = float(fem_error_percent[p.reference_mode])
        if reference_hz is not None:
            row["f_reference_hz"] = float(reference_hz[p.reference_mode])
            row["error_vs_reference_percent"] = float(
                100 * (a_hz[p.model_mode] / reference_hz[p.reference_mode] - 1))
        rows.append(row)
    return rows
