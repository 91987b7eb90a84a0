"""A content-keyed cache of expensive results (FEM solves, refinement studies).

The key is a SHA-256 of the inputs (as canonical JSON) and of the source code of the packages
that compute the value, so editing the physics invalidates the entry. Entries are written
atomically and carry the SHA-256 of every one of their files (common.checksum); an entry that
fails its checksums or cannot be read back (truncated, edited, wrong schema) is dropped, with
one line on stderr, and recomputed: never trusted.
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import os
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable

from common.atomic import write_text_atomic
from common.checksum import ChecksumError, report_dropped, seal, side_files, verify

ROOT = Path(__file__).resolve().parents[1]
CODE_PACKAGES = ("analytical", "common", "joint_ends", "meshing", "fem_reference")


@lru_cache(maxsize=None)
def code_fingerprint(modules: tuple[str, ...] = ()) -> str:
    """Hash of every Python source that the cached values depend on: the model packages, and
    the modules or packages (dotted names under the project root) of a value computed above them (a
    sweep task pairing modes in solvers/ is stale when the pairing changes)."""
    paths = [p for package in CODE_PACKAGES for p in sorted((ROOT / package).rglob("*.py"))]
    for name in sorted(modules):  # a module, or a package (every module in it)
        base = ROOT / name.replace(".", "/")
        paths += sorted(base.rglob("*.py")) if base.is_dir() else [base.with_suffix(".py")]
    digest = hashlib.sha256()
    for path in paths:
        digest.update(path.relative_to(ROOT).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def content_key(payload: Any, modules: tuple[str, ...] = ()) -> str:
    """The cache key of a value: its inputs and the code that computes it (`modules`: the
    modules beyond the model packages that the value depends on)."""
    text = json.dumps({"inputs": payload, "code": code_fingerprint(tuple(modules))},
                      sort_keys=True, default=float)
    return hashlib.sha256(text.encode()).hexdigest()[:24]


class ResultCache:
    """JSON values (plus optional side files) under `directory/<kind>/<key>.*`."""


    def __init__(self, directory: Path):
        self.directory = Path(directory)

    def _path(self, kind: str, key: str, suffix: str = ".json") -> Path:
        return self.directory / kind / f"{key}{suffix}"

    def get(self, kind: str, key: str, required: tuple[str, ...] = ()) -> dict | None:
        """The stored value, or None when absent; an entry that fails its checksums (a file
        truncated, overwritten or edited), cannot be parsed or lacks a required field is
        dropped with one line on stderr."""
        path = self._path(kind, key)
        try:
            stored = json.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            return None
        except (OSError, ValueError, UnicodeDecodeError) as exc:
            self._drop(kind, key, f"unreadable: {type(exc).__name__}")
            return None
        try:
            value = verify(stored, {s: self._path(kind, key, s) for s in side_files(stored)})
        except ChecksumError as exc:
            self._drop(kind, key, str(exc))
            return None
        missing = [k for k in required if k not in value]
        if missing:
            self._drop(kind, key, f"lacks {missing[0]!r}")
            return None
        return value

    def put(self, kind: str, key: str, value: dict, files: dict[str, Path] | None = None) -> None:
        """Store `value`; `files` maps a suffix (".vtu") to a complete file that is moved in
        beside it (same file system: a rename, no copy). The JSON, written last, commits the
        entry and carries the SHA-256 of itself and of every side file."""
        moved = {}
        for suffix, source in (files or {}).items():
            target = self._path(kind, key, suffix)
            target.parent.mkdir(parents=True, exist_ok=True)
            os.replace(source, target)
            moved[suffix] = target
        write_text_atomic(self._path(kind, key), json.dumps(seal(value, moved)))

    def side_file(self, kind: str, key: str, suffix: str) -> Path:
        return self._path(kind, key, suffix)

    def discard(self, kind: str, key: str) -> None:
        for path in self._path(kind, key).parent.glob(f"{key}.*"):
            path.unlink(missing_ok=True)

    def _drop(self, kind: str, key: str, why: str) -> None:
        report_dropped("result-cache entry", self._path(kind, key), why)
        self.discard(kind, key)

    def get_or_compute(self, kind: str, payload: Any, compute: Callable[[], tuple[dict, dict]],
                       required: tuple[str, ...] = (), modules: tuple[str, ...] = ()
                       ) -> tuple[dict, str, bool]:
        """(value, key, hit). `compute` returns (value, side files); `modules`: the modules
        beyond the model packages that the value depends on (see `content_key`)."""
        key = content_key(payload, modules)
        hit = self.get(kind, key, required)
        if hit is not None:
            return hit, key, True
        value, files = compute()
        self.put(kind, key, value, files)
        return value, key, False


def _entry_files(directory: Path):
    """(kind, file) of every file this project's caches write under `directory`: entries
    `<kind>/<hex key>.<suffix>` (result kinds, and `meshes` of meshing.cache), temporary files
    `tmp/*` and atomic-write leftovers `<kind>/.<name>.*.tmp`. Nothing else is touched, so
    pointing --cache at a directory that holds other files cannot lose them."""
    directory = Path(directory)
    if not directory.is_dir():
        return
    for kind in sorted(p for p in directory.iterdir() if p.is_dir() and not p.is_symlink()):
        for path in sorted(kind.iterdir()):
            if not path.is_file() or path.is_symlink():
                continue
            stem = path.name.split(".")[0]
            leftover = path.name.startswith(".") and path.name.endswith(".tmp")
            if kind.name == "tmp" or leftover or (len(stem) >= 16 and all(
                    c in "0123456789abcdef" for c in stem)):
                yield kind.name, path


def cache_info(directory: Path) -> dict:
    """Directory, entries (committed `.json` records) and bytes, per kind and in total."""
    kinds: dict[str, dict] = {}
    for kind, path in _entry_files(directory):
        part = kinds.setdefault(kind, {"entries": 0, "bytes": 0})
        part["entries"] += path.suffix == ".json"
        part["bytes"] += path.stat().st_size
    return {"directory": str(Path(directory).resolve()), "exists": Path(directory).is_dir(),
            "kinds": kinds, "entries": sum(k["entries"] for k in kinds.values()),
            "bytes": sum(k["bytes"] for k in kinds.values())}


def clear(directory: Path) -> dict:
    """Delete every cache file under `directory` (and the directories left empty); returns
    what was removed, as `cache_info` counts it."""
    info = cache_info(directory)
    for _, path in list(_entry_files(directory)):
        path.unlink(missing_ok=True)
    directory = Path(directory)
    for kind in sorted(set(info["kinds"]) | {"tmp", "meshes"}):
        with contextlib.suppress(OSError):  # only if empty
            (directory / kind).rmdir()
    with contextlib.suppress(OSError):
        directory.rmdir()
    return info
