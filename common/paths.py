"""File names from names a user typed, and writes kept inside the output tree: one rule.

A scene's case names (and anything else typed into a scene or a results file) become parts of
file names (`tables/<case>.csv`, `modes/<case>_fem.vtu`, `figures/mode_<case>_fem_3.png`) only
through `file_stem`, and every such file is placed with `inside`, which refuses a path that
resolves outside the folder it is written into. So input never chooses where a file lands.

The rule for a name:
- refused, with the reason (`name_problem`): an empty name, a path separator (`/`, `\\`: a
  traversal such as `../../escape` or an absolute path), a control or invisible character
  (NUL, newline, a bidirectional override), a leading dot (`.`, `..`, a hidden file), a name
  longer than MAX_LENGTH characters, or one whose file name would be a device name Windows
  reserves (CON, PRN, AUX, NUL, COM1-9, LPT1-9, with or without an extension);
- otherwise slugged: every character outside [A-Za-z0-9._-] becomes `_` (a space, `é`, `:`),
  so "level pose" is written as `level_pose`.
Refused rather than slugged, because a name such as `../../escape` or one holding NUL is a
mistake or an attack, and a clear refusal naming it says so, where a silent rename would hide
it. Two names that give the same file name (case ignored, as on macOS and Windows file
systems) are refused together (`distinct_stems`), naming both.
"""
from __future__ import annotations

import os
import re
import unicodedata
from collections.abc import Iterable
from pathlib import Path

from .errors import InputError

MAX_LENGTH = 64  # characters; the longest file name built from one is ~90 bytes
SAFE_CHARACTERS = "letters, digits, spaces, '.', '_' and '-'"
_UNSAFE = re.compile(r"[^A-Za-z0-9._-]")
INVISIBLE = ("Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp")  # controls, formats, surrogates, ...
RESERVED = frozenset(["CON", "PRN", "AUX", "NUL", "CONIN$", "CONOUT$"]
                     + [f"{d}{k}" for d in ("COM", "LPT") for k in range(1, 10)])


class UnsafeName(InputError):
    """A name that cannot become a file name (one line naming it and why)."""


class OutsideTree(InputError):
    """A path that would be written outside its output folder."""


def shown(name: object, limit: int = 40) -> str:
    """The name as typed, quoted and escaped (a NUL shows as \\x00), cut when very long."""
    text = repr(name)
    return text if len(text) <= limit else text[:limit - 4] + "...'"


def name_problem(name: object) -> str | None:
    """Why `name` cannot become part of a file name, or None."""
    if not isinstance(name, str):
        return "is not a string"
    if not name.strip():
        return "is empty"
    if len(name) > MAX_LENGTH:
        return f"is {len(name)} characters long, more than {MAX_LENGTH}"
    if "/" in name or "\\" in name:
        return "holds a path separator"
    odd = next((c for c in name if unicodedata.category(c) in INVISIBLE), None)
    if odd is not None:
        return f"holds the control or invisible character U+{ord(odd):04X}"
    if name.startswith("."):
        return "starts with a dot"
    if _UNSAFE.sub("_", name).split(".")[0].upper() in RESERVED:
        return "is a device name that Windows reserves"
    return None


def file_stem(name: str, what: str = "name") -> str:
    """The part of a file name that `name` becomes; UnsafeName (naming it) when refused."""
    why = name_problem(name)
    if why is not None:
        raise UnsafeName(f"{what} {shown(name)} {why}: {what}s become file names; use "
                         f"{SAFE_CHARACTERS} (at most {MAX_LENGTH})")
    return _UNSAFE.sub("_", name)


def distinct_stems(names: Iterable[str], what: str = "name") -> dict[str, str]:
    """{name: file_stem(name)}; UnsafeName naming both when two names give one file name."""
    stems: dict[str, str] = {}
    seen: dict[str, str] = {}
    for name in names:
        stem = file_stem(name, what)
        other = seen.setdefault(stem.casefold(), name)
        if other != name:
            raise UnsafeName(f"{what}s {shown(other)} and {shown(name)} would both be written "
                             f"as {stem!r} (file names ignore case and write other characters "
                             "as '_'): rename one")
        stems[name] = stem
    return stems


def inside(root: str | os.PathLike, *parts: str) -> Path:
    """root / parts, refused (OutsideTree) unless it resolves inside `root` (symbolic links
    followed): the check every writer of an output tree makes before it writes."""
    base = Path(root).resolve()
    path = Path(root).joinpath(*parts)
    resolved = path.resolve()
    if resolved == base or not resolved.is_relative_to(base):
        raise OutsideTree(f"{Path(*parts)}: would be written outside {Path(root)}; refused")
    return path


def display_path(path: str | os.PathLike, base: str | os.PathLike | None = None) -> str:
    """A path as a record or a report shows it: relative to `base` (default: the working
    folder the run was started in) where it lies inside it, never the machine's absolute
    path of a file the reader also has; a path outside it is shown as given."""
    where = Path(os.path.abspath(path))  # as named: a link is not followed to its target
    root = Path(os.path.abspath(base if base is not None else Path.cwd()))
    try:
        return where.relative_to(root).as_posix()
    except ValueError:
        return str(path)
