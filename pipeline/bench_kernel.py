"""The best model's speed against the flops it needs (issue 40), stage by stage.

The most accurate analytical setting (Timoshenko middles between solid end zones at the largest
s offered) over the 10,000-pose map's reachable poses, batched in chunks of the map's size, on
one core, frequencies only: assembly, the standard form (Cholesky K = U^T U, LAPACK ?potrf, and
A = U^-T M U^-1, ?sygst) and the eigenvalues (the compiled kernel of `analytical.lanes`,
tridiagonal reduction and bisection with the poses in its vector lanes; and, timed in the same
run, LAPACK's ?syevd without vectors one pose a call). Each stage is timed as the difference of
medians of the pipeline cut after it.

Flops of one pose, n coordinates (the textbook counts, leading order): Cholesky n^3 / 3, ?sygst
n^3, ?sytrd 4 n^3 / 3; the tridiagonal QR's O(n^2) is not counted (under 1 % at n = 126). The
floor is those flops at one core's peak: its clock (`cpu MHz` of /proc/cpuinfo, the clock it
runs at, not a turbo it may reach) times the double flops a cycle its vector units retire (two
fused multiply-adds of 4 doubles with AVX2 and FMA: 16; 32 with AVX-512, where a core with one
512-bit FMA unit does 16 and the floor stated is then half the true one; 8 with AVX alone; 4
with SSE2), so the ratio of the measured time to it says how far from the hardware the kernel
is.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from studies.workspace_map import workspace_heights

from .bench_records import BestModel, Peak
from .bench_timing import median_seconds

MAP_GRID = (20, 10, 50)  # heights x rings x azimuths: the 10,000-pose map of issue 12
FLOPS_PER_CYCLE = (("avx512f", 32), ("avx2 fma", 16), ("avx", 8), ("sse2", 4))
CPUINFO = Path("/proc/cpuinfo")


def grid_poses(scene, grid: tuple[int, int, int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Heights, azimuths and tilts (SI) of a layers x rings x azimuths grid over the workspace:
    every layer's rings up to its regular tilt radius, as the map draws them."""
    from analytical.reach import regular_radii

    layers, rings, azimuths = grid
    heights = workspace_heights(scene, layers)
    radii = regular_radii(scene.manipulator, heights)
    z, fraction, phi = np.meshgrid(np.arange(layers), np.linspace(0.0, 1.0, rings),
                                   np.linspace(0.0, 2 * np.pi, azimuths, endpoint=False),
                                   indexing="ij")
    return heights[z.ravel()], phi.ravel(), (radii[z] * fraction).ravel()


def map_poses(scene):
    """The reachable poses of the 10,000-pose map grid (every layer's rings and azimuths)."""
    from analytical.pose_batch import pose_batch

    poses = pose_batch(scene.manipulator, *grid_poses(scene, MAP_GRID))
    return poses.take(np.flatnonzero(poses.feasible))


def stage_flops(n: int) -> dict[str, float]:
    """Flops of one pose's frequencies, n x n (the module doc's counts)."""
    return {"standard_form": n ** 3 / 3 + n ** 3, "eigenvalues": 4 * n ** 3 / 3}


def core_peak(cpuinfo: Path = CPUINFO) -> Peak | None:
    """One core's peak double-precision rate from /proc/cpuinfo (None where it cannot be
    read: another system, or no clock given)."""
    try:
        text = cpuinfo.read_text()
    except OSError:
        return None
    clock = re.search(r"^cpu MHz\s*:\s*([0-9.]+)", text, re.MULTILINE)
    flags = re.search(r"^flags\s*:(.*)$", text, re.MULTILINE)
    if clock is None or flags is None:
        return None
    have = set(flags.group(1).split())
    name, per_cycle = next(((n, f) for n, f in FLOPS_PER_CYCLE if set(n.split()) <= have),
                           ("none", 1))
    ghz = float(clock.group(1)) / 1e3
    return Peak(gflops=per_cycle * ghz, clock_ghz=ghz, flops_per_cycle=per_cycle,
                vector_units=name)


def bench_best_model(scene, runs: int) -> BestModel:
    """Seconds a pose of the most accurate analytical setting, batched over the map's poses on
    one core (frequencies only, the scene's modes), per stage: medians of `runs`; its flops,
    GFLOP/s and the ratio of its time to the flop floor."""
    from analytical.batch_model import (
        CHUNK,
        assemble_batch,
        assembly_plan,
        batch_coordinates,
        batch_layout,
    )
    from analytical.batch_solve import batch_frequencies, standard_form
    from analytical.lanes import kernels
    from solvers.settings import SOLID_END_ELEMENTS, speed_settings

    label = f"Timoshenko (Hutchinson) + solid ends, s={max(SOLID_END_ELEMENTS)}"
    options = speed_settings(scene)[label]
    poses = map_poses(scene)
    plan = assembly_plan(batch_layout(scene.manipulator, options, poses.base_joint,
                                      poses.platform_joint))

    def solve(last: str, kernel: str = "lanes"):
        for start in range(0, len(poses), CHUNK):
            model = assemble_batch(scene.manipulator, poses.take(slice(start, start + CHUNK)),
                                   options, plan)
            if last == "assembly":
                continue
            form = standard_form(model)
            if last == "eigenvalues":
                batch_frequencies(form, options.modes, kernel)

    seconds = {last: median_seconds(lambda: solve(last), runs, warmup=1)[0] / len(poses)
               for last in ("assembly", "standard_form", "eigenvalues")}
    lapack = median_seconds(lambda: solve("eigenvalues", "lapack"), runs, warmup=1)[0] / len(
        poses) - seconds["standard_form"]
    n = batch_coordinates(scene.manipulator, options)
    flops = stage_flops(n)
    standard = seconds["standard_form"] - seconds["assembly"]
    eigen = seconds["eigenvalues"] - seconds["standard_form"]
    total = sum(flops.values())
    peak = core_peak()
    floor = None if peak is None else total / (peak["gflops"] * 1e9)

    def rate(work: float, time: float) -> float | None:  # a difference of medians can be noise
        return work / time / 1e9 if time > 0.0 else None

    return BestModel(
        setting=label, poses=len(poses), matrix_size=n, modes=options.modes, runs=runs,
        pose_seconds=seconds["eigenvalues"], assembly_pose_seconds=seconds["assembly"],
        standard_form_pose_seconds=standard, eigenvalues_pose_seconds=eigen,
        flops_per_pose=total, gflops_per_core=total / seconds["eigenvalues"] / 1e9,
        solve_gflops_per_core=rate(total, standard + eigen),
        standard_form_gflops=rate(flops["standard_form"], standard),
        eigenvalues_gflops=rate(flops["eigenvalues"], eigen),
        kernel="lanes" if kernels() is not None else "lapack (numba missing)",
        lapack_eigenvalues_pose_seconds=lapack,
        eigenvalues_vs_lapack=eigen / lapack if lapack > 0.0 else None,
        peak=peak, floor_pose_seconds=floor,
        vs_floor=None if floor is None else seconds["eigenvalues"] / floor)
