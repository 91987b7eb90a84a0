"""`rps readme`: refresh README.md's results block from a results.json, or (--timings) its
timings block from the newest records of `make` and `make test` (checkout only)."""
from __future__ import annotations

import argparse
from pathlib import Path

from common.errors import InputError
from runtime.places import path_argument

from ..args import checkout
from .registry import Command


def add_arguments(r: argparse.ArgumentParser) -> None:
    r.add_argument("--results", metavar="PATH", type=path_argument,
                   default=Path("out/results.json"), help="results file of a full run")
    r.add_argument("--timings", action="store_true",
                   help="refresh the timings block instead, from the newest `make` and `make "
                   "test` records of this machine (bench/timings.jsonl) into docs/timings.json")


def timings(root: Path) -> int:
    """docs/timings.json updated with this machine's newest records of each kind, and the
    README's timings block rendered from it."""
    import json

    from common.atomic import write_text_atomic
    from pipeline.bench_history import machine
    from pipeline.make_timing import TIMINGS, bench_dir, newest, update_readme

    found = newest(bench_dir() / TIMINGS, machine())
    if not found:
        raise InputError(f"{bench_dir() / TIMINGS}: no record of `make` or `make test` on this "
                         "machine; run them first (each records itself when it succeeds)")
    stored = root / "docs" / "timings.json"
    records = json.loads(stored.read_text(encoding="utf-8")) if stored.is_file() else {}
    records.update(found)
    write_text_atomic(stored, json.dumps(records, indent=1, sort_keys=True) + "\n")
    update_readme(root / "README.md", records)
    print(f"wrote {stored} and README.md's timings block ({', '.join(sorted(found))} "
          "from this machine)")
    return 0


def run(args: argparse.Namespace) -> int:
    if args.timings:
        return timings(checkout(args.command))
    from reports.readme import update_readme
    from results import read
    from studies import RECORDS

    readme = checkout(args.command) / "README.md"
    results = read(args.results, RECORDS)
    where = f"--results {args.results}"
    if results["profile"] != "full":
        raise InputError(f"{where}: a run of the {results['profile']} profile; the README's "
                         "block is written from a full run (`make`)")
    for case in results["cases"]:  # a run whose folder is whole, not a results file alone
        for key in ("vtu", "pvd"):
            name = case["fem"][key]
            if name is not None and not (args.results.parent / name).is_file():
                raise InputError(f"{where}: names {name} (case {case['name']}), which is not "
                                 "beside it: an incomplete or moved run; rerun `make`")
    update_readme(readme, results)
    return 0


COMMAND = Command("readme", "refresh README.md's results block from results.json, or with "
                  "--timings its timings block (checkout only)", add_arguments, run,
                  developer=True)
