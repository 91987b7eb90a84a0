"""Issue 51's figure: the 10,000-pose map of a machine with real legs (scenes/actuator-legs.toml,
a housing and a rod) with its solid legs against the same map with its beam legs, one core.

The solid legs are the fidelity step's setting on such machines ("Solid legs, s=8",
`solvers.settings`), batched as every map is (`analytical.batch_model`: each part read from
pieces of its stroke, its interior reduced to the modes chosen for the machine); the beam legs
are the scene's own [analytical] setting. Both solve the scene's modes at the grid's reachable
poses in chunks of the map's size, timed alternately (`bench_timing.alternate`), medians.
Beside them, once, the machine's one-off build from an empty cache: every piece its rods' strokes
need, its housing and the choice of the reduction (`build_seconds`), with the estimate the run
announced for it.
"""
from __future__ import annotations

import contextlib
import io
import os
import statistics
import tempfile
import time
from dataclasses import replace
from pathlib import Path

from .bench_kernel import map_poses
from .bench_records import RealLegsMap
from .bench_timing import alternate

SCENE = "actuator-legs.toml"


def bench_real_legs(scenes: Path, runs: int) -> RealLegsMap:
    from analytical import batch_model, solid_legs
    from analytical.batch_model import CHUNK, assemble_batch, batch_coordinates, leg_reduction
    from analytical.batch_solve import frequencies
    from fem_reference import meridian
    from scene import load_scene
    from solvers.settings import SOLID_LEGS, model_variants

    scene = load_scene(scenes / SCENE)
    beam = scene.analytical
    modes = beam.modes
    poses = map_poses(scene)
    with tempfile.TemporaryDirectory() as cache:
        solid = replace(model_variants(scene)[SOLID_LEGS], modes=modes, cache_dir=cache)
        solid_legs.clear_caches()
        batch_model.leg_reduction.cache_clear()
        meridian.clear_caches()  # its meshes too: a cold build
        said = io.StringIO()
        start = time.perf_counter()
        with contextlib.redirect_stderr(said):
            chosen = leg_reduction(scene.manipulator, solid)
            for first in range(0, len(poses), CHUNK):  # every piece the map needs
                batch_model.machine_parts(
                    scene.manipulator, poses.take(slice(first, first + CHUNK)), solid,
                    batch_model.batch_layout(scene.manipulator, solid, poses.base_joint,
                                             poses.platform_joint))
        build = time.perf_counter() - start
        pieces = len(list(Path(cache, "joint_ends").glob("*.json")))

        def draw(options):
            def run():
                for first in range(0, len(poses), CHUNK):
                    frequencies(assemble_batch(scene.manipulator,
                                               poses.take(slice(first, first + CHUNK)),
                                               options), modes)
            return run

        times = alternate({"solid": draw(solid), "beam": draw(beam)}, runs, warmup=1)
    median = {k: statistics.median(v) for k, v in times.items()}

    return RealLegsMap(
        scene=SCENE, poses=len(poses), modes=modes, runs=runs,
        openblas_num_threads=os.environ.get("OPENBLAS_NUM_THREADS"),
        solid_setting=solid.describe(), beam_setting=beam.describe(),
        part_modes=chosen.modes, coordinates_kept=chosen.coordinates[0],
        coordinates_reduced=chosen.coordinates[1],
        beam_coordinates=batch_coordinates(scene.manipulator, beam),
        reduction_error=chosen.error, build_seconds=build, cache_entries=pieces,
        announced=" ".join(said.getvalue().split()),
        solid_median_seconds=median["solid"], solid_seconds=times["solid"],
        beam_median_seconds=median["beam"], beam_seconds=times["beam"],
        solid_pose_seconds=median["solid"] / len(poses),
        beam_pose_seconds=median["beam"] / len(poses),
        ratio=median["solid"] / median["beam"])
