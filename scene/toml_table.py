"""The reader of the project's TOML inputs (scene, design, campaign and cutting files): typed
access to one table that remembers which keys were read, each value read through its
declaration (`common.settings`: kind, unit, range), converted to SI once, and every problem a
SceneError of one line naming the key as typed and the value.

    top = Table(read_toml(path, "design file"), str(path))
    constraints = top.table("constraints", {}).settings(Constraints)   # a declared dataclass
    top.done()                                                          # unknown keys refused
"""
from __future__ import annotations

import difflib
import tomllib
from pathlib import Path
from typing import Any

from common.messages import short
from common.settings import MISSING, Setting, declared, nested
from fem_reference.model import FemError

from .errors import SceneError

__all__ = ["REQUIRED", "Table", "found_instead", "read_toml", "scene_keys", "short"]


class Table:
    """Typed access to one TOML table that remembers which keys were read."""

    def __init__(self, data: Any, where: str):
        if not isinstance(data, dict):
            raise SceneError(f"{where} = {short(data)}: expected a table")
        self.data, self.where = data, where
        self.used: set[str] = set()

    def get(self, key: str, default: Any) -> Any:
        """The raw value of `key` (marked read), `default` where it is absent (REQUIRED: a
        missing key is refused)."""
        self.used.add(key)
        if key not in self.data:
            if default is REQUIRED:
                raise SceneError(f"{self.where}.{key}: missing")
            return default
        return self.data[key]

    def table(self, key: str, default: Any = None) -> "Table":
        value = self.get(key, REQUIRED if default is None else default)
        return Table(value, f"{self.where}.{key}")

    def settings(self, cls, defaults: dict | None = None, **given):
        """Read every declared field of the dataclass `cls` (and of its nested settings) from
        this table, in the field's edge unit, converted to SI once. `defaults` replace the
        declared defaults (SI); `given` are values decided elsewhere (passed through)."""
        defaults = defaults or {}
        values = dict(given)
        for name, sub in nested(cls):
            if name not in values:
                values[name] = self.settings(sub, defaults)
        for name, spec, default in declared(cls):
            if name in values or not spec.scene:
                continue
            default = defaults.get(name, default)
            key = spec.scene_key(name)
            if key not in self.data:
                self.used.add(key)
                if default is MISSING or spec.scene_required:
                    raise SceneError(f"{self.where}.{key}: missing ({spec.doc}"
                                     f"{', in ' + spec.unit if spec.unit else ''})"
                                     + found_instead(key, self.data, scene_keys(cls)))
                values[name] = default
                continue
            values[name] = self.value(key, spec)
        try:
            return cls(**values)
        except (ValueError, FemError) as exc:
            raise SceneError(f"{self.where}: {exc}") from None

    def value(self, key: str, spec: Setting):
        """One declared value, checked in the edge unit and returned in SI."""
        raw = typed = self.get(key, REQUIRED)
        if spec.kind is tuple:
            if not isinstance(raw, list) or not raw:
                raise SceneError(f"{self.where}.{key} = {short(raw)}: expected a non-empty list")
            raw = tuple(raw)
        if spec.kind is float and isinstance(raw, int) and not isinstance(raw, bool):
            raw = float(raw)
        si: Any
        if spec.kind is tuple and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                      for v in raw):
            si = tuple(float(v) * spec.scale for v in raw)
        elif spec.kind is float and isinstance(raw, float):
            si = raw * spec.scale
        else:
            si = raw
        why = spec.problem(si, edge=True)
        if why is not None:
            raise SceneError(f"{self.where}.{key} = {short(typed)}: {why}")
        return si

    def done(self) -> None:
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise SceneError(f"{self.where}: unknown key {short(unknown[0])}"
                             + _did_you_mean(unknown[0], self.used)
                             + (f" (and {len(unknown) - 1} more)" if len(unknown) > 1 else ""))


def _did_you_mean(key: str, known) -> str:
    """'; did you mean youngs_modulus_gpa?' for the closest known key (case ignored), or ''."""
    by_lower = {k.lower(): k for k in sorted(known)}
    close = difflib.get_close_matches(str(key).lower(), list(by_lower), n=1, cutoff=0.6)
    return f"; did you mean {by_lower[close[0]]}?" if close else ""


def scene_keys(cls) -> set[str]:
    """The scene keys of every declared field of `cls` and of its nested settings."""
    keys = {spec.scene_key(name) for name, spec, _ in declared(cls)}
    for _, sub in nested(cls):
        keys |= scene_keys(sub)
    return keys


def found_instead(key: str, data: dict, known=()) -> str:
    """'; found Youngs_Modulus_GPa: did you mean youngs_modulus_gpa?' for a misspelt key (a
    key of its own, `known`, is not one: slider_min_mm is no typo of slider_max_mm)."""
    typo = next((k for k in sorted(data, key=str)
                 if k not in known and _did_you_mean(k, [key])), None)
    return f"; found {short(typo)}: did you mean {key}?" if typo is not None else ""


REQUIRED = object()



def read_toml(path: str | Path, what: str = "scene file") -> dict:
    """The tables of a TOML file; SceneError naming `what` and the path on any problem."""
    path = Path(path)
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SceneError(f"{what} {str(path)!r} does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"{what} {str(path)!r} cannot be read: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{what} {str(path)!r} is not valid TOML: {exc}") from None
