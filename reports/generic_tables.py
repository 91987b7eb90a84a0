"""A study drawn without a template of its own: its declared tables as a reader reads them.

The rules (reports/README.md, "Every section"), held by tests/test_report_pages.py:
- a header is words with the unit in brackets, never the record's field name
  (`table_words.HEADINGS`; a column not listed there gets `words`: its unit suffix in
  brackets, underscores as spaces);
- a number is printed to the digits its stated error supports (`ERROR_OF`: the column holding
  a column's error): the error to two significant figures, the value to the same decimal; an
  index that its error exceeds prints as "< error" (`SHARES`), never as sampling noise;
- a column no row holds is left out; a text every row shares is said once under the table,
  not in every row (the case, the model, a V&V 20 verdict's meaning: `VERDICTS`);
- a table longer than MAX_ROWS shows the MAX_ROWS rows a reader compares (`RANK`: the largest
  or smallest of a column; else the first ones) and links the CSV that holds them all
  (out/tables/studies/, written by every run: `results.tables`).
"""
from __future__ import annotations

import math
from typing import Any, Sequence

from results import Record, Results, table_rows

from .cells import Cells, cell, decimal, head, missing, significant
from .table_words import CAPTIONS, VERDICTS, verdict_words, words

MAX_ROWS = 12
FIGURES = 4  # significant figures of a number without a stated error
SHARE_DECIMALS = 3  # an index (a share of a variance) matters to its third decimal at most

ERROR_OF = {"e_percent": "u_num_percent", "mean_hz": "mean_error_hz",
            "q025_hz": "q025_error_hz", "q975_hz": "q975_error_hz",
            "first": "first_error", "total": "total_error"}
SHARES = frozenset({"first", "total"})  # non-negative by definition

# (record key, table) -> (column, "largest" | "smallest" | "largest ratio" of it to another)
RANK: dict[tuple[str, str], tuple[str, ...]] = {
    ("uncertainty", "sobol"): ("total", "largest"),
    ("uncertainty", "validation"): ("e_percent", "largest ratio", "u_val_percent"),
    ("uncertainty_path", "path"): ("f1_q025_hz", "smallest"),
}


def error_decimals(error: float) -> int:
    """Decimals that show an error to two significant figures."""
    return max(0, 1 - math.floor(math.log10(abs(error))))


def _number(c: Cells, pointer: str, value: float, error: Any, share: bool) -> dict:
    usable = isinstance(error, (int, float)) and error > 0 and math.isfinite(error)
    if share:  # an index: to its error's digits, never past the third decimal
        digits = min(error_decimals(error), SHARE_DECIMALS) if usable else SHARE_DECIMALS
        bound = max(error if usable else 0.0, 0.5 * 10.0 ** -digits)
        if abs(value) < bound:  # the bound rounded up: never a printed bound below the value
            shown = math.ceil(bound * 10.0 ** digits - 1e-9) / 10.0 ** digits
            return cell(f"< {decimal(max(shown, 10.0 ** -digits), digits)}", "num", pointer)
        return cell(decimal(value, digits), "num", pointer)
    if usable:  # to the error's two figures (and never past the value's sixth)
        return cell(decimal(value, min(error_decimals(error), significant(value, 6))), "num",
                    pointer)
    if isinstance(value, int):
        return c.num(pointer, digits=None)
    if value != 0 and not 1e-3 <= abs(value) < 1e5:
        return c.sci(pointer)
    return c.num(pointer, digits=significant(value, FIGURES))


