"""Settings declared once: a dataclass field carries its meaning, unit, range and scene key.

A model's options are frozen dataclasses whose fields are declared with `setting(...)`. The same
declaration
- validates a value given from Python (`check_settings` in the dataclass's __post_init__),
- reads and validates the scene file's key (`scene` converts the edge unit to SI once),
- documents the key (`docs/scenes.md` is generated from it),
so a new knob is one field in one dataclass and one key in a scene file.

Values inside the code are SI; `unit` names the unit at the edge (scene files, reports), and the
scene key is the field name with that unit's suffix (`mesh_size` in mm -> `mesh_size_mm`).
Ranges are declared in SI, and every number has both bounds, tight enough to exclude the
absurd (a length of 1e300 mm, an angle of 1e300 degrees, a tolerance of 1e-300 %): the limits
shared by many declarations are below, each with its reason. The command line reads its
numbers through the same declarations (`Setting.from_text`), so an option and its scene key
admit the same values.
"""
from __future__ import annotations

import math
from dataclasses import MISSING, dataclass, field, fields, is_dataclass
from typing import Any

from .errors import InputError
from .messages import short
from .paths import INVISIBLE

# edge unit -> (scene-key suffix, SI value of one edge unit, SI unit name)
UNITS = {
    None: ("", 1.0, ""),
    "mm": ("_mm", 1e-3, "m"),
    "deg": ("_deg", math.pi / 180.0, "rad"),
    "GPa": ("_gpa", 1e9, "Pa"),
    "kg/m3": ("_kg_m3", 1.0, "kg/m3"),
    "kg": ("_kg", 1.0, "kg"),
    "kg m2": ("_kg_m2", 1.0, "kg m2"),
    "N/um": ("_n_per_um", 1e6, "N/m"),
    "N m/urad": ("_nm_per_urad", 1e6, "N m/rad"),
    "1/s": ("_per_s", 1.0, "1/s"),
    "s": ("_s", 1.0, "s"),
    "N/mm2": ("_n_per_mm2", 1e6, "Pa"),
    "rpm": ("_rpm", 1.0 / 60.0, "1/s"),
}


# Lengths of a machine of this kind (a parallel manipulator whose legs are beams): nothing above
# 100 m (the largest parallel kinematic machines, telescope hexapods and flight simulators, are
# tens of metres; far beyond, the workspace arithmetic overflows) and, for a dimension of the
# machine, nothing below 1 mm (a leg or plate thinner is a wire or a foil, not a machine part).
MAX_LENGTH = 100.0  # m
MIN_PART = 1e-3  # m
# Angles at the edge: one turn either way (any direction is reachable without wrapping round).
MAX_ANGLE = 2 * math.pi  # rad
# Modes compared or solved for: the lowest few dozen describe a manipulator's dynamics; the
# dense and shift-invert solvers are sized for that many (the FEM adds a few beyond the
# compared ones to pair by shape, solvers.compare.EXTRA_MODES).
MAX_MODES = 60
MAX_SOLVED_MODES = 100
# Free text that reaches the reports (names, titles, reasons): a title is one line of at most
# MAX_LINE_TEXT characters (it heads a table or a page), a reason a few paragraphs of at most
# MAX_PARAGRAPH_TEXT; neither may hold a character the PDF and HTML renderers cannot lay out or
# that hides what is written: control characters (a reason keeps its line breaks and tabs), line
# and paragraph separators (U+2028, U+2029), format characters (bidirectional overrides,
# zero-width joiners), surrogates, private-use and unassigned code points.
MAX_LINE_TEXT = 200
MAX_PARAGRAPH_TEXT = 4000


