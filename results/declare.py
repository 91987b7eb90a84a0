"""What a study's record is, declared once beside the study: its key, its type, what the results
hold when the study did not run, its report section and its CSV tables.

A `Record` is pure data (and pure functions of the record), so every room that handles results
can be given the registry without importing the studies: the run builds its results stub and
writes the tables from it, `results.schema` checks each record against its type, the report
numbers and titles its sections from it and draws a study without a template of its own as its
tables (the generic section). The registry itself is `studies.RECORDS`; the command line hands
it to the run and to the report.
"""
from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from functools import lru_cache
from types import UnionType
from typing import (
    Annotated,
    Any,
    Iterable,
    Literal,
    Mapping,
    Sequence,
    Union,
    get_args,
    get_origin,
)

from pydantic import PydanticUserError, TypeAdapter, ValidationError
from typing_extensions import get_type_hints, is_typeddict  # its TypedDicts (pydantic's)

from common.errors import InputError
from common.messages import short

from .types import STRICT

Scope = Literal["scene", "case"]
Row = Mapping[str, Any]  # column (units in its name) -> a number, a text or None


@dataclass(frozen=True)
class Table:
    """A table of a record, pure data: one row per item of the list at `each` (a JSON pointer
    inside the record; "" the record itself: a list's items, or one row of a single record),
    one column per field of `columns` (their names carry the units; "a/b" reaches into a
    nested field). Written to out/tables/studies/<key>-<name>.csv (a case study's rows of
    every case, with a `case` column first); a study without a template of its own is shown
    in the report as these tables, every cell naming its source by pointer."""

    name: str
    columns: tuple[str, ...]
    each: str = ""


@dataclass(frozen=True)
class Section:
    """Where the report shows a record: its anchor and title, and how the contents name it when
    these results do not hold it. `template`: the name of the report template's own block for
    it; None: the generic section, the study's tables as the report's tables. `absent` None:
    not named when missing (a study the profile leaves out); `asks`: the scene's tables that
    ask for a study only some scenes run, named with the study when a scene has none."""

    anchor: str
    title: str
    absent: str | None = None
    template: str | None = None
    asks: str | None = None  # what in a scene asks for the study ("[cutting]"): the report
    # names the study and what would ask for it when a scene does not
    nothing: str | None = None  # what a study that ran with no row to show found


@dataclass(frozen=True)
class Record:
    """A study's record: `results.studies[key]` (scope "scene") or `results.cases[][key]`
    (scope "case"), of `type` (as pydantic reads it: a TypedDict with units in its field names,
    a list of them, `| None` where the study may not run), `empty` when the study did not run
    (None or []). `section` None: shown inside each case's section (case studies)."""

    key: str
    scope: Scope
    type: Any
    empty: Any = None
    section: Section | None = None
    tables: tuple[Table, ...] = ()

    def __post_init__(self):
        if self.scope not in ("scene", "case"):
            raise InputError(f"record {self.key}: scope {self.scope!r} is not scene or case")
        if self.empty not in (None, []):
            raise InputError(f"record {self.key}: an empty record is None or [], got "
                             f"{self.empty!r}")
        for table in self.tables:  # a column the record cannot hold is refused here, at import
            for column in table.columns:
                if not _holds(self.type, [*filter(None, table.each.split("/")),
                                          *column.split("/")]):
                    raise InputError(f"record {self.key}: table {table.name}: column {column!r}"
                                     f"{f' of {table.each!r}' if table.each else ''} is not a "
                                     "field of the record")

    def checked(self, value: Any, where: str = "results") -> Any:
        """The record checked against its type, as soon as the study returns it (not after
        the run's expensive work): the value, or InputError in one line."""
        return check(self, value, where, (self.key,))


def check(record: Record, value: Any, where: str, loc: tuple = ()) -> Any:
    try:
        return _adapter(record.type).validate_python(value)
    except ValidationError as exc:
        raise refusal(exc, where, loc) from None


def check_type(kind: Any, value: Any, where: str) -> Any:
    """`value` checked against a record type (a TypedDict of this room), strictly: the value,
    or InputError in one line naming `where` and the first offending field."""
    try:
        return _adapter(kind).validate_python(value)
    except ValidationError as exc:
        raise refusal(exc, where) from None


def refusal(exc: ValidationError, where: str, loc: tuple = ()) -> InputError:
    """A pydantic failure in one line: where, the first offending field, its value."""
    errors = exc.errors(include_url=False)
    first = errors[0]
    more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
    value = "" if first["type"] == "missing" else f", got {short(first.get('input'), 60)}"
    message = first["msg"].removeprefix("Value error, ")
    return InputError(f"{where}: {location(loc + tuple(first['loc']))}: "
                      f"{message[:1].lower()}{message[1:]}{value}{more}")


