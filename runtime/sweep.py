"""Sweeps: one pose is one task, run locally on a process pool or on a Dask cluster.

- Locally: joblib's loky process pool, one BLAS thread per worker (`inner_max_num_threads`),
  results streamed back as they finish.
- Past one machine: `scheduler="tcp://host:8786"` sends the same tasks to a running
  `dask.distributed` scheduler (its workers need this package and the cache directory).
- Every task's result is cached by content (`ResultCache`, kind given by the caller) as soon
  as it arrives, so an interrupted sweep resumes without recomputing a finished task.
- A task that fails is recorded with its one-line error (`{"error": ...}`) and the sweep goes
  on; failures are not cached, so the next run tries them again.
- Before launching, the caller is told how many tasks must be computed (and, given a measured
  time per task, how long that should take); a progress bar shows tasks done and time left.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, Callable, Mapping

from common.errors import ComputeError

from .cache import ResultCache, content_key

TaskFn = Callable[[Any], Mapping[str, Any]]  # a task's answer: a JSON object


@dataclass(frozen=True)
class SweepPlan:
    total: int
    cached: int
    to_compute: int
    estimated_seconds: float | None


def _safe(fn: TaskFn, task) -> Mapping[str, Any]:
    """fn(task), or {"error": one line} for an expected failure of this task."""
    try:
        return fn(task)
    except (ValueError, RuntimeError, OSError, ArithmeticError) as exc:
        return {"error": " ".join(str(exc).split())[:300] or type(exc).__name__}


def run_sweep(fn: TaskFn, tasks: list, payloads: list, cache: ResultCache, kind: str,
              workers: int = 2, scheduler: str | None = None,
              announce: Callable[[SweepPlan], None] | None = None,
              seconds_per_task: float | None = None, progress=None,
              code: tuple[str, ...] = ()) -> list[Mapping[str, Any]]:
    """Results of fn(task) for every task, in task order.

    `payloads[i]` is what determines task i's result (its cache key), with the source of
    `code` (the modules fn computes with beyond the model packages, see
    runtime.cache.code_fingerprint). `progress(done, total)` is called as results arrive.
    """
    keys = [content_key({"kind": kind, "task": p}, code) for p in payloads]
    results: list[dict | None] = [cache.get(kind, k) for k in keys]
    todo = [i for i, r in enumerate(results) if r is None]
    if announce is not None:
        announce(SweepPlan(len(tasks), len(tasks) - len(todo), len(todo),
                           None if seconds_per_task is None
                           else len(todo) * seconds_per_task / max(workers, 1)))
    done = len(tasks) - len(todo)
    if progress is not None:
        progress(done, len(tasks))

    def store(i: int, value: dict) -> None:
        nonlocal done
        results[i] = value
        if not value.get("error"):
            cache.put(kind, keys[i], value)
        done += 1
        if progress is not None:
            progress(done, len(tasks))

    _dispatch(fn, tasks, todo, workers, scheduler, store)
    return results  # type: ignore[return-value]


def map_tasks(fn: TaskFn, tasks: list, workers: int = 2,
              scheduler: str | None = None) -> list[Mapping[str, Any]]:
    """fn(task) for every task on the sweep's workers, in task order, with no result cache of
    its own (for tasks that cache what they compute, such as FEM solves): a failed task gives
    its {"error": one line}."""
    results: list[dict | None] = [None] * len(tasks)

    def store(i: int, value: dict) -> None:
        results[i] = value

    _dispatch(fn, tasks, list(range(len(tasks))), workers, scheduler, store)
    return results  # type: ignore[return-value]


def _dispatch(fn: TaskFn, tasks: list, todo: list[int], workers: int, scheduler: str | None,
              store) -> None:
    if not todo:
        return
    if scheduler:
        _run_dask(fn, tasks, todo, scheduler, store)
    elif workers <= 1 or len(todo) == 1:
        for i in todo:
            store(i, _safe(fn, tasks[i]))
    else:
        _run_local(fn, tasks, todo, workers, store)


# loky retires a worker whose memory grew 300 MB above its start (its leak guard,
# loky.process_executor._MAX_MEMORY_LEAK_SIZE) and then warns "A worker stopped while some jobs
# were given to the executor ... memory leak". Our workers grow by design, not by a leak: a FEM
# factorisation's peak and the per-process mesh and harmonic caches. The retired worker has
# finished its task and loky starts a fresh one, so nothing is lost; only that message is
# silenced, only around our pool.
LOKY_RESTART = "A worker stopped while some jobs were given to the executor"


def _run_local(fn: TaskFn, tasks: list, todo: list[int], workers: int, store) -> None:
    import warnings

    from joblib import Parallel, delayed, parallel_config

    with warnings.catch_warnings(), parallel_config(backend="loky", inner_max_num_threads=1):
        warnings.filterwarnings("ignore", message=LOKY_RESTART, category=UserWarning)
        stream = Parallel(n_jobs=workers, return_as="generator_unordered")(
            delayed(_indexed)(fn, i, tasks[i]) for i in todo)
        for i, value in stream:
            store(i, value)


def _indexed(fn: TaskFn, i: int, task) -> tuple[int, Mapping[str, Any]]:
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    return i, _safe(fn, task)


def _run_dask(fn: TaskFn, tasks: list, todo: list[int], address: str, store) -> None:
    try:
        from dask.distributed import Client, as_completed
    except ImportError as exc:  # pragma: no cover - dask is a declared dependency
        raise ComputeError(f"--scheduler {address}: dask.distributed is not installed") from exc
    try:
        client = Client(address, timeout="10s")
    except (OSError, TimeoutError) as exc:
        raise ComputeError(f"--scheduler {address}: cannot reach the Dask scheduler "
                           f"({' '.join(str(exc).split())})") from None
    try:
        # a result is released on the cluster as soon as it is here, before it is stored: a
        # worker that dies once the release has reached the scheduler (the client sends such
        # messages every few milliseconds) holds nothing this sweep still wants, so nothing
        # that arrived is computed again
        for future in as_completed([client.submit(_indexed, fn, i, tasks[i], pure=False)
                                    for i in todo]):
            i, value = future.result()
            future.release()
            store(i, value)
    finally:
        client.close()
