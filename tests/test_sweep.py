"""Sweeps: one pose one task, cached by content, resumable, failures recorded, local pool or
a Dask cluster giving the same results."""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from analytical.model import natural_frequencies
from analytical.params import ModelOptions, Pose
from runtime.cache import ResultCache
from runtime.sweep import run_sweep
from scene import load_scene
from tests.conftest import PAPER_SCENE


def frequencies_task(task: dict) -> dict:
    """A cheap real task: the analytical frequencies of one pose; logs each computation."""
    with open(task["log"], "a", encoding="utf-8") as log:
        log.write(f"{task['tilt']}\n")
    if task["tilt"] > 1.0:
        raise ValueError(f"tilt = {task['tilt']}: beyond every joint limit")
    scene = load_scene(PAPER_SCENE)
    f = natural_frequencies(scene.manipulator, Pose(0.55, task["azimuth"], task["tilt"]),
                            ModelOptions(modes=3))
    return {"frequencies_hz": f.tolist()}


def _tasks(log: Path, n: int, bad: bool = False):
    tasks = [{"azimuth": 0.3 * k, "tilt": math.radians(2 * k), "log": str(log)}
             for k in range(n)]
    if bad:
        tasks.append({"azimuth": 0.0, "tilt": 1.5, "log": str(log)})
    return tasks, [{k: t[k] for k in ("azimuth", "tilt")} for t in tasks]


def test_an_interrupted_sweep_resumes_and_computes_each_pose_once(tmp_path):
    log, cache = tmp_path / "log.txt", ResultCache(tmp_path / "cache")
    tasks, payloads = _tasks(log, 8)

    def stop_half_way(done, total):
        if done == total // 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_sweep(frequencies_task, tasks, payloads, cache, "test", workers=1,
                  progress=stop_half_way)
    assert len(log.read_text().split()) == 4
    plans = []
    results = run_sweep(frequencies_task, tasks, payloads, cache, "test", workers=1,
                        announce=plans.append)
    assert plans[0].cached == 4 and plans[0].to_compute == 4
    assert sorted(log.read_text().split()) == sorted(str(t["tilt"]) for t in tasks)
    assert all(len(r["frequencies_hz"]) == 3 for r in results)


def test_a_failed_pose_is_recorded_and_the_sweep_goes_on(tmp_path):
    log, cache = tmp_path / "log.txt", ResultCache(tmp_path / "cache")
    tasks, payloads = _tasks(log, 3, bad=True)
    results = run_sweep(frequencies_task, tasks, payloads, cache, "test", workers=2)
    assert results[-1] == {"error": "tilt = 1.5: beyond every joint limit"}
    assert all("frequencies_hz" in r for r in results[:-1])
    again = run_sweep(frequencies_task, tasks, payloads, cache, "test", workers=1)
    assert again[:-1] == results[:-1]  # from the cache; the failure is tried again
    assert len(log.read_text().split()) == 4 + 1


@pytest.mark.slow
def test_a_dask_cluster_gives_the_same_results_as_the_local_pool(tmp_path):
    from dask.distributed import LocalCluster

    tasks, payloads = _tasks(tmp_path / "log.txt", 6)
    local = run_sweep(frequencies_task, tasks, payloads, ResultCache(tmp_path / "a"), "test",
                      workers=2)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster:
        remote = run_sweep(frequencies_task, tasks, payloads, ResultCache(tmp_path / "b"),
                           "test", scheduler=cluster.scheduler_address)
    assert remote == local
