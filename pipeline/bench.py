"""Timing benchmarks (`make bench`): medians of repeated runs, written to bench/bench.json
with a line in bench/history.jsonl and the comparisons of pipeline/bench_history.py.

- the analytical model per pose (s = 1, 3, 6, 10; s = 3 and 5 with solid ends) against a plain
  scipy.linalg.eigh call on the pose's own matrices, timed alternately: `vs_plain_eigh`, and
  `analytical_pose_vs_plain_eigh` for the scene's setting; the FEM per mesh size;
- the workspace-validation sweep (the CI-size design: FEM at two sizes and every candidate
  model per pose) with 1 and with 2 workers, each from an empty cache: `sweep_speedup`;
- the 10,000-pose analytical map (20 heights x 10 rings x 50 azimuths, modes followed by
  shape, every core) against 10,000 plain scipy.linalg.eigh(K, M) calls on matrices of the
  same size on one core, timed alternately in the same run: `map_vs_plain_eigh` (the map the
  run draws, 3 modes; issue 12 asks for <= 1.0) and `map_scene_modes_vs_plain_eigh` (the
  scene's modes);
- issue 38's: `dynamic_map_vs_frequency_map`, the least dynamic stiffness at the tool over the
  10,000-pose map's reachable poses with 2,000 lines against the frequency map of the same grid
  (the scene's modes), both on one core;
- issue 39's: `uncertainty_run_vs_batched_pose`, one model run of the input-uncertainty
  propagation (a machine of its own per sample, assembled per machine, solved as a batch)
  against one pose of the batched frequencies of the scene's machine, at the case, timed
  alternately (scenes with [uncertainty]);
- issue 26's two figures and issue 40's account of them: `best_model_pose_seconds`, the most
  accurate analytical setting per pose over the map's reachable poses, batched, on one core,
  stage by stage with its flops, GFLOP/s and the ratio to the flop floor
  (pipeline/bench_kernel.py); and `map_one_core_vs_plain_eigh`, the map the run draws on one
  worker against the 10,000 plain eigh calls;
- issue 52's `lobes_pose_vs_map_pose`: one pose's lobe diagram (400 speeds) of
  scenes/3prs-head.toml against one pose of its frequency map, and its workspace stability map
  once (pipeline/bench_lobes.py);
- issue 51's `real_legs_map_vs_beam`: the 10,000-pose map of scenes/actuator-legs.toml (a
  housing and a rod) with its solid legs against its beam legs, one core, and the solid legs'
  one-off build from an empty cache (pipeline/bench_real_legs.py);
- issue 40's `distributed_overhead`: a 10^5-pose sweep on a local Dask cluster of two workers
  against one process, and a worker killed part-way (pipeline/bench_distributed.py).

Timings never gate a test: this machine is shared and noisy. Run as
`python -m pipeline.bench --scene scenes/paper.toml [--skip-fem] [--distributed-poses 0]`.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import scipy.linalg

from analytical.kinematics import pose_geometry
from analytical.model import analyse
from analytical.params import Pose
from analytical.substructure import assemble
from analytical.workspace import default_workers, frequency_map
from common.locations import default_scene
from runtime.places import path_argument
from scene import load_scene
from solvers.compare import fem_options, fem_runtime
from studies.workspace_map import workspace_heights

from .bench_distributed import POSE_GRID, bench_distributed
from .bench_history import (
    HISTORY,
    against,
    default_out,
    headline,
    machine,
    previous_run,
    record,
    reference_ratios,
    revision,
)
from .bench_kernel import MAP_GRID, bench_best_model, map_poses
from .bench_lobes import SCENE as LOBES_SCENE
from .bench_lobes import bench_lobes
from .bench_real_legs import SCENE as REAL_LEGS_SCENE
from .bench_real_legs import bench_real_legs
from .bench_records import (
    BENCH,
    DynamicMapBench,
    EstimatedErrors,
    FemTiming,
    FemTimings,
    Grid,
    MapBench,
    SweepBench,
    Timing,
    Timings,
    UncertaintyBench,
)
from .bench_timing import alternate


def bench_analytical(scene, case_name: str, runs: int) -> Timings:
    """One pose of the per-pose model (kinematics, assembly, modes) per setting, against a
    plain scipy.linalg.eigh(K, M) call on that pose's own matrices, timed alternately: medians
    and their ratio (the figure that carries across machines, pipeline/bench_history.py)."""
    case = scene.case(case_name)
    settings = {f"s={s}": replace(scene.analytical, elements=s) for s in (1, 3, 6, 10)}
    settings.update({  # Timoshenko middles between solid end zones (analytical.end_zones)
        f"s={s}, solid ends": replace(scene.analytical, elements=s, beam="timoshenko",
                                      shear="hutchinson", joint_ends="solid") for s in (3, 5)})
    out: Timings = {}
    for name, opts in settings.items():
        model = analyse(scene.manipulator, case.pose, opts).model
        times = alternate({"pose": lambda: analyse(scene.manipulator, case.pose, opts),
                           "plain": lambda: scipy.linalg.eigh(model.stiffness, model.mass)},
                          runs)
        pose, plain = (statistics.median(times[k]) for k in ("pose", "plain"))
        out[name] = Timing(median_seconds=pose, min_seconds=min(times["pose"]), runs=runs,
                           plain_eigh_seconds=plain, vs_plain_eigh=pose / plain)
    return out


def bench_map(scene, runs: int, modes: int, workers: int | None = None) -> MapBench:
    """The 10,000-pose analytical map (frequencies and modes followed by shape, on every core)
    against 10,000 plain scipy.linalg.eigh(K, M) calls on the map's own 18 s x 18 s matrices in
    one process (one core: OPENBLAS_NUM_THREADS=1 under make), timed alternately; medians.
    `workers` processes draw the map (default: every core)."""
    layers, rings, azimuths = MAP_GRID
    options = replace(scene.analytical, modes=modes)
    heights = workspace_heights(scene, layers)
    fmap = frequency_map(scene.manipulator, options, heights, rings, azimuths,
                         workers)  # warm-up
    reached = np.argwhere(np.isfinite(fmap.frequencies_hz[..., 0]))[::47][:200]
    sample = [Pose(float(fmap.heights[iz]), float(fmap.azimuths[ip]), float(fmap.tilts[iz, ir]))
              for iz, ir, ip in reached]
    models = [assemble(scene.manipulator, pose_geometry(scene.manipulator, p), options)
              for p in sample]
    calls = layers * rings * azimuths

    def plain():
        for k in range(calls):
            model = models[k % len(models)]
            scipy.linalg.eigh(model.stiffness, model.mass)

    plain()
    map_s, plain_s = [], []
    for _ in range(runs):
        start = time.perf_counter()
        frequency_map(scene.manipulator, options, heights, rings, azimuths, workers)
        map_s.append(time.perf_counter() - start)
        start = time.perf_counter()
        plain()
        plain_s.append(time.perf_counter() - start)
    tracking = fmap.tracking
    if tracking is None:  # frequency_map always follows the families
        raise RuntimeError("the map was drawn without following its families")
    return MapBench(
        grid=Grid(heights=layers, rings=rings, azimuths=azimuths, poses=calls,
                  distinct_poses=layers * (1 + (rings - 1) * azimuths)),
        modes=modes,
        matrix_size=18 * options.elements,
        workers=default_workers() if workers is None else workers,
        openblas_num_threads=os.environ.get("OPENBLAS_NUM_THREADS"),
        map_median_seconds=statistics.median(map_s),
        map_seconds=map_s,
        plain_eigh_calls=calls,
        plain_eigh_median_seconds=statistics.median(plain_s),
        plain_eigh_seconds=plain_s,
        ratio=statistics.median(map_s) / statistics.median(plain_s),
        poses_with_shapes=tracking.poses_with_shapes,
        steps_matched_by_shape=tracking.steps_with_shapes,
        steps=tracking.steps,
        crossings=len(fmap.crossings),
        runs=runs)


def bench_dynamic_map(scene, runs: int) -> DynamicMapBench:
    """The least dynamic stiffness at the tool over the 10,000-pose map's reachable poses
    (issue 38: 2,000 lines; the scene's [damping] and [tool], or their defaults) against the
    frequency map the run draws on the same grid with the scene's modes, one core each, and
    against the same poses' frequencies alone; timed alternately, medians."""
    from analytical.batch_model import (
        CHUNK,
        assemble_batch,
        assembly_plan,
        batch_coordinates,
        batch_layout,
    )
    from analytical.batch_solve import frequencies
    from analytical.tool_response import SUPERPOSED_EXTRA, least_stiffness_map
    from common.frf import LINES

    layers, rings, azimuths = MAP_GRID
    options, modes = scene.analytical, scene.analytical.modes
    heights = workspace_heights(scene, layers)
    poses = map_poses(scene)
    plan = assembly_plan(batch_layout(scene.manipulator, options, poses.base_joint,
                                      poses.platform_joint))

    def dynamic():
        least_stiffness_map(scene.manipulator, options, poses, scene.damping,
                            scene.tool.point, modes, LINES)

    def frequencies_only():
        for start in range(0, len(poses), CHUNK):
            model = assemble_batch(scene.manipulator, poses.take(slice(start, start + CHUNK)),
                                   options, plan)
            frequencies(model, modes)

    def fmap():
        frequency_map(scene.manipulator, options, heights, rings, azimuths, 1)

    times = alternate({"dynamic": dynamic, "frequencies": frequencies_only, "map": fmap}, runs,
                      warmup=1)
    median = {k: statistics.median(v) for k, v in times.items()}
    return DynamicMapBench(
        poses=len(poses), lines=LINES, modes=modes,
        modes_summed=min(modes + SUPERPOSED_EXTRA, batch_coordinates(scene.manipulator,
                                                                     options)),
        runs=runs, dynamic_median_seconds=median["dynamic"], dynamic_seconds=times["dynamic"],
        frequency_map_median_seconds=median["map"], frequency_map_seconds=times["map"],
        frequencies_only_median_seconds=median["frequencies"],
        frequencies_only_seconds=times["frequencies"],
        vs_frequency_map=median["dynamic"] / median["map"],
        vs_frequencies_only=median["dynamic"] / median["frequencies"])


def bench_fem(scene, case_name: str, runs: int, sizes: list[float],
              legs: str | None = None) -> FemTimings:
    from fem_reference import solve_pose
    from fem_reference.harmonic import clear_caches

    case = scene.case(case_name)
    geometry = pose_geometry(scene.manipulator, case.pose)
    out: FemTimings = {}
    for size in sizes:
        # no mesh cache (nor the harmonic legs' per-process memo), so that meshing is timed
        # too; as many modes as the pipeline asks
        def once(size=size):
            clear_caches()
            return solve_pose(scene.manipulator, geometry, fem_options(scene, size, legs=legs),
                              fem_runtime(scene, use_cache=False))

        samples, timings, dofs = [], [], 0
        for _ in range(runs):
            start = time.perf_counter()
            result = once()
            samples.append(time.perf_counter() - start)
            timings.append(result.timings)
            dofs = result.dofs
        out[f"{size * 1e3:g}mm"] = FemTiming(
            mesh_size_mm=size * 1e3, dofs=int(dofs), median_seconds=statistics.median(samples),
            min_seconds=min(samples),
            median_timings={k: statistics.median(t[k] for t in timings) for k in timings[0]},
            runs=runs)
    return out


def bench_sweep(scene, runs: int, workers: tuple[int, ...] = (1, 2)) -> SweepBench:
    """Wall time of the CI-size workspace-validation sweep with each worker count, every run
    from an empty cache (meshes included), alternating the worker counts run by run."""
    import tempfile

    from runtime.cache import ResultCache
    from solvers.refinement import coarse_size
    from solvers.settings import speed_settings
    from studies.workspace_validation import SMALL, run_study

    models = speed_settings(scene)
    samples: dict[int, list[float]] = {w: [] for w in workers}
    poses = 0
    for _ in range(runs):
        for w in workers:
            with tempfile.TemporaryDirectory(prefix="rps-bench-sweep-") as tmp:
                start = time.perf_counter()
                study = run_study(scene, models, ResultCache(Path(tmp)),
                                  coarse_size(scene, scene.fem.mesh_size), size=SMALL,
                                  workers=w)
                samples[w].append(time.perf_counter() - start)
            poses = len(study["poses"])
    medians = {str(w): statistics.median(samples[w]) for w in workers}
    return SweepBench(poses=poses, runs=runs, models=len(models), median_seconds=medians,
                      seconds={str(w): samples[w] for w in workers},
                      speedup=medians[str(workers[0])] / medians[str(workers[-1])])


def bench_uncertainty(scene, case_name: str, runs: int, samples: int = 256
                      ) -> UncertaintyBench:
    """Seconds per model run of `solvers.uncertainty.propagate` (Saltelli's design, `samples`
    base points, the statistics included) at the case, against seconds per pose of the batched
    frequencies of as many copies of the case's pose of the scene's own machine; medians."""
    from analytical.batch_model import CHUNK, assemble_batch
    from analytical.batch_solve import frequencies
    from analytical.pose_batch import pose_batch
    from solvers.uncertainty import propagate

    pose, modes = scene.cases[case_name].pose, scene.analytical.modes
    count = samples * (len(scene.uncertainty.inputs) + 2)
    poses = pose_batch(scene.manipulator, [pose.height] * count, [pose.azimuth] * count,
                       [pose.tilt] * count)

    def propagated():
        propagate(scene, scene.analytical, pose, modes, samples=samples)

    def batched():
        for start in range(0, count, CHUNK):
            model = assemble_batch(scene.manipulator, poses.take(slice(start, start + CHUNK)),
                                   scene.analytical)
            frequencies(model, modes)

    times = alternate({"propagated": propagated, "batched": batched}, runs, warmup=1)
    run_s = statistics.median(times["propagated"]) / count
    pose_s = statistics.median(times["batched"]) / count
    return UncertaintyBench(case=case_name, inputs=len(scene.uncertainty.inputs),
                            samples=samples, model_runs=count, runs=runs, run_seconds=run_s,
                            batched_pose_seconds=pose_s, propagated_seconds=times["propagated"],
                            batched_seconds=times["batched"], run_vs_batched_pose=run_s / pose_s)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m pipeline.bench")
    parser.add_argument("--scene", default=str(default_scene()),
                        help="scene file (default: the paper's scene)")
    parser.add_argument("--case", default=None,
                        help="case to time (default: the scene's last CI case)")
    parser.add_argument("--out", type=path_argument, default=default_out(),
                        help="the figures (default: bench/bench.json at the checkout, beside "
                        "out/, which a validation replaces whole); its folder keeps "
                        "history.jsonl, one line a run")
    parser.add_argument("--results", type=path_argument, default=Path("out/results.json"),
                        help="a validation's results, for the FEM's estimated errors "
                        "(default: out/results.json)")
    parser.add_argument("--runs", type=int, default=200, help="analytical repetitions")
    parser.add_argument("--fem-runs", type=int, default=3, help="FEM repetitions per size")
    parser.add_argument("--map-runs", type=int, default=5,
                        help="repetitions of the 10,000-pose map and its eigh baseline")
    parser.add_argument("--sweep-runs", type=int, default=1,
                        help="repetitions of the workspace-validation sweep per worker count "
                        "(0: skip it)")
    parser.add_argument("--distributed-poses", type=int, default=POSE_GRID[0] * POSE_GRID[1]
                        * POSE_GRID[2], choices=(0, 100_000), metavar="{0,100000}",
                        help="the 10^5-pose sweep on a local Dask cluster (0: skip it; "
                        "default: 100000)")
    parser.add_argument("--no-stability-map", dest="stability_map", action="store_false",
                        help="skip the 3-PRS head's workspace stability map (about 3 min; "
                        "default: timed once)")
    parser.add_argument("--skip-fem", action="store_true",
                        help="no FEM timings nor the validation sweep (default: both)")
    args = parser.parse_args(argv)
    try:
        scene = load_scene(args.scene)
        if args.case is None:
            args.case = scene.ci_cases[-1]
        analytical = bench_analytical(scene, args.case, args.runs)
        result = {
            "machine": machine(),
            "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
            "case": args.case,
            "analytical": analytical,
            "analytical_pose_seconds_median": analytical[f"s={scene.analytical.elements}"][
                "median_seconds"],
            "analytical_runs": args.runs,
            "analytical_pose_vs_plain_eigh": analytical[f"s={scene.analytical.elements}"][
                "vs_plain_eigh"],
        }
        # the map the run draws (3 modes), and the same grid with the scene's modes
        result["map"] = bench_map(scene, args.map_runs, modes=3)
        result["map_vs_plain_eigh"] = result["map"]["ratio"]
        result["map_scene_modes"] = bench_map(scene, args.map_runs, modes=scene.analytical.modes)
        result["map_scene_modes_vs_plain_eigh"] = result["map_scene_modes"]["ratio"]
        result["map_one_core"] = bench_map(scene, args.map_runs, modes=3, workers=1)
        result["map_one_core_vs_plain_eigh"] = result["map_one_core"]["ratio"]
        result["best_model"] = bench_best_model(scene, args.map_runs)
        result["best_model_pose_seconds"] = result["best_model"]["pose_seconds"]
        result["dynamic_map"] = bench_dynamic_map(scene, args.map_runs)
        result["dynamic_map_vs_frequency_map"] = result["dynamic_map"]["vs_frequency_map"]
        scenes = Path(default_scene()).parent
        if (scenes / REAL_LEGS_SCENE).is_file():
            result["real_legs_map"] = bench_real_legs(scenes, args.map_runs)
            result["real_legs_map_vs_beam"] = result["real_legs_map"]["ratio"]
        if (scenes / LOBES_SCENE).is_file():
            result["lobes"] = bench_lobes(scenes, args.map_runs,
                                          stability_map=args.stability_map)
            result["lobes_pose_vs_map_pose"] = result["lobes"]["ratio"]
        if scene.uncertainty is not None:
            result["uncertainty"] = bench_uncertainty(scene, args.case, args.map_runs)
            result["uncertainty_run_vs_batched_pose"] = \
                result["uncertainty"]["run_vs_batched_pose"]
        if not args.skip_fem:
            sizes = sorted(set(scene.fem_study.refinement) | {scene.fem.mesh_size}, reverse=True)
            fem = bench_fem(scene, args.case, args.fem_runs, sizes)
            result["fem"] = fem
            result["fem_pose_seconds_median"] = fem[f"{scene.fem.mesh_size * 1e3:g}mm"][
                "median_seconds"]
            result["fem_runs"] = args.fem_runs
            result["fem_legs"] = scene.fem.legs
            other = "tetrahedra" if scene.fem.legs == "harmonic" else None
            if other:  # the other discretisation of the same solid, timed in the same run
                result["fem_tetrahedra"] = bench_fem(scene, args.case, args.fem_runs, sizes,
                                                     legs=other)
                result["fem_pose_seconds_vs_tetrahedra"] = result["fem_pose_seconds_median"] / \
                    result["fem_tetrahedra"][f"{scene.fem.mesh_size * 1e3:g}mm"]["median_seconds"]
            if args.sweep_runs > 0:
                result["sweep"] = bench_sweep(scene, args.sweep_runs)
                result["sweep_speedup"] = result["sweep"]["speedup"]
            est = _estimated_errors(args.results, args.case)
            if est:
                result["fem_estimated_error_percent"] = est
        if args.distributed_poses:
            result["distributed"] = bench_distributed(scene)
            result["distributed_overhead"] = result["distributed"]["overhead"]
        result.update(revision())
        history = args.out.parent / HISTORY
        result["previous"] = against(headline(result), previous_run(
            history, result["machine"], result["commit"]))
        result["reference"] = reference_ratios(result)
        BENCH.write_to(args.out, result)  # checked against its declaration
        record(history, result)
    except (ValueError, RuntimeError, OSError) as exc:
        print(f"error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    print(json.dumps({"headline": headline(result), "previous": result["previous"],
                      "reference": result["reference"]}, indent=1))
    print(f"wrote {args.out} and a line of {history}")
    return 0


def _estimated_errors(results_path: Path, case_name: str) -> EstimatedErrors | None:
    """The refinement study's estimated error per size, if a validation run left one."""
    from results import read
    from studies import RECORDS

    try:
        results = read(results_path, RECORDS)
    except ValueError:  # none, or of another schema
        return None
    case = next((c for c in results["cases"] if c["name"] == case_name), None)
    study = case and case["fem_refinement"]
    if not study:
        return None
    return {f"{h:g}mm": e for h, e in zip(study["mesh_sizes_mm"],
                                                 study["estimated_error_percent_max"])}


if __name__ == "__main__":
    sys.exit(main())
