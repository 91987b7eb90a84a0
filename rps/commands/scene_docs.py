"""`rps scene-docs`: rewrite docs/scenes.md and docs/campaigns.md from the declarations of
scene and campaign files (checkout only)."""
from __future__ import annotations

import argparse

from ..args import checkout
from .registry import Command


def add_arguments(p: argparse.ArgumentParser) -> None:
    pass


def run(args: argparse.Namespace) -> int:
    checkout(args.command)
    from modaltest.docs import write as write_campaigns
    from scene.docs import write
    print(f"wrote {write()}")
    print(f"wrote {write_campaigns()}")
    return 0


COMMAND = Command("scene-docs", "rewrite docs/scenes.md and docs/campaigns.md from the "
                  "declarations (checkout only)", add_arguments, run)
