"""Timing benchmarks (`make bench`): medians of repeated runs, written to out/bench.json.

Timings never gate a test: this machine is shared and noisy. Run as
`python -m pipeline.bench --scene scenes/paper.toml --out out/bench.json [--quick]`.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

from analytical.kinematics import pose_geometry
from analytical.model import analyse

from common.atomic import write_json_atomic
from common.locations import default_scene
from .compare import fem_options, fem_runtime
from .scene import load_scene


def _median_seconds(fn, runs: int, warmup: int = 3) -> tuple[float, list[float]]:
    for _ in range(warmup):
        fn()
    samples = []
    for _ in range(runs):
        start = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - start)
    return statistics.median(samples), samples


def bench_analytical(scene, case_name: str, runs: int) -> dict:
    case = scene.case(case_name)
    out = {}
    for s in (1, 3, 6, 10):
        opts = replace(scene.analytical, elements=s)
        median, samples = _median_seconds(lambda: analyse(scene.manipulator, case.pose, opts), runs)
        out[f"s={s}"] = {"median_seconds": median, "min_seconds": min(samples), "runs": runs}
    return out


def bench_fem(scene, case_name: str, runs: int, sizes: list[float]) -> dict:
    from fem_reference import solve_pose

    case = scene.case(case_name)
    geometry = pose_geometry(scene.manipulator, case.pose)
    out = {}
    for size in sizes:
        # no mesh cache, so that meshing is timed too; as many modes as the pipeline asks
        def once(size=size):
            return solve_pose(scene.manipulator, geometry, fem_options(scene, size),
                              fem_runtime(scene, use_cache=False))

        samples, timings, dofs = [], [], 0
        for _ in range(runs):
            start = time.perf_counter()
            result = once()
            samples.append(time.perf_counter() - start)
            timings.append(result.timings)
            dofs = result.dofs
        out[f"{size * 1e3:g}mm"] = {
            "mesh_size_m": size,
            "dofs": int(dofs),
            "median_seconds": statistics.median(samples),
            "min_seconds": min(samples),
            "median_timings": {k: statistics.median(t[k] for t in timings) for k in timings[0]},
            "runs": runs,
        }
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m pipeline.bench")
    parser.add_argument("--scene", default=str(default_scene()),
                        help="scene file (default: the paper's scene)")
    parser.add_argument("--case", default=None,
                        help="case to time (default: the scene's last CI case)")
    parser.add_argument("--out", default="out/bench.json")
    parser.add_argument("--runs", type=int, default=200, help="analytical repetitions")
    parser.add_argument("--fem-runs", type=int, default=3, help="FEM repetitions per size")
    parser.add_argument("--skip-fem", action="store_true")
    args = parser.parse_args(argv)
    try:
        scene = load_scene(args.scene)
        if args.case is None:
            args.case = scene.ci_cases[-1]
        analytical = bench_analytical(scene, args.case, args.runs)
        result = {
            "machine": {"python": sys.version.split()[0], "platform": platform.platform(),
                        "processor": platform.processor() or platform.machine(),
                        "cpu_count": os.cpu_count()},
            "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
            "case": args.case,
            "analytical": analytical,
            "analytical_pose_seconds_median": analytical[f"s={scene.analytical.elements}"][
                "median_seconds"],
            "analytical_runs": args.runs,
        }
        if not args.skip_fem:
            sizes = sorted(set(scene.fem_study.refinement) | {scene.fem.mesh_size}, reverse=True)
            fem = bench_fem(scene, args.case, args.fem_runs, sizes)
            result["fem"] = fem
            result["fem_pose_seconds_median"] = fem[f"{scene.fem.mesh_size * 1e3:g}mm"][
                "median_seconds"]
            result["fem_runs"] = args.fem_runs
            est = _estimated_errors(Path(args.out).parent / "results.json", args.case)
            if est:
                result["fem_estimated_error_percent"] = est
        write_json_atomic(Path(args.out), result)
    except (ValueError, RuntimeError, OSError) as exc:
        print(f"error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    print(json.dumps({k: v for k, v in result.items() if k.endswith("median")}, indent=1))
    return 0


def _estimated_errors(results_path: Path, case_name: str) -> dict | None:
    """The refinement study's estimated error per size, if a validation run left one."""
    from .results import read

    try:
        results = read(results_path)
    except ValueError:  # none, or of another schema
        return None
    case = next((c for c in results["cases"] if c["name"] == case_name), None)
    study = case and case["fem_refinement"]
    if not study:
        return None
    return {f"{s * 1e3:g}mm": e for s, e in zip(study["sizes_m"],
                                                 study["estimated_error_percent_max"])}


if __name__ == "__main__":
    sys.exit(main())
