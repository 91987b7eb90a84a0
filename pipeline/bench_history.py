"""Where `make bench` keeps its figures, and what it compares them with.

A validation run replaces out/ whole, so the benchmarks write to bench/ at the checkout (beside
out/, never inside it; not committed): bench/bench.json, the latest run, and
bench/history.jsonl, one line per run (its commit, whether the tree had changes, the machine and
the headline figures). Two comparisons follow every run:

- against the newest earlier run of another commit on the same machine (same processor, core
  count and platform): each headline figure's ratio now / then. Absolute times mean something
  only on one machine, and this one is shared: a ratio far from 1 is worth a paired run
  (`git worktree` of the other commit, both benchmarks one after the other);
- against figures of earlier releases stored in the repository (pipeline/bench_reference.json):
  the per-pose model's time as a multiple of a plain scipy.linalg.eigh call on its own matrices,
  timed alternately in the same run, so the figure carries across machines as far as LAPACK's
  share does (measured paired on one machine; the file says which).
"""
from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any, Mapping, cast

from common.locations import checkout_root

from .bench_records import HistoryLine, Machine, Previous, Reference, Revision

REFERENCE = Path(__file__).with_name("bench_reference.json")
HISTORY = "history.jsonl"
HEADLINE = ("analytical_pose_seconds_median", "analytical_pose_vs_plain_eigh",
            "best_model_pose_seconds", "map_vs_plain_eigh", "map_scene_modes_vs_plain_eigh",
            "map_one_core_vs_plain_eigh", "dynamic_map_vs_frequency_map",
            "uncertainty_run_vs_batched_pose", "distributed_overhead", "fem_pose_seconds_median",
            "real_legs_map_vs_beam", "lobes_pose_vs_map_pose")


def default_out() -> Path:
    """bench/bench.json at the checkout (installed: in the working directory's bench/)."""
    root = checkout_root()
    return (root if root is not None else Path.cwd()) / "bench" / "bench.json"


def revision() -> Revision:
    """The checkout's commit and whether its tracked files differ from it (None outside a
    checkout or without git)."""
    root = checkout_root()
    if root is None:
        return Revision(commit=None, changed=None)
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, check=True,
                                capture_output=True, text=True, timeout=10).stdout.strip()
        changed = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                                 cwd=root, check=True, capture_output=True, text=True,
                                 timeout=10).stdout.strip() != ""
    except (OSError, subprocess.SubprocessError):
        return Revision(commit=None, changed=None)
    return Revision(commit=commit, changed=changed)


def cpu_model(cpuinfo: Path = Path("/proc/cpuinfo")) -> str | None:
    """The processor's model name (platform.processor() is only "x86_64" on Linux)."""
    try:
        for line in cpuinfo.read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return None


def machine() -> Machine:
    """This machine as the timing records name it: two records compare only on one machine."""
    import os
    import platform
    import sys

    return Machine(python=sys.version.split()[0], platform=platform.platform(),
                   processor=platform.processor() or platform.machine(),
                   cpu_model=cpu_model(), cpu_count=os.cpu_count())


def _same_machine(a: Mapping[str, Any], b: Mapping[str, Any]) -> bool:
    keys = ("processor", "cpu_model", "cpu_count", "platform")
    return all(a.get(k) == b.get(k) for k in keys)


def headline(result: Mapping[str, Any]) -> dict[str, float]:
    return {k: result[k] for k in HEADLINE if isinstance(result.get(k), (int, float))}


def previous_run(history: Path, machine: Machine, commit: str | None) -> HistoryLine | None:
    """The newest run in `history` of another commit on the same machine."""
    if not history.is_file():
        return None
    found: HistoryLine | None = None
    for line in history.read_text().splitlines():
        try:
            entry = json.loads(line)
        except json.JSONDecodeError:  # a line cut by a killed run: skip it
            continue
        if (isinstance(entry, dict) and _same_machine(entry.get("machine", {}), machine)
                and entry.get("commit") != commit):
            found = cast(HistoryLine, entry)  # as `record` wrote it (older lines lack keys)
    return found


def against(now: dict[str, float], then: HistoryLine | None) -> Previous | None:
    """Each headline figure now / then, for the figures both runs have."""
    if then is None:
        return None
    figures = then.get("figures", {})
    return {"commit": then.get("commit"), "changed": then.get("changed"),
            "date": then.get("date"),
            "ratios": {k: v / figures[k] for k, v in now.items()
                       if isinstance(figures.get(k), (int, float)) and figures[k] > 0}}


def reference_ratios(result: Mapping[str, Any], reference: Path = REFERENCE
                     ) -> Reference | None:
    """The per-pose model against each stored release: (pose / plain eigh) now over then."""
    if not reference.is_file():
        return None
    stored = json.loads(reference.read_text())
    timings = result.get("analytical", {})
    out = {}
    for release, figures in stored.get("releases", {}).items():
        out[release] = {setting: timings[setting]["vs_plain_eigh"] / ratio
                        for setting, ratio in figures.get("vs_plain_eigh", {}).items()
                        if setting in timings}
    return {"measured": stored.get("measured"), "now_over_then": out}


def record(history: Path, result: Mapping[str, Any]) -> None:
    """Append this run's line to `history`."""
    entry = {"date": result.get("date"), "commit": result.get("commit"),
             "changed": result.get("changed"), "machine": result.get("machine"),
             "figures": headline(result)}
    history.parent.mkdir(parents=True, exist_ok=True)
    with history.open("a") as stream:
        stream.write(json.dumps(entry) + "\n")
