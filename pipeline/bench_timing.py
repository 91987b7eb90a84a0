"""Medians of repeated runs, the one way every benchmark times (after a warm-up)."""
from __future__ import annotations

import statistics
import time


def median_seconds(fn, runs: int, warmup: int = 3) -> tuple[float, list[float]]:
    """The median wall time of `runs` calls of fn() after `warmup` untimed ones, and every
    time."""
    for _ in range(warmup):
        fn()
    samples = []
    for _ in range(runs):
        start = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - start)
    return statistics.median(samples), samples


def alternate(fns: dict, runs: int, warmup: int = 3) -> dict[str, list[float]]:
    """Every call's wall time of each of `fns`, called in turn `runs` times after `warmup`
    untimed rounds (so that a load that comes and goes falls on all of them alike)."""
    for _ in range(warmup):
        for fn in fns.values():
            fn()
    times: dict[str, list[float]] = {name: [] for name in fns}
    for _ in range(runs):
        for name, fn in fns.items():
            start = time.perf_counter()
            fn()
            times[name].append(time.perf_counter() - start)
    return times