def _cell(c: Cells, row: dict, column: str) -> dict:
    value, pointer = row[column], f"{row['']}/{column}"
    if value is None:
        return missing()
    if column == "case":
        return c.text(literal=str(value), cls="text nowrap")
    if isinstance(value, bool):
        return c.text(literal="yes" if value else "no")
    if isinstance(value, (int, float)):
        partner = ERROR_OF.get(column)
        error = row.get(partner) if partner else None
        if column in ERROR_OF.values():  # an error: to its own two figures
            error = value
        share = column in SHARES or column in {ERROR_OF[k] for k in SHARES}
        return _number(c, pointer, value, error, share)
    if isinstance(value, list) and value and all(
            v is None or isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
        return cell(" – ".join("open" if v is None else decimal(v, 2 if abs(v) < 1e3 else 0)
                               for v in value), "num", pointer)  # None: no bound that side
    if column == "verdict":
        return cell(verdict_words(str(value)), "text", pointer)
    return c.text(pointer)


def _ranked(rows: list[dict], rank: tuple[str, ...] | None) -> list[dict]:
    if rank is None:
        return rows[:MAX_ROWS]
    column, how = rank[0], rank[1]

    def key(row):
        v = row.get(column)
        if v is None:
            return -math.inf
        if how == "largest ratio":
            u = row.get(rank[2])
            return abs(v) / u if u else math.inf
        return v if how == "largest" else -v

    keep = sorted(range(len(rows)), key=lambda i: key(rows[i]), reverse=True)[:MAX_ROWS]
    return [rows[i] for i in sorted(keep)]


def _chosen(rank: tuple[str, ...] | None, shown: int, total: int) -> str:
    if rank is None:
        return f"the first {shown} of {total} rows"
    column, how = words(rank[0]), rank[1]
    if how == "largest ratio":
        return f"the {shown} of {total} rows with the largest {column} against {words(rank[2])}"
    return f"the {shown} of {total} rows with the {how} {column}"


def _alike(rows: list[dict], cases: list[str]) -> bool:
    """Whether every case has the same rows (but for its name and where they are)."""
    def of(case):
        return [{k: v for k, v in r.items() if k not in ("", "case")}
                for r in rows if r["case"] == case]
    first = of(cases[0])
    return all(of(case) == first for case in cases[1:])


def generic_table(record: Record, name: str, rows: list[dict], c: Cells) -> dict:
    """One declared table as the report shows it (module rules)."""
    columns = [k for k in rows[0] if k and any(r[k] is not None for r in rows)]  # a column
    said = []  # no row holds (the least stiffness of a scene that asks no dynamics) is left out
    cases = list(dict.fromkeys(r["case"] for r in rows)) if "case" in columns else []
    if len(cases) > 1 and _alike(rows, cases):  # every case the same rows: shown once
        rows = [r for r in rows if r["case"] == cases[0]]
        said.append(f"the same for every case ({', '.join(cases)})")
        columns.remove("case")
    if len(rows) > 1:  # a text every row shares: said once
        for k in list(columns):
            values = {str(r[k]) for r in rows}
            if len(values) == 1 and not isinstance(rows[0][k], (int, float)) \
                    and rows[0][k] is not None and k != "verdict":
                said.append(f"{words(k)}: {rows[0][k]}")
                columns.remove(k)
    shown = rows if len(rows) <= MAX_ROWS else _ranked(rows, RANK.get((record.key, name)))
    notes = list(said)
    if "verdict" in columns:
        present = {verdict_words(str(r["verdict"])) for r in rows if r["verdict"]}
        notes += [VERDICTS[v] for v in VERDICTS if v in present]
    csv = f"tables/studies/{record.key}-{name}.csv"
    more = None
    if len(shown) < len(rows):
        more = {"text": f"Shown: {_chosen(RANK.get((record.key, name)), len(shown), len(rows))}"
                "; every row:", "href": csv}
    return {"name": name, "cls": "generic" + (" wide" if len(columns) > 8 else ""),
            "caption": CAPTIONS.get((record.key, name), words(name).capitalize()),
            "head": [head(*(words(k) for k in columns))],
            "rows": [[_cell(c, r, k) for k in columns] for r in shown],
            "notes": notes, "more": more, "csv": csv}


def values(results: Results, record: Record) -> list:
    """The record's values these results hold: the study's (scope "scene") or each case's;
    none where the study did not run."""
    if record.scope == "scene":
        found = [results["studies"].get(record.key)]  # type: ignore[attr-defined]
    else:
        found = [case.get(record.key) for case in results["cases"]]  # type: ignore[attr-defined]
    return [v for v in found if v not in (None, [])]


def ran(results: Results, records: Sequence[Record], anchor: str) -> bool:
    """Whether a study shown under `anchor` ran (its record holds a value, rows or not)."""
    return any(values(results, r) for r in records
               if r.section is not None and r.section.anchor == anchor)


def generic_sections(results: Results, records: Sequence[Record], c: Cells
                     ) -> dict[str, list]:
    """The tables of every study drawn without a template of its own, by section anchor
    (`generic_table`; a table with no rows is left out), and a study's refusal said where
    its record holds one (a record's `refused`: why it was not computed)."""
    out: dict[str, list] = {}
    for r in records:
        if r.section is None or r.section.template is not None:
            continue
        tables = out.setdefault(r.section.anchor, [])
        for table in r.tables:
            rows = [dict(row) for row in table_rows(r, table, results)]
            if rows:
                tables.append(generic_table(r, table.name, rows, c))
    return out


def refusals(results: Results, records: Sequence[Record]) -> dict[str, list[str]]:
    """Per section anchor, why a study that ran did not compute (its record's `refused`)."""
    out: dict[str, list[str]] = {}
    for r in records:
        if r.section is None or r.section.template is not None:
            continue
        for value in values(results, r):
            why = value.get("refused") if isinstance(value, dict) else None
            if why:
                out.setdefault(r.section.anchor, []).append(f"Not computed: {why}")
    return out
