"""A setting's time per pose is measured once per machine and code: the fidelity choice, the
variant table and the speed-vs-error chart quote the same measurement, and a warm run the one
made when the cache entry was."""
from __future__ import annotations

import pytest

from runtime.cache import ResultCache
from solvers import timing


@pytest.fixture
def counted(monkeypatch):
    calls = []

    def fake(scene, case, options, runs):
        calls.append((case.name, options.elements, runs))
        return 1e-3 * len(calls)

    monkeypatch.setattr(timing, "time_model", fake)
    return calls


def test_one_measurement_serves_every_step_of_a_run(scene, tmp_path, counted):
    cache = ResultCache(tmp_path)
    case = next(iter(scene.cases.values()))
    first = timing.seconds_per_pose(scene, case, scene.analytical, cache)
    again = timing.seconds_per_pose(scene, case, scene.analytical, cache)
    assert again == first and len(counted) == 1
    assert counted[0][2] == timing.RUNS


def test_another_setting_pose_or_machine_is_measured_anew(scene, tmp_path, counted,
                                                         monkeypatch):
    from dataclasses import replace

    cache = ResultCache(tmp_path)
    cases = list(scene.cases.values())
    timing.seconds_per_pose(scene, cases[0], scene.analytical, cache)
    timing.seconds_per_pose(scene, cases[0], replace(scene.analytical, elements=5), cache)
    timing.seconds_per_pose(scene, cases[1], scene.analytical, cache)
    assert len(counted) == 3
    monkeypatch.setattr(timing, "machine", lambda: {"node": "elsewhere"})
    timing.seconds_per_pose(scene, cases[0], scene.analytical, cache)
    assert len(counted) == 4


def test_without_a_cache_it_is_always_measured(scene, counted):
    case = next(iter(scene.cases.values()))
    timing.seconds_per_pose(scene, case, scene.analytical, None)
    timing.seconds_per_pose(scene, case, scene.analytical, None)
    assert len(counted) == 2
