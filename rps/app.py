"""Command line: `rps` (or `python -m rps`) and its commands, each a module of `rps.commands`
registered once (the help's list of commands is made from the registry). Lengths in mm and
angles in degrees at this edge; SI inside.

Every expected failure (bad scene value, unreachable pose, solver failure) prints one line on
stderr naming the offending value and exits with status 2, without a traceback. The commands
are modules of `rps.commands`, each registered once with its options.
"""
from __future__ import annotations

import argparse
import re
import signal
import sys
import textwrap
from pathlib import Path

from common.errors import RpsError
from common.locations import DISTRIBUTION
from common.messages import failed

from .commands import COMMANDS

EXIT_BAD_INPUT = 2
COMMANDS_BY_NAME = {c.name: c for c in COMMANDS}


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage error is one line on stderr and exit status 2; a refused value
    is named first, as typed (`error: --tilt 100 deg: must be ...`)."""

    def error(self, message: str):  # noqa: D401 - argparse hook
        message = re.sub(r"^argument (--[\w-]+): '", r"\1 '", message)  # a refused value
        where = "" if message.startswith("--") else f"{self.prog}: "
        self.exit(EXIT_BAD_INPUT, f"error: {where}{message}\n")


class _Help(argparse.RawDescriptionHelpFormatter):
    """Help with every option's default beside its text (units are in the text and the
    metavars: MM, DEG); an option without a fixed default says what it defaults to."""

    def __init__(self, prog):
        super().__init__(prog, max_help_position=30, width=100)

    def _split_lines(self, text, width):
        return textwrap.wrap(" ".join(text.split()), width, break_on_hyphens=False)

    def _get_help_string(self, action):
        text = action.help or ""
        if ("default" in text or not action.option_strings or action.default is None
                or action.default is False or action.default is argparse.SUPPRESS):
            return text
        return f"{text} (default: %(default)s)"


class _Version(argparse.Action):
    """--version: the project's version and commit, worked out only when asked."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, **kwargs):
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        from .version import describe
        print(describe())
        parser.exit(0)


def description() -> str:
    """What `rps --help` says above its options: what the commands are, from the registry."""
    users = textwrap.fill("commands: " + ", ".join(c.name for c in COMMANDS
                                                  if not c.developer), 92)
    developers = textwrap.fill("developer commands (in a checkout): " + ", ".join(
        c.name for c in COMMANDS if c.developer), 92)
    return textwrap.dedent("""\
        Elastodynamics of a 3-RPS or 3-PRS parallel manipulator: a fast analytical model,
        validated against a 3D solid FEM. Lengths in mm and angles in degrees here; SI inside.

        {users}
        {developers}

        `rps COMMAND --help` shows a command's options with their defaults and units. Bad input
        is one line on stderr naming what was typed, exit status 2, nothing written.""").format(
        users=users, developers=developers)


def build_parser(prog: str = "rps") -> argparse.ArgumentParser:
    parser = _Parser(prog=prog, description=description(), formatter_class=_Help)
    parser.add_argument("--version", action=_Version,
                        help="print the project's version and git commit, and exit")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser,
                                metavar="COMMAND", title="commands")
    for command in COMMANDS:
        p = sub.add_parser(command.name, help=command.help, description=command.help,
                           formatter_class=_Help)
        command.add_arguments(p)
        p.set_defaults(registry=COMMANDS)  # the registry, for a command that lists the others
    return parser


def _terminate(signum, frame):
    """SIGTERM (kill) unwinds like Ctrl-C, so staged outputs are removed on the way out."""
    raise KeyboardInterrupt


def _check_places(args: argparse.Namespace) -> None:
    """The checks every command that takes a place option shares, before it reads anything:
    a --cache given must be (or be able to become) a directory the run can write into,
    whether or not this run's model stores anything there (runtime/places.py)."""
    cache = getattr(args, "cache", None)
    if cache is not None:
        from runtime.places import check_writable_dir
        check_writable_dir(cache, "--cache")


def main(argv: list[str] | None = None) -> int:
    signal.signal(signal.SIGTERM, _terminate)
    prog = "rps" if Path(sys.argv[0]).name == "rps" else "python -m rps"
    parser = build_parser(prog)
    args = parser.parse_args(argv)
    try:
        _check_places(args)
        return COMMANDS_BY_NAME[args.command].run(args)
    except ModuleNotFoundError as exc:
        extras = COMMANDS_BY_NAME[args.command].extras
        print(f"error: {exc.name} is not installed; `{prog} {args.command}` needs "
              f"pip install '{DISTRIBUTION}[{extras}]'", file=sys.stderr)
        return EXIT_BAD_INPUT
    except (KeyboardInterrupt, RpsError, OSError) as exc:  # anything else is a bug: traceback
        return failed(exc)