@dataclass(frozen=True)
class Setting:
    """What one field means and which values it admits (ranges in SI)."""

    doc: str
    unit: str | None = None  # unit at the edge
    kind: type = float  # float, int, str, bool or tuple (of `item`)
    item: type = float  # tuples: float (numbers) or str (names)
    minimum: float | None = None
    maximum: float | None = None
    exclusive_minimum: bool = False
    choices: tuple[str, ...] | None = None
    length: int | None = None  # tuples: required length
    min_length: int | None = None  # tuples: least length
    scene: bool = True  # read from scene files
    scene_required: bool = False  # a scene must give it even though Python has a default
    scene_name: str | None = None  # scene key stem when it differs from the field name
    paragraphs: bool = False  # text: several lines (a reason) rather than one (a title)
    key: str | None = None  # the whole scene key, where the unit is not its suffix

    def scene_key(self, name: str) -> str:
        return self.key or (self.scene_name or name) + UNITS[self.unit][0]

    @property
    def scale(self) -> float:
        return UNITS[self.unit][1]

    def edge(self, value: float) -> float:
        """An SI value in the edge unit."""
        return value / self.scale

    def range_text(self, edge: bool = True) -> str:
        """The admitted values, in the edge unit (or in SI), unit included."""
        if self.choices:
            return "one of " + ", ".join(repr(c) for c in self.choices)
        if self.kind is str:
            return (f"at most {MAX_PARAGRAPH_TEXT} characters, line breaks allowed"
                    if self.paragraphs else f"one line of at most {MAX_LINE_TEXT} characters")
        convert = self.edge if edge else float
        parts = []
        if self.minimum is not None:
            parts.append(f"{'>' if self.exclusive_minimum else '>='} {convert(self.minimum):g}")
        if self.maximum is not None:
            parts.append(f"<= {convert(self.maximum):g}")
        unit = (self.unit if edge else UNITS[self.unit][2]) or ""
        return (" and ".join(parts) + (f" {unit}" if unit else "")) if parts else "any"

    def problem(self, value: Any, edge: bool = False) -> str | None:
        """Why an SI value is not admitted (message tail, limits in the edge unit or SI),
        or None."""
        if self.kind is bool:
            return None if isinstance(value, bool) else "expected true or false"
        if self.kind is str:
            if not isinstance(value, str):
                return "expected a string"
            if self.choices and value not in self.choices:
                return f"expected one of {', '.join(self.choices)}"
            return None if self.choices else text_problem(value, self.paragraphs)
        if self.kind is tuple:
            if self.item is str:
                if not isinstance(value, tuple) or not all(isinstance(v, str) for v in value):
                    return "expected a list of names"
            elif not isinstance(value, tuple) or not all(_is_number(v) for v in value):
                return "expected a list of numbers"
            if self.length is not None and len(value) != self.length:
                return f"expected {self.length} numbers"
            if self.min_length is not None and len(value) < self.min_length:
                return f"expected at least {self.min_length} numbers"
            bad = [v for v in value if self._out_of_range(v)]
            return None if not bad else f"every value must be {self.range_text(edge)}"
        if self.kind is int and (isinstance(value, bool) or not isinstance(value, int)):
            return "expected an integer"
        if not _is_number(value) and not (_is_infinite(value) and self._out_of_range(value)):
            return "expected a finite number"
        if self._out_of_range(value):
            return f"must be {self.range_text(edge)}"
        return None

    def from_text(self, text: str, option: str) -> Any:
        """A command-line value typed in the edge unit (`--size 40`), checked by this
        declaration and returned in SI; ValueError "--size 0.001 mm: must be ..." naming the
        option and the value as typed first."""
        shown = f"{option} {short_text(text)}" + (f" {self.unit}" if self.unit else "")
        try:
            value = int(text) if self.kind is int else float(text)
        except ValueError:
            raise InputError(f"{shown}: expected {'an integer' if self.kind is int else 'a number'}"
                             ) from None
        si = value * self.scale if self.kind is float else value
        why = self.problem(si, edge=True)
        if why is not None:
            raise InputError(f"{shown}: {why}")
        return si

    def _out_of_range(self, v: float) -> bool:
        if self.minimum is not None and (v < self.minimum or (self.exclusive_minimum
                                                              and v <= self.minimum)):
            return True
        return self.maximum is not None and v > self.maximum


def text_problem(text: str, paragraphs: bool = False) -> str | None:
    """Why free text cannot reach a report (see MAX_LINE_TEXT), or None."""
    import unicodedata

    limit = MAX_PARAGRAPH_TEXT if paragraphs else MAX_LINE_TEXT
    if len(text) > limit:
        return f"is {len(text)} characters long, more than {limit}"
    allowed = "\n\t" if paragraphs else ""
    for k, char in enumerate(text):
        if char not in allowed and unicodedata.category(char) in INVISIBLE:
            name = unicodedata.name(char, "a control character")
            allowed_text = ("printable text, tabs and line breaks" if paragraphs
                            else "one line of printable text")
            return (f"holds U+{ord(char):04X} ({name}) at character {k + 1}, which the "
                    f"reports cannot show (expected {allowed_text})")
    return None


