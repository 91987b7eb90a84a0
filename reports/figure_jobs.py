"""The report's figures as jobs: drawn in parallel, and drawn once.

A job is a drawing function, its inputs and the files it writes. `draw` runs every job whose
picture is not already in the figure cache on a small process pool (matplotlib and VTK hold the
GIL while they draw, so threads would not help), and copies the cached pictures of the others.
A job's cache key is what the picture shows: the function's name, its inputs (an input file,
such as a FEM mode file, by the SHA-256 of its contents; arrays by their bytes), the source of
this package and the versions of the drawing libraries. A warm run of an unchanged scene draws
nothing; a changed number redraws exactly the figures that show it. Entries are checksummed
(`runtime.cache.ResultCache`): a damaged picture is dropped and drawn again.

A job that fails with an expected error (ValueError, or the `errors` it names) does not stop
the others; `Outcome.error` carries it for the caller, which decides (a note, or a failure).
"""
from __future__ import annotations

import dataclasses
import hashlib
import shutil
import tempfile
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from typing import Any, Callable

import numpy as np

PACKAGE = Path(__file__).resolve().parent
LIBRARIES = ("matplotlib", "pyvista", "vtk", "numpy")
KIND = "figures"


@dataclass
class Job:
    draw: Callable[..., Any]
    outputs: tuple[Path, ...]  # the files `draw` writes
    args: tuple = ()
    kwargs: dict = field(default_factory=dict)
    errors: tuple[type[BaseException], ...] = ()  # expected failures besides ValueError


@dataclass
class Outcome:
    value: Any = None  # what `draw` returned (JSON-able)
    error: BaseException | None = None
    cached: bool = False


def _canonical(value, digest, outputs: dict) -> None:
    """Feed a deterministic description of `value` to `digest`: an input file by its
    contents, an output file by its place among the job's outputs (not by its path, which
    differs from run to run)."""
    if isinstance(value, Path) and value in outputs:
        digest.update(f"output:{outputs[value]};".encode())
    elif isinstance(value, Path):
        digest.update(b"file:")
        digest.update(hashlib.sha256(value.read_bytes()).digest() if value.is_file()
                      else str(value).encode())
    elif isinstance(value, np.ndarray):
        digest.update(f"array:{value.dtype.str}:{value.shape}:".encode())
        digest.update(np.ascontiguousarray(value).tobytes())
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        digest.update(f"{type(value).__qualname__}(".encode())
        for f in dataclasses.fields(value):
            digest.update(f.name.encode())
            _canonical(getattr(value, f.name), digest, outputs)
        digest.update(b")")
    elif isinstance(value, dict):
        digest.update(b"{")
        for k in value:
            _canonical(k, digest, outputs)
            _canonical(value[k], digest, outputs)
        digest.update(b"}")
    elif isinstance(value, (list, tuple)):
        digest.update(b"[" if isinstance(value, list) else b"(")
        for item in value:
            _canonical(item, digest, outputs)
        digest.update(b"]")
    elif value is None or isinstance(value, (bool, int, float, str, np.generic)):
        digest.update(f"{type(value).__name__}:{value!r};".encode())
    else:
        raise TypeError(f"figure input of type {type(value).__name__} has no cache key")


def _code() -> bytes:
    """The source this package draws with (`runtime.cache.code_fingerprint` of its modules)
    and the versions of the drawing libraries."""
    from runtime.cache import ROOT, code_fingerprint

    modules = tuple(".".join(p.relative_to(ROOT).with_suffix("").parts)
                    for p in sorted(PACKAGE.rglob("*.py")))
    versions = []
    for name in LIBRARIES:
        try:
            versions.append(f"{name}={metadata.version(name)}")
        except metadata.PackageNotFoundError:
            versions.append(f"{name}=none")
    return f"{code_fingerprint(modules)};{';'.join(versions)}".encode()


def job_key(job: Job, code: bytes) -> str:
    digest = hashlib.sha256(code)
    digest.update(f"{job.draw.__module__}.{job.draw.__qualname__}:{len(job.outputs)}".encode())
    outputs = {path: k for k, path in enumerate(job.outputs)}
    _canonical(job.args, digest, outputs)
    _canonical(job.kwargs, digest, outputs)
    return digest.hexdigest()[:24]


def _run(job: Job) -> Outcome:
    import os

    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    expected: tuple[type[BaseException], ...] = (ValueError, *job.errors)
    try:
        return Outcome(job.draw(*job.args, **job.kwargs))
    except expected as exc:
        return Outcome(error=exc)


def draw(jobs: list[Job], cache_dir: Path | None = None, workers: int = 1) -> list[Outcome]:
    """Every job's outcome, in order; its files written (drawn, or copied from the cache)."""
    from runtime.cache import ResultCache

    cache = ResultCache(cache_dir) if cache_dir is not None else None
    code = _code()
    keys = [job_key(job, code) for job in jobs]
    outcomes: list[Outcome | None] = [None] * len(jobs)
    for i, (job, key) in enumerate(zip(jobs, keys)):
        hit = cache.get(KIND, key, required=("value",)) if cache is not None else None
        if hit is None or cache is None:  # a hit: a cache
            continue
        for k, target in enumerate(job.outputs):
            shutil.copyfile(cache.side_file(KIND, key, f".{k}{target.suffix}"), target)
        outcomes[i] = Outcome(hit["value"], cached=True)
    todo = [i for i, o in enumerate(outcomes) if o is None]
    if workers > 1 and len(todo) > 1:
        done = _in_processes([jobs[i] for i in todo], min(workers, len(todo)))
    else:
        done = [_run(jobs[i]) for i in todo]
    for i, outcome in zip(todo, done):
        outcomes[i] = outcome
        if cache is None or outcome.error is not None:
            continue
        job = jobs[i]
        with tempfile.TemporaryDirectory(dir=_tmp(cache)) as tmp:
            files = {}
            for k, source in enumerate(job.outputs):
                copy = Path(tmp) / f"{k}{source.suffix}"
                shutil.copyfile(source, copy)
                files[f".{k}{source.suffix}"] = copy
            cache.put(KIND, keys[i], {"value": outcome.value}, files)
    return outcomes  # type: ignore[return-value]


def _in_processes(jobs: list[Job], workers: int) -> list[Outcome]:
    """The jobs on a fresh pool of forked processes. Not joblib's reusable loky pool: the
    report is drawn in a forked child of the run (common.worker), which inherits the run's
    own pool and would wait forever on workers that are not its own (measured: a hang). Not
    spawned either: spawning starts multiprocessing's resource tracker, which outlives a
    stopped report and writes to the caller's terminal after it."""
    import multiprocessing
    import os
    from concurrent.futures import ProcessPoolExecutor

    from common.worker import die_with_parent

    method = "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"
    # its workers die with this process: a report stopped by a signal (common.worker kills
    # the child that draws it) leaves no worker drawing on, nor holding the caller's pipes
    with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context(method),
                             initializer=die_with_parent, initargs=(os.getpid(),)) as pool:
        return list(pool.map(_run, jobs))


def _tmp(cache) -> Path:
    path = Path(cache.directory) / "tmp"
    path.mkdir(parents=True, exist_ok=True)
    return path
