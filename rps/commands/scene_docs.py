"""`rps scene-docs`: rewrite the generated documentation from its declarations: docs/scenes.md
and docs/campaigns.md (scene and campaign files), rps/README.md's table of commands (the
registry) (checkout only)."""
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

    from ..docs import write as write_commands
    from ..docs import write_outputs
    print(f"wrote {write()}")
    print(f"wrote {write_campaigns()}")
    print(f"wrote {write_commands(args.registry)}")
    print(f"wrote {write_outputs()}")
    return 0


COMMAND = Command("scene-docs", "rewrite docs/scenes.md, docs/campaigns.md and the "
                  "commands table of rps/README.md from the declarations (checkout only)",
                  add_arguments, run, developer=True)
