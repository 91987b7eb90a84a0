"""Command-line numbers read through the declarations of their scene keys.

Every number `rps` takes is parsed by the `setting(...)` declaration that also validates the
scene key of the same quantity (`--height` by [cases.NAME] height_mm, `--size` by [fem]
mesh_size_mm, `--modes` by [fidelity] modes, ...): one range, one unit, one meaning. The value
lands in the parsed arguments in SI; what the user typed is kept beside it (`args.typed`), so
an error found later (an unreachable pose, a mesh too large) can name it first.

The workspace map's grid and the sweep's workers have no scene key; they are declared here.
"""
from __future__ import annotations

import argparse
from dataclasses import dataclass

from common.settings import Setting, check_settings, setting, short_text, spec_of

MAX_MAP_POSES = 100_000  # poses of one workspace map: about a minute of the batched model


@dataclass(frozen=True)
class MapGrid:
    """The polar grid of `rps workspace` (the paper's Fig. 6)."""

    layers: int = setting(8, kind=int, minimum=1, maximum=200, scene=False,
                          doc="height layers of the workspace map")
    rings: int = setting(6, kind=int, minimum=1, maximum=100, scene=False,
                         doc="tilt rings per layer")
    azimuths: int = setting(36, kind=int, minimum=1, maximum=720, scene=False,
                            doc="azimuths per ring (720: every half degree)")

    def __post_init__(self):
        check_settings(self)


@dataclass(frozen=True)
class Workers:
    workers: int = setting(None, kind=int, minimum=1, maximum=1024, scene=False,
                           doc="local worker processes of the sweep")


class _Declared(argparse.Action):
    """Store the option's value in SI, checked by `spec`; keep the text as typed."""

    def __init__(self, option_strings, dest, spec: Setting | None = None, **kwargs):
        self.spec = spec
        super().__init__(option_strings, dest, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        try:
            value = self.spec.from_text(values, option_string)
        except ValueError as exc:
            raise argparse.ArgumentError(None, str(exc)) from None
        setattr(namespace, self.dest, value)
        typed = dict(getattr(namespace, "typed", None) or {})
        typed[self.dest] = typed_text(option_string, values, self.spec)
        namespace.typed = typed


def typed_text(option: str, text: str, spec: Setting) -> str:
    """`--height 5000 mm`: an option as the user typed it, with its unit."""
    return f"{option} {short_text(text)}" + (f" {spec.unit}" if spec.unit else "")


def declared_option(parser: argparse.ArgumentParser, option: str, cls, name: str,
                    help: str, **kwargs) -> argparse.Action:
    """`parser.add_argument(option)` read through the declaration of `cls.name`; the help
    ends with the admitted range in the edge unit."""
    spec = spec_of(cls, name)
    text = f"{help}; {spec.range_text()}"
    return parser.add_argument(option, action=_Declared, spec=spec, help=text, **kwargs)


def typed(args: argparse.Namespace, *dests: str) -> str:
    """What the user typed of these options ('--height 5000 mm, --tilt 10 deg'), or ''."""
    given = getattr(args, "typed", None) or {}
    return ", ".join(given[d] for d in dests if d in given)