def location(loc) -> str:
    text = ""
    for token in loc:
        text += f"[{token}]" if isinstance(token, int) else (f".{token}" if text else token)
    return text


@lru_cache(maxsize=None)
def _adapter(kind: Any) -> TypeAdapter:
    """Strict like the rest of the schema (a TypedDict brings its own strict config)."""
    try:
        return TypeAdapter(kind, config=STRICT)
    except PydanticUserError:  # a type with a config of its own
        return TypeAdapter(kind)


def in_scope(records: Iterable[Record], scope: Scope) -> tuple[Record, ...]:
    return tuple(r for r in records if r.scope == scope)


def stub(records: Iterable[Record], scope: Scope) -> dict[str, Any]:
    """Every record of `scope` at its empty value: what a run holds before its studies run."""
    return {r.key: [] if r.empty == [] else None for r in in_scope(records, scope)}


# the report's own sections (the summary, the fidelity choice, the comparison of each case,
# its mode shapes, the other cases): no study's section may take their anchors
REPORT_ANCHORS = ("summary", "fidelity", "comparison", "modes", "other")


def unique(records: Iterable[Record]) -> tuple[Record, ...]:
    """The registry checked: one record per key, one section per anchor (studies sharing an
    anchor declare the same `Section`), none of the report's own anchors."""
    out = tuple(records)
    keys = [r.key for r in out]
    twice = sorted({k for k in keys if keys.count(k) > 1})
    if twice:
        raise InputError(f"records: {', '.join(twice)} declared more than once")
    sections = [r.section for r in out if r.section is not None]
    clash = sorted({s.anchor for s in sections
                    if any(s.anchor == o.anchor and s != o for o in sections)})
    if clash:
        raise InputError(f"records: the report anchor {', '.join(clash)} is declared twice, "
                         "differently")
    taken = sorted({s.anchor for s in sections} & set(REPORT_ANCHORS))
    if taken:
        raise InputError(f"records: the report anchor {', '.join(taken)} is the report's own")
    return out


def csv_text(rows: Sequence[Row]) -> str:
    """Rows as CSV: the first row's keys are the columns (the row pointer "" left out), None
    an empty cell."""
    buf = io.StringIO()
    if rows:
        columns = [k for k in rows[0] if k]
        writer = csv.DictWriter(buf, fieldnames=columns, lineterminator="\n")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: "" if row[k] is None else row[k] for k in columns})
    return buf.getvalue()


def table_rows(record: Record, table: Table, results: Mapping[str, Any]) -> list[Row]:
    """A table's rows over the results: each row's JSON pointer (into the results) under the
    key "" and its columns' values; a case study's from every case (a `case` column first);
    none where the study did not run."""
    if record.scope == "scene":
        places: list[tuple[str, Any, dict[str, Any]]] = [
            (f"/studies/{record.key}", results["studies"][record.key], {})]
    else:
        places = [(f"/cases/{i}/{record.key}", case[record.key], {"case": case["name"]})
                  for i, case in enumerate(results["cases"])]
    rows: list[Row] = []
    for base, value, first in places:
        if value is None:
            continue
        items = _at(value, table.each)
        if items is None:  # an optional part of the record, absent here
            continue
        listed = list(enumerate(items)) if isinstance(items, list) else [(None, items)]
        for i, item in listed:
            at = base + (f"/{table.each}" if table.each else "") + ("" if i is None else f"/{i}")
            rows.append({"": at, **first, **{c: _at(item, c) for c in table.columns}})
    return rows


def _at(value: Any, pointer: str) -> Any:
    """The value at a pointer; None where an optional part is absent."""
    for token in filter(None, pointer.split("/")):
        if value is None:
            return None
        value = value[int(token)] if isinstance(value, list) else value.get(token)
    return value


def _holds(kind: Any, path: list[str]) -> bool:
    """Whether a value of type `kind` can hold `path` (field names; a list's items are passed
    through, an optional's value is its type's, a free mapping holds any key)."""
    while True:
        args = [a for a in get_args(kind) if a is not type(None)]
        origin = get_origin(kind)
        if origin is Annotated:
            kind = args[0]
        elif origin in (Union, UnionType) and len(args) == 1:
            kind = args[0]
        elif origin is list:
            kind = args[0]
        else:
            break
    if not path:
        return True
    if is_typeddict(kind):
        hints = get_type_hints(kind, include_extras=True)
        return path[0] in hints and _holds(hints[path[0]], path[1:])
    return origin is dict or kind is Any  # a mapping of labels: any key
