"""Wall time per pose of an analytical setting, measured once and kept with the results.

One pose's time (kinematics, synthesis and eigen solve; `time_model`: the median of
RUNS repetitions after a warm-up) is asked for by three steps of a run - the fidelity choice,
the model-variant table and the speed-vs-error chart - for the same settings at the same
poses. It is measured once per (machine, code, manipulator, pose, setting) and kept in the
result cache beside the FEM solves, whose times are kept the same way; a warm run reports the
times measured when the entry was made, on the same machine (the machine's identity is part
of the key, so a cache moved to another computer measures again). `make bench` re-measures
everything from scratch and is where timings are compared.
"""
from __future__ import annotations

import os
import platform
import time
from dataclasses import replace
from functools import lru_cache

import numpy as np
from typing_extensions import TypedDict

from analytical.kinematics import pose_geometry
from analytical.model import natural_frequencies
from analytical.params import ModelOptions, Pose
from common.settings import as_dict
from runtime.cache import ResultCache
from scene import Case, Scene

RUNS = 30  # repetitions per measurement (the median is kept)
KIND = "model-timings"


class Machine(TypedDict):
    """What identifies the computer a time was measured on (part of a timing's cache key)."""
    node: str
    cpu: str
    cores: int | None
    python: str


@lru_cache(maxsize=1)
def machine() -> Machine:
    """What identifies the computer a time was measured on."""
    cpu = platform.processor()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as info:
            cpu = next((line.split(":", 1)[1].strip() for line in info
                        if line.startswith("model name")), cpu)
    except OSError:
        pass
    return Machine(node=platform.node(), cpu=cpu, cores=os.cpu_count(),
                   python=platform.python_version())


def seconds_per_pose(scene: Scene, case: Case, options, cache: ResultCache | None) -> float:
    """Median wall time (s) of one pose of `case` with the analytical `options`; from the
    cache when this machine measured it with this code before (no cache: always measured)."""
    if cache is None:
        return time_model(scene, case, options, runs=RUNS)
    payload = {"manipulator": as_dict(scene.manipulator), "pose": as_dict(case.pose),
               "options": as_dict(options), "runs": runs_of(options), "machine": machine()}
    value, _, _ = cache.get_or_compute(
        KIND, payload, lambda: ({"seconds": time_model(scene, case, options, runs=RUNS)}, {}),
        required=("seconds",), modules=("solvers.timing",))
    return float(value["seconds"])


SOLID_LEG_RUNS = 5  # solid legs take ~0.1-2 s a new pose: fewer repetitions
NEW_POSE_STEP = 1e-6  # m and rad: how far apart the poses of a solid-legs timing are


def runs_of(options: ModelOptions) -> int:
    """Timed repetitions of a setting: RUNS, or SOLID_LEG_RUNS new poses with solid legs."""
    return SOLID_LEG_RUNS if options.legs == "solid" else RUNS


def new_pose(scene: Scene, pose: Pose, k: int) -> Pose:
    """A reachable pose k steps from `pose` in height and tilt (so the three legs take three
    new lengths, a level pose's too), stepping back where a limit is in the way; the pose
    itself when no step is reachable (a pose pinned by its limits: its parts are remembered)."""
    step = k * NEW_POSE_STEP
    for dz, dt in ((step, step), (-step, -step), (step, -step), (-step, step)):
        candidate = replace(pose, height=pose.height + dz, tilt=pose.tilt + dt)
        try:
            pose_geometry(scene.manipulator, candidate)
        except ValueError:
            continue
        return candidate
    return pose


def time_model(scene: Scene, case: Case, options: ModelOptions, runs: int = 30) -> float:
    """Median wall time (s) of one pose: kinematics, synthesis and eigen solve. With solid legs
    (`legs = "solid"`) each run is a new pose (`new_pose`), so the parts whose length follows
    the pose are read at new lengths from the pieces of their stroke (a piece not built yet is
    built once, by the first run that reaches it), as in a map of new poses; a part of fixed
    length is built once, as there."""
    natural_frequencies(scene.manipulator, case.pose, options)
    fresh = options.legs == "solid"
    samples = []
    for k in range(min(runs, SOLID_LEG_RUNS) if fresh else runs):
        pose = new_pose(scene, case.pose, k + 1) if fresh else case.pose
        start = time.perf_counter()
        natural_frequencies(scene.manipulator, pose, options)
        samples.append(time.perf_counter() - start)
    return float(np.median(samples))
