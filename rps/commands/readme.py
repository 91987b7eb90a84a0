"""`rps readme`: refresh README.md's results block from a results.json (checkout only)."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..args import checkout
from .registry import Command


def add_arguments(r: argparse.ArgumentParser) -> None:
    r.add_argument("--results", metavar="PATH", type=Path, default=Path("out/results.json"),
                   help="results file of a full run")


def run(args: argparse.Namespace) -> int:
    from reports.readme import update_readme
    from results import read

    readme = checkout(args.command) / "README.md"
    update_readme(readme, read(args.results))
    return 0


COMMAND = Command("readme", "refresh README.md's results block from results.json (checkout "
            "only)", add_arguments, run)
