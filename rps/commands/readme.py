"""`rps readme`: refresh README.md's results block from a results.json (checkout only)."""
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


def run(args: argparse.Namespace) -> int:
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


COMMAND = Command("readme", "refresh README.md's results block from results.json (checkout "
            "only)", add_arguments, run)