def _is_infinite(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isinf(x)


def _is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def setting(default: Any = MISSING, **spec) -> Any:
    """A dataclass field with its declaration (see `Setting`)."""
    return field(default=default, metadata={"setting": Setting(**spec)})


def named_setting(**spec) -> Any:
    """A declared field without a default that may follow fields with one: given by name."""
    return field(kw_only=True, metadata={"setting": Setting(**spec)})


def declared(cls_or_obj) -> list[tuple[str, Setting, Any]]:
    """(name, Setting, default or MISSING) of every declared field, in order."""
    out = []
    for f in fields(cls_or_obj):
        spec = f.metadata.get("setting")
        if spec is not None:
            out.append((f.name, spec, f.default))
    return out


def edge_values(obj, names: tuple[str, ...] | None = None) -> dict[str, Any]:
    """The declared fields of `obj` (those of `names`, or all) under their scene keys, in
    their edge units (a tuple element by element): what a record of the scene holds, each
    value converted once by its own declaration."""
    out: dict[str, Any] = {}
    for name, spec, _ in declared(obj):
        if names is None or name in names:
            value = getattr(obj, name)
            if isinstance(value, tuple):
                out[spec.scene_key(name)] = [spec.edge(v) for v in value]
            else:
                out[spec.scene_key(name)] = value if spec.kind is str else spec.edge(value)
    if names is not None and len(out) != len(names):
        raise ValueError(f"edge_values: {sorted(set(names) - {n for n, _, _ in declared(obj)})}"
                         f" are not declared settings of {type(obj).__name__}")
    return out


def nested(cls_or_obj) -> list[tuple[str, type]]:
    """(name, dataclass type) of the fields that hold settings dataclasses of their own."""
    out = []
    for f in fields(cls_or_obj):
        if f.metadata.get("nested"):
            out.append((f.name, f.metadata["nested"]))
    return out


def nested_setting(cls: type, default_factory=None) -> Any:
    """A field holding another settings dataclass (read from the same scene table)."""
    if default_factory is None:
        return field(metadata={"nested": cls})
    return field(default_factory=default_factory, metadata={"nested": cls})


def check_settings(obj) -> None:
    """Raise ValueError naming the first declared field whose value is not admitted."""
    for name, spec, _ in declared(obj):
        value = getattr(obj, name)
        why = spec.problem(value)
        if why is not None:
            unit = UNITS[spec.unit][2]
            shown = short(value) + (f" {unit}" if unit and spec.kind is float
                                     and isinstance(value, float) else "")
            raise InputError(f"{name} = {shown}: {why}")


def short_text(text: str, limit: int = 24) -> str:
    """A typed value as shown in a message: '1e308' stays, a 309-digit number is cut."""
    text = str(text).strip()
    return text if len(text) <= limit else text[:10] + "..." + text[-6:] + f" ({len(text)} chars)"


def spec_of(cls_or_obj, name: str) -> Setting:
    """The declaration of field `name`."""
    for n, spec, _ in declared(cls_or_obj):
        if n == name:
            return spec
    raise KeyError(name)


def as_dict(obj) -> dict:
    """Every compared field of a dataclass, nested dataclasses and arrays included, as plain
    JSON-ready values (floats rounded to 12 significant digits): the whole object, for cache
    keys. A field declared with compare=False (where a value is stored, such as
    ModelOptions.cache_dir) is not part of what the object is, and is left out."""
    if not is_dataclass(obj):
        raise TypeError(f"{obj!r} is not a dataclass")
    return {f.name: _plain(getattr(obj, f.name)) for f in fields(obj) if f.compare}


def _plain(v: Any) -> Any:
    if is_dataclass(v):
        return as_dict(v)
    if hasattr(v, "tolist") and hasattr(v, "dtype"):  # numpy array or scalar
        return _plain(v.tolist())
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    if isinstance(v, dict):
        return {str(k): _plain(x) for k, x in v.items()}
    if isinstance(v, float):
        return float(f"{v:.12g}") if math.isfinite(v) else repr(v)
    return v
