"""`rps update-baselines`: rewrite tests/baselines from a fresh CI run (checkout only)."""
from __future__ import annotations

import argparse

from ..args import checkout, scene_option
from .registry import Command


def add_arguments(u: argparse.ArgumentParser) -> None:
    scene_option(u)


def run(args: argparse.Namespace) -> int:
    checkout(args.command)
    from pipeline.baselines import update_command
    return update_command(args.scene)


COMMAND = Command("update-baselines", "rewrite tests/baselines from a fresh CI run (checkout "
            "only)", add_arguments, run, developer=True)
