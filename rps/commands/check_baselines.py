"""`rps check-baselines`: recompute the CI error tables and compare them with tests/baselines
(checkout only)."""
from __future__ import annotations

import argparse

from runtime.places import path_argument

from ..args import checkout
from .registry import Command


def add_arguments(c: argparse.ArgumentParser) -> None:
    c.add_argument("--results", metavar="PATH", type=path_argument,
                   help="read the tables from this results.json "
                   "(computed at the baselines' mesh size) instead of recomputing them "
                   "(default: none)")


def run(args: argparse.Namespace) -> int:
    checkout(args.command)
    from pipeline.baselines import check_command
    return check_command(args.results)


COMMAND = Command("check-baselines", "recompute the CI error tables and compare them with "
            "tests/baselines (checkout only)", add_arguments, run, developer=True)
