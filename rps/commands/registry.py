"""What a command is: its name, its one-line help, its options, what it runs, whether it is a
developer's (checkout only) and which extras it needs. The help text's list of commands and
rps/README.md's table are generated from these declarations (`rps.docs`)."""
from __future__ import annotations

import argparse
from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class Command:
    """`rps NAME`: `add_arguments` declares its options on its own parser, `run(args)` does
    the work and returns the exit status."""

    name: str
    help: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]
    developer: bool = False  # a developer's command: works in a checkout only
    extras: str = "fem"  # the install extras it needs (named when a module is missing)
