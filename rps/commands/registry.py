"""What a command is: its name, its one-line help, its options and what it runs."""
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
