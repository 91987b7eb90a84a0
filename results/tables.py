"""Error tables of every case as CSV and Markdown (out/tables/), from results.json only.

The table of a case puts, mode by mode: the paper's FEA and theory (Table I, only where the
case carries the paper's rows), our FEM with its estimated discretisation error, our analytical
model, the error and the MAC.
"""
from __future__ import annotations

from pathlib import Path
from typing import Literal, Sequence

from common.atomic import write_text_atomic
from common.paths import distinct_stems, inside

from .case_records import Case
from .declare import Record, csv_text, table_rows
from .schema import Results

PAPER_COLUMNS = ("paper_fea_hz", "paper_theory_hz", "paper_error_percent")
COLUMNS = ("mode",) + PAPER_COLUMNS + ("fem_hz", "fem_estimated_error_percent",
                                       "analytical_hz", "error_percent", "mac")
HEADINGS = {"mode": "mode", "paper_fea_hz": "paper FEA (Hz)",
            "paper_theory_hz": "paper theory (Hz)", "paper_error_percent": "paper err (%)",
            "fem_hz": "our FEM (Hz)", "fem_estimated_error_percent": "FEM est. err (%)",
            "analytical_hz": "our analytical (Hz)", "error_percent": "err vs FEM (%)",
            "mac": "MAC"}
DIGITS = {"fem_estimated_error_percent": 3, "mac": 3}


def columns(case: Case) -> tuple[str, ...]:
    """The columns of a case's table: the paper's only when the case carries its rows."""
    return COLUMNS if case["paper"] else tuple(c for c in COLUMNS if c not in PAPER_COLUMNS)


def case_rows(case: Case) -> list[dict[str, float | None]]:
    paper = case["paper"]

    def paper_value(key: Literal["fea_hz", "theory_hz", "error_percent"], k: int
                    ) -> float | None:
        row = (paper[key] if paper else None) or []
        return row[k] if k < len(row) else None  # the paper may list fewer modes than we do

    rows: list[dict[str, float | None]] = []
    for pair in sorted(case["pairs"], key=lambda p: p["fem_mode"]):
        k = pair["fem_mode"] - 1
        row = {"mode": pair["fem_mode"],
               "paper_fea_hz": paper_value("fea_hz", k),
               "paper_theory_hz": paper_value("theory_hz", k),
               "paper_error_percent": paper_value("error_percent", k),
               "fem_hz": pair["f_fem_hz"],
               "fem_estimated_error_percent": pair["fem_estimated_error_percent"],
               "analytical_hz": pair["f_analytical_hz"],
               "error_percent": pair["error_percent"],
               "mac": pair["mac"]}
        rows.append({c: row[c] for c in columns(case)})
    return rows


def fmt(value: float | None, digits: int) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def case_csv(case: Case) -> str:
    return csv_text(case_rows(case))


def case_markdown(case: Case) -> str:
    a, pose = case["analytical"], case["pose"]
    head = (f"**{case['description']}** — z = {pose['height_mm']:.1f} mm, "
            f"phi = {pose['azimuth_deg']:g}°, theta = {pose['tilt_deg']:g}°; "
            f"analytical: {a['beam']}, s = {a['elements']}, {a['platform_inertia']} inertia; "
            f"FEM: h = {case['fem']['mesh_size_mm']:g} mm, {case['fem']['dofs']} dofs\n\n")
    cols = columns(case)
    lines = ["| " + " | ".join(HEADINGS[c] for c in cols) + " |",
             "|" + "---:|" * len(cols)]
    for r in case_rows(case):
        lines.append("| " + " | ".join(str(r[c]) if c == "mode" else fmt(r[c], DIGITS.get(c, 2))
                                       for c in cols) + " |")
    return head + "\n".join(lines) + "\n"


def write_tables(results: Results, out: Path, records: Sequence[Record]) -> None:
    """Under `out`: tables/<case>.csv and .md of every case (file names by `common.paths`),
    and tables/studies/<key>-<name>.csv of every table a study declares (`records`: the
    registry), where these results hold rows for it."""
    stems = distinct_stems((case["name"] for case in results["cases"]), "case name")
    for case in results["cases"]:
        stem = stems[case["name"]]
        write_text_atomic(inside(out, "tables", f"{stem}.csv"), case_csv(case))
        write_text_atomic(inside(out, "tables", f"{stem}.md"), case_markdown(case))
    for record in records:
        for table in record.tables:
            rows = table_rows(record, table, results)
            if rows:
                path = inside(out, "tables", "studies", f"{record.key}-{table.name}.csv")
                path.parent.mkdir(parents=True, exist_ok=True)
                write_text_atomic(path, csv_text(rows))
