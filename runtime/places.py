"""Options that name a place, checked for what they must be before any work starts.

A folder the run writes into (`--cache`, `rps verify --out`) must be a directory, or creatable,
and writable: the deepest part of the path that exists is a directory in which a file can be
made (tried with a temporary file, removed at once, so a read-only mount, /proc or a path under
a regular file is refused however the permission bits read). A Dask scheduler (`--scheduler`)
is `host:port` (optionally `tcp://` or `tls://`) and answers a TCP connection within
CONNECT_TIMEOUT seconds. Every refusal is one line naming the option and the value as typed;
nothing is created or left behind by a check.
"""
from __future__ import annotations

import os
import shutil
import socket
import tempfile
from pathlib import Path
from urllib.parse import urlsplit

from common.errors import InputError

CONNECT_TIMEOUT = 5.0  # s: a scheduler on the network answers far sooner
# A cache holds FEM mode files: a full run of the paper's scene stores 290 MB from empty
# (measured), a CI-profile run about a tenth of it, a single solve a few MB. Below this much
# free space a command would fail part-way (a full disk), so a cache directory on a file system
# with less is refused up front: MIN_FREE_CACHE for a command of a few solves, MIN_FREE_RUN for
# a full validation (its cold-cache need with room to spare; a warm cache needs less, but the
# refusal says how much is free, and a run that dies on a full disk costs more).
MIN_FREE_CACHE = 64_000_000  # bytes
MIN_FREE_RUN = 400_000_000  # bytes
SCHEMES = ("tcp", "tls")


class PlaceError(InputError):
    """An option names a place the command cannot use (one line naming it)."""


def _shown(option: str, text: str) -> str:
    return f"{option} {text!r}" if not text or text != text.strip() else f"{option} {text}"


def path_argument(text: str) -> Path:
    """argparse `type` of an option that names a file or folder: an empty value (which Path
    would read as the current directory) or one holding NUL is refused at parse time."""
    import argparse

    if not text.strip():
        raise argparse.ArgumentTypeError(f"{text!r}: empty; give a path")
    if "\0" in text:
        raise argparse.ArgumentTypeError(f"{text!r}: holds a NUL character")
    return Path(text)


def existing_part(path: Path) -> Path:
    """The deepest existing ancestor of `path` (itself if it exists)."""
    path = Path(os.path.abspath(path))
    while not os.path.lexists(path) and path.parent != path:
        path = path.parent
    return path


def check_writable_dir(place: str | os.PathLike, option: str, typed: str | None = None) -> Path:
    """`place` as an absolute path, if it is (or can become) a directory that files can be
    written into; PlaceError naming `option` and what was typed (`typed`, default `place`)
    otherwise."""
    text = os.fspath(place)
    shown = _shown(option, text if typed is None else typed)
    if not text.strip():
        raise PlaceError(f"{shown}: empty; give a directory")
    if "\0" in text:
        raise PlaceError(f"{shown}: holds a NUL character")
    path = Path(os.path.abspath(text))
    if os.path.lexists(path) and not path.is_dir():
        raise PlaceError(f"{shown}: exists and is not a directory")
    base = existing_part(path)
    if not base.is_dir():
        what = ("a broken symbolic link" if base.is_symlink() and not base.exists()
                else "a file, not a directory")
        raise PlaceError(f"{shown}: {base} is {what}, so nothing can be created under it")
    try:
        fd, probe = tempfile.mkstemp(prefix=".rps-write-check-", dir=base)
    except OSError as exc:
        why = exc.strerror or type(exc).__name__
        raise PlaceError(f"{shown}: cannot write in {base} ({why})") from None
    os.close(fd)
    os.unlink(probe)
    return path


def check_free_space(place: Path, need: int, option: str, typed: str | None = None) -> None:
    """PlaceError naming `option` when the file system of `place` has less than `need` bytes
    free."""
    free = shutil.disk_usage(existing_part(place)).free
    if free < need:
        raise PlaceError(f"{_shown(option, str(place) if typed is None else typed)}: "
                         f"{free / 1e6:.1f} MB free on its file system, less than the "
                         f"{need / 1e6:g} MB a run may store there; free some space or give "
                         "another directory")


def check_scheduler(address: str, option: str = "--scheduler") -> str:
    """The address of a running dask.distributed scheduler, checked to be host:port and to
    accept a TCP connection; PlaceError naming `option` otherwise."""
    shown = _shown(option, address)
    text = address.strip()
    parts = urlsplit(text if "://" in text else f"tcp://{text}")
    if parts.scheme not in SCHEMES:
        raise PlaceError(f"{shown}: expected host:port, tcp://host:port or tls://host:port "
                         f"(e.g. tcp://10.0.0.5:8786), not a {parts.scheme}:// address")
    try:
        port = parts.port
    except ValueError:
        port = -1
    if not parts.hostname or port is None or port <= 0 or parts.path not in ("", "/"):
        raise PlaceError(f"{shown}: expected host:port, e.g. tcp://10.0.0.5:8786")
    try:
        with socket.create_connection((parts.hostname, port), timeout=CONNECT_TIMEOUT):
            pass
    except OSError as exc:
        why = exc.strerror or ("no answer within "
                               f"{CONNECT_TIMEOUT:g} s" if isinstance(exc, TimeoutError)
                               else type(exc).__name__)
        raise PlaceError(f"{shown}: no scheduler answers at {parts.hostname}:{port} ({why}); "
                         "start one (dask scheduler) or leave the option out") from None
    return text
