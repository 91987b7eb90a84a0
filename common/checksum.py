"""Checksums of cache entries: a SHA-256 of every file of an entry, verified on every read.

A cache entry is a JSON record plus optional side files (a mesh, mode shapes). `seal` adds to
the record a table `sha256` holding the digest of each side file (keyed by its suffix, ".vtu")
and the digest of the record itself (key "record", over its canonical JSON), so a truncated,
overwritten or one-byte-edited file of either kind is caught. `verify` returns the record
without the table, or raises ChecksumError saying which file does not match. The caches drop
such an entry with one line on stderr (`report_dropped`) and recompute it.
"""
from __future__ import annotations

import hashlib
import json
import os
import sys
from pathlib import Path
from typing import Any

from .errors import InputError

TABLE = "sha256"
RECORD = "record"  # the record's own digest in the table (side files are keyed ".ext")


class ChecksumError(InputError):
    """A cache entry does not match its checksums (the message says which file)."""


def file_sha256(path: str | os.PathLike) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def record_sha256(record: dict) -> str:
    text = json.dumps(record, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def seal(record: dict, files: dict[str, Path] | None = None) -> dict:
    """The record with its checksum table (side files by suffix -> complete file)."""
    table = {suffix: file_sha256(path) for suffix, path in (files or {}).items()}
    table[RECORD] = record_sha256(record)
    return {**record, TABLE: table}


def side_files(stored: Any) -> list[str]:
    """The suffixes of the side files a sealed record lists."""
    table = stored.get(TABLE) if isinstance(stored, dict) else None
    return sorted(k for k in table if k != RECORD) if isinstance(table, dict) else []


def verify(stored: Any, files: dict[str, Path]) -> dict:
    """The record of a sealed entry whose every file matches; `files` maps each listed suffix
    to where that side file is. Raises ChecksumError otherwise."""
    if not isinstance(stored, dict) or not isinstance(stored.get(TABLE), dict):
        raise ChecksumError("no checksums (written by an older version)")
    table = stored[TABLE]
    record = {k: v for k, v in stored.items() if k != TABLE}
    if table.get(RECORD) != record_sha256(record):
        raise ChecksumError("the record does not match its checksum")
    for suffix in side_files(stored):
        path = files.get(suffix)
        if path is None:
            raise ChecksumError(f"unexpected side file {suffix!r}")
        try:
            actual = file_sha256(path)
        except FileNotFoundError:
            raise ChecksumError(f"{Path(path).name} is missing") from None
        if actual != table[suffix]:
            raise ChecksumError(f"{Path(path).name} does not match its checksum")
    return record


def report_dropped(what: str, path: Path, why: str) -> None:
    """The one stderr line of a dropped cache entry."""
    print(f"note: {what} {path} failed its check ({why}): dropped, recomputing", file=sys.stderr,
          flush=True)
