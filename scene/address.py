"""A scene key as an address: `table.key` (e.g. `stiffness.actuator_axial_n_per_um`) names one
numeric value of a scene for every tool that varies one (the design study, identification from
test data). One resolver: it refuses an unknown address in one line, reads the value a scene
holds (given or default) in the key's edge unit, writes values into a copy of the raw scene,
and checks a value against the key's declared range.

Addressable: every declared number (a float setting read from scene files) of [manipulator],
[material], [leg], [stiffness] and [payload]; lists (a payload's centre) and names are not.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Mapping

from analytical.params import Manipulator, Material
from common.leg_profile import LegProfile
from common.payload import Payload
from common.settings import Setting, declared
from common.stiffness import Stiffness

from .errors import SceneError

TABLES: dict[str, type] = {"manipulator": Manipulator, "material": Material, "leg": LegProfile,
                           "stiffness": Stiffness, "payload": Payload}


@dataclass(frozen=True)
class Address:
    table: str
    key: str  # the scene key, unit suffix included (`actuator_axial_n_per_um`)
    field: str  # the dataclass field it sets (`actuator_axial`)
    spec: Setting

    @property
    def name(self) -> str:
        return f"{self.table}.{self.key}"

    @property
    def unit(self) -> str:
        return self.spec.unit or "-"

    def value(self, scene: Any) -> float:
        """The value this scene holds (given or default), in the edge unit."""
        return self.read(scene.manipulator)

    def read(self, manipulator: Manipulator) -> float:
        """The value this machine has, in the edge unit."""
        holder = (manipulator if self.table == "manipulator"
                  else getattr(manipulator, self.table))
        return float(self.spec.edge(getattr(holder, self.field)))

    def applied(self, manipulator: Manipulator, value: float) -> Manipulator:
        """The manipulator with this key at `value` (edge unit): its own dataclass checks
        run (a hollow leg's wall, the stepped leg's parts), not the scene's whole-machine
        plausibility, which `parse_scene` of a scene with the value does."""
        return applied(manipulator, {self: value})

    def problem(self, value: float) -> str | None:
        """Why `value` (edge unit) is outside the key's declared range, or None."""
        return self.spec.problem(float(value) * self.spec.scale, edge=True)


def applied(manipulator: Manipulator, values: Mapping[Address, float]) -> Manipulator:
    """The manipulator with every addressed key at its value (edge units), set together: one
    replace per table, so a pair that is only valid together (a rod's outer and inner
    diameter) is checked as the pair, never half moved."""
    tables: dict[str, dict[str, Any]] = {}
    for address, value in values.items():
        tables.setdefault(address.table, {})[address.field] = float(value) * address.spec.scale
    changes = dict(tables.pop("manipulator", {}))
    for table, fields in tables.items():
        holder = replace(getattr(manipulator, table), **fields)
        changes[table] = holder
        if table == "leg" and holder.stepped:  # a stepped leg's diameter is its parts'
            changes["leg_diameter"] = holder.largest_diameter
    return replace(manipulator, **changes)


def numbers(cls: type) -> dict[str, tuple[str, Setting]]:
    """scene key -> (field, declaration) of the numbers `cls` declares."""
    return {spec.scene_key(name): (name, spec) for name, spec, _ in declared(cls)
            if spec.scene and spec.kind is float}


def resolve(name: Any, where: str = "key") -> Address:
    """The address `name` ('table.key'); SceneError in one line naming it otherwise."""
    table, _, key = str(name).partition(".")
    if not isinstance(name, str) or table not in TABLES or not key:
        raise SceneError(f"{where} {name!r}: expected a scene key as 'table.key', table one of "
                         f"{', '.join(TABLES)}")
    known = numbers(TABLES[table])
    if key not in known:
        raise SceneError(f"{where} {name!r} is not a number of [{table}] (it has: "
                         f"{', '.join(sorted(known))})")
    field, spec = known[key]
    return Address(table, key, field, spec)


def with_values(raw: Mapping[str, Any], values: Mapping[Address, float]) -> dict:
    """A copy of the raw scene (its TOML tables) with the addressed keys set (edge units)."""
    out = {k: (dict(v) if isinstance(v, dict) else v) for k, v in raw.items()}
    for address, value in values.items():
        out.setdefault(address.table, {})[address.key] = float(value)
    return out


def _toml_number(value: float) -> str:
    text = repr(float(value))
    return text if ("." in text or "e" in text or "inf" in text or "nan" in text) else text + ".0"


def edited_text(text: str, values: Mapping[Address, float],
                notes: Mapping[Address, str] | None = None) -> str:
    """The scene file's text with the addressed keys set (edge units), every other line kept:
    a key given in its table is rewritten in place (its comment kept, or replaced by its
    `notes` entry: one line saying where the value came from), a key left out is added under
    its table's header, a table left out is added at the end."""
    import re

    lines = text.splitlines()
    for address, value in values.items():
        note = (notes or {}).get(address)
        number = _toml_number(value) + (f"  # {' '.join(note.split())}" if note else "")
        table = None
        header_at = None
        done = False
        for k, line in enumerate(lines):
            head = re.match(r"^\s*\[([^\[\]]+)\]\s*(#.*)?$", line)
            if head:
                table = head.group(1).strip()
                if table == address.table:
                    header_at = k
                continue
            if line.lstrip().startswith("[["):
                table = None
                continue
            found = re.match(rf"^(\s*{re.escape(address.key)}\s*=\s*)([^#]*?)(\s*#.*)?$", line)
            if table == address.table and found:
                lines[k] = found.group(1) + number + ("" if note else (found.group(3) or ""))
                done = True
                break
        if done:
            continue
        if header_at is not None:
            lines.insert(header_at + 1, f"{address.key} = {number}")
        else:
            lines += ["", f"[{address.table}]", f"{address.key} = {number}"]
    return "\n".join(lines) + "\n"
