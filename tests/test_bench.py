"""`make bench`'s machinery (never its timings): where it writes, what it compares with, how it
counts flops, and the distributed sweep surviving a killed worker."""
from __future__ import annotations

import json

import numpy as np
import pytest

from common.locations import checkout_root
from pipeline.bench_history import (
    HISTORY,
    against,
    default_out,
    headline,
    previous_run,
    record,
    reference_ratios,
)
from pipeline.bench_kernel import core_peak, stage_flops
from scene import load_scene
from tests.conftest import PAPER_SCENE

MACHINE = {"python": "3.11.7", "platform": "Linux-x", "processor": "x86_64", "cpu_count": 2}


def test_the_figures_are_kept_where_a_validation_does_not_replace_them():
    out = default_out()
    assert out.name == "bench.json" and out.parent.name == "bench"
    root = checkout_root()
    if root is not None:
        assert not out.resolve().is_relative_to((root / "out").resolve())


def test_a_run_is_compared_with_the_newest_run_of_another_commit_on_the_same_machine(tmp_path):
    history = tmp_path / HISTORY
    runs = [("aaa", MACHINE, 2.0), ("bbb", MACHINE, 1.0), ("ccc", {**MACHINE, "cpu_count": 8},
                                                            9.0), ("ddd", MACHINE, 4.0)]
    for commit, machine, seconds in runs:
        record(history, {"date": commit, "commit": commit, "changed": False, "machine": machine,
                         "best_model_pose_seconds": seconds, "not_a_headline": 1.0})
    history.write_text(history.read_text() + '{"cut by a kill')  # a torn last line
    then = previous_run(history, MACHINE, "ddd")
    assert then["commit"] == "bbb"  # not ddd itself, not the other machine's ccc
    assert against({"best_model_pose_seconds": 0.5}, then)["ratios"] == {
        "best_model_pose_seconds": 0.5}
    assert previous_run(tmp_path / "none.jsonl", MACHINE, "x") is None
    assert headline({"best_model_pose_seconds": 1.0, "not_a_headline": 2.0, "map": {}}) == {
        "best_model_pose_seconds": 1.0}


def test_the_stored_release_figures_are_compared_as_ratios_to_plain_eigh(tmp_path):
    reference = tmp_path / "reference.json"
    reference.write_text(json.dumps({"measured": "paired", "releases": {
        "old": {"vs_plain_eigh": {"s=3": 4.0, "s=99": 1.0}}}}))
    result = {"analytical": {"s=3": {"vs_plain_eigh": 3.0}}}
    assert reference_ratios(result, reference)["now_over_then"] == {"old": {"s=3": 0.75}}


def test_the_shipped_release_figures_name_how_they_were_measured():
    from pipeline.bench_history import REFERENCE

    stored = json.loads(REFERENCE.read_text())
    assert "paired" in stored["measured"]
    assert all(set(f["vs_plain_eigh"]) <= {"s=1", "s=3", "s=6", "s=10"}
               for f in stored["releases"].values())


def test_flops_and_the_core_peak(tmp_path):
    flops = stage_flops(126)
    assert flops["standard_form"] + flops["eigenvalues"] == pytest.approx(
        (1 / 3 + 1 + 4 / 3) * 126 ** 3)  # 5.3 Mflop: Cholesky, ?sygst, ?sytrd
    cpuinfo = tmp_path / "cpuinfo"
    cpuinfo.write_text("processor\t: 0\ncpu MHz\t\t: 2500.000\nflags\t\t: fpu sse2 avx fma avx2\n")
    peak = core_peak(cpuinfo)
    assert peak["flops_per_cycle"] == 16 and peak["gflops"] == pytest.approx(40.0)
    cpuinfo.write_text("cpu MHz\t\t: 3000.0\nflags\t\t: fpu sse2 avx\n")
    assert core_peak(cpuinfo)["gflops"] == pytest.approx(24.0)
    assert core_peak(tmp_path / "absent") is None


def test_a_pose_task_is_the_batched_model(tmp_path):
    from analytical.model import natural_frequencies
    from analytical.params import Pose
    from pipeline.bench_distributed import pose_frequencies, sweep_tasks

    scene = load_scene(PAPER_SCENE)
    tasks, payloads = sweep_tasks(scene, (2, 3, 4), per_task=10)
    assert [len(t.heights) for t in tasks] == [10, 10, 4] and len(payloads) == 3
    task = tasks[1]
    hz = pose_frequencies(task)["frequencies_hz"]
    for k in (0, 5, 9):
        pose = Pose(float(task.heights[k]), float(task.azimuths[k]), float(task.tilts[k]))
        np.testing.assert_allclose(hz[k], natural_frequencies(scene.manipulator, pose,
                                                              scene.analytical), rtol=1e-9)


@pytest.mark.slow
def test_a_killed_worker_loses_nothing_that_had_arrived(tmp_path):
    """A Dask worker killed part-way: the tasks whose results had reached the sweep are never
    computed again, every task is computed, the results are the one-process run's, and the
    sweep run again on its cache computes nothing."""
    from dask.distributed import LocalCluster

    from pipeline.bench_distributed import difference, killed_worker_sweep, sweep_tasks
    from runtime.cache import ResultCache
    from runtime.sweep import run_sweep

    scene = load_scene(PAPER_SCENE)
    tasks, payloads = sweep_tasks(scene, (4, 10, 30), per_task=100)
    from pipeline.bench_distributed import KIND, pose_frequencies

    one = run_sweep(pose_frequencies, tasks, payloads, ResultCache(tmp_path / "one"), KIND,
                    workers=1)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster:
        killed = killed_worker_sweep(tasks, payloads, cluster.scheduler_address,
                                     ResultCache(tmp_path / "killed"), tmp_path / "log.txt",
                                     kill_at=4)
    counts = killed["computed"]
    assert killed["killed_pid"] not in killed["worker_pids_after"]  # it did die
    assert len(killed["before_kill"]) == 4
    assert all(counts[i] == 1 for i in killed["before_kill"])
    assert min(counts) >= 1
    assert difference(killed["results"], one) == 0.0
    assert killed["rerun_to_compute"] == 0
