"""The commands of `rps`, one module each, registered once: adding a command is one module with
a `COMMAND` declaration (copy `cache.py`, the smallest) and one line below."""
from __future__ import annotations

from . import (
               analytical,
               cache,
               check_baselines,
               correlate,
               design,
               fem,
               frf,
               identify,
               lobes,
               modes,
               readme,
               report,
               scene_docs,
               uncertainty,
               update_baselines,
               validate,
               verify,
               workspace,
)
from .registry import Command

COMMANDS: tuple[Command, ...] = (
    analytical.COMMAND,
    fem.COMMAND,
    workspace.COMMAND,
    design.COMMAND,
    correlate.COMMAND,
    identify.COMMAND,
    modes.COMMAND,
    frf.COMMAND,
    lobes.COMMAND,
    uncertainty.COMMAND,
    validate.COMMAND,
    verify.COMMAND,
    cache.COMMAND,
    check_baselines.COMMAND,
    readme.COMMAND,
    report.COMMAND,
    scene_docs.COMMAND,
    update_baselines.COMMAND,
)

__all__ = ["COMMANDS", "Command"]
