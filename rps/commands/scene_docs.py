"""`rps scene-docs`: rewrite docs/scenes.md from the scene declarations (checkout only)."""
from __future__ import annotations

import argparse

from ..args import checkout
from .registry import Command


def add_arguments(p: argparse.ArgumentParser) -> None:
    pass


def run(args: argparse.Namespace) -> int:
    checkout(args.command)
    from scene.docs import write
    print(f"wrote {write()}")
    return 0


COMMAND = Command("scene-docs", "rewrite docs/scenes.md from the scene declarations (checkout "
                  "only)", add_arguments, run)
