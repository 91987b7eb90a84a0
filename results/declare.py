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
from typing import Any, Iterable, Literal, Mapping

from pydantic import PydanticUserError, TypeAdapter, ValidationError

from common.errors import InputError

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
    not named when missing."""

    anchor: str
    title: str
    absent: str | None = None
    template: str | None = None


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

    def checked(self, value: Any, where: str = "results") -> Any:
        """The record checked against its type, as soon as the study returns it (not after
        the run's expensive work): the value, or InputError in one line."""
        return check(self, value, where, (self.key,))


def check(record: Record, value: Any, where: str, loc: tuple = ()) -> Any:
    try:
        return _adapter(record.type).validate_python(value)
    except ValidationError as exc:
        raise refusal(exc, where, loc) from None


def refusal(exc: ValidationError, where: str, loc: tuple = ()) -> InputError:
    """A pydantic failure in one line: where, the first offending field, its value."""
    errors = exc.errors(include_url=False)
    first = errors[0]
    more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
    value = "" if first["type"] == "missing" else f", got {_short(first.get('input'))}"
    message = first["msg"].removeprefix("Value error, ")
    return InputError(f"{where}: {location(loc + tuple(first['loc']))}: "
                      f"{message[:1].lower()}{message[1:]}{value}{more}")


def location(loc) -> str:
    text = ""
    for token in loc:
        text += f"[{token}]" if isinstance(token, int) else (f".{token}" if text else token)
    return text


def _short(value, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


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


def unique(records: Iterable[Record]) -> tuple[Record, ...]:
    """The registry checked: one record per key, one section per anchor."""
    out = tuple(records)
    keys = [r.key for r in out]
    twice = sorted({k for k in keys if keys.count(k) > 1})
    if twice:
        raise InputError(f"records: {', '.join(twice)} declared more than once")
    anchors = [(r.section.anchor, r.section.title) for r in out if r.section is not None]
    clash = sorted({a for a, t in anchors if any(a == b and t != u for b, u in anchors)})
    if clash:
        raise InputError(f"records: the report anchor {', '.join(clash)} has two titles")
    return out


def csv_text(rows: list[Row]) -> str:
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
    for token in filter(None, pointer.split("/")):
        value = value[int(token)] if isinstance(value, list) else value[token]
    return value
