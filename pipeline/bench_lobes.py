"""Issue 52's figures, on scenes/3prs-head.toml (its [cutting], [tool] and [damping]), one core:

- `lobes_pose_vs_map_pose`: one pose's lobe diagram (the [cutting] table's 400 speeds, its
  method and default intervals) against one pose of the 10,000-pose frequency map of the same
  machine, timed alternately (`bench_timing.alternate`), medians;
- the workspace stability map (`studies.stability_map`: its grid, its speeds) once, with the
  estimate it said before it started.
"""
from __future__ import annotations

import contextlib
import io
import os
import statistics
import time
from pathlib import Path

from .bench_kernel import map_poses
from .bench_records import LobesBench
from .bench_timing import alternate

SCENE = "3prs-head.toml"


def bench_lobes(scenes: Path, runs: int, stability_map: bool = True) -> LobesBench:
    from analytical.batch_model import CHUNK, assemble_batch
    from analytical.batch_solve import frequencies
    from analytical.kinematics import pose_geometry
    from chatter.lobes import diagram
    from chatter.tool_input import from_base
    from scene import load_scene
    from solvers.tool_frf import analytical_tool
    from studies.stability_map import stability_map as draw_map

    scene = load_scene(scenes / SCENE)
    cutting = scene.cutting
    if cutting is None:
        raise RuntimeError(f"{SCENE}: no [cutting] table to time")
    case = scene.case(scene.ci_cases[0])
    geometry = pose_geometry(scene.manipulator, case.pose)
    tool = analytical_tool(scene.manipulator, geometry, scene.analytical, scene.damping,
                           scene.tool.point, scene.fidelity.modes)
    modes = from_base(tool.modes.omega, tool.zeta, tool.modes.phi, geometry.rotation,
                      cutting.feed_direction)
    poses = map_poses(scene)

    def lobes():
        diagram(modes, cutting)

    def fmap():
        for first in range(0, len(poses), CHUNK):
            frequencies(assemble_batch(scene.manipulator, poses.take(slice(first, first + CHUNK)),
                                       scene.analytical), scene.analytical.modes)

    times = alternate({"lobes": lobes, "map": fmap}, runs, warmup=1)
    lobes_s, map_s = (statistics.median(times[k]) for k in ("lobes", "map"))
    out = LobesBench(
        scene=SCENE, case=case.name, runs=runs,
        openblas_num_threads=os.environ.get("OPENBLAS_NUM_THREADS"), method=cutting.method,
        speeds=len(cutting.speeds_hz()), tool_modes=modes.count,
        lobes_seconds=times["lobes"], lobes_median_seconds=lobes_s,
        map_poses=len(poses), map_median_seconds=map_s, map_pose_seconds=map_s / len(poses),
        ratio=lobes_s / (map_s / len(poses)))
    if stability_map:
        said = io.StringIO()
        start = time.perf_counter()
        with contextlib.redirect_stderr(said):
            record = draw_map(scene)
        out["stability_map_seconds"] = time.perf_counter() - start
        out["stability_map_poses"] = record["poses"]
        out["stability_map_speeds"] = record["speeds"]
        out["stability_map_estimated_seconds"] = record["estimated_seconds"]
        out["stability_map_announced"] = " ".join(said.getvalue().split())
    return out
