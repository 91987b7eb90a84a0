"""The report's rules for every section (reports/README.md, "Every section"), on the report of
the fixture results (every study a scene may run but the cut's and the tool's; those by their
synthetic records in tests/test_study_figures.py) and, in `make scenes`, on every shipped
scene's (tests/test_scenes.py calls `words_past_the_page`):

- no word past the PDF's page box (pdftotext -bbox), laid out in the report's own fonts;
- no header a record's field name; a number no finer than its stated error, an index its
  error exceeds printed as "< error";
- a study's section shows a picture before its tables; a long table is cut to the rows a
  reader compares and links the CSV that holds them all;
- the campaign beside a run is named in the summary and has its section; paths relative.
"""
from __future__ import annotations

import hashlib
import json
import re
import shutil
import subprocess
from html import unescape
from pathlib import Path

import pytest

from reports.generic_tables import MAX_ROWS, error_decimals, generic_table
from reports.table_words import words
from results import Table
from studies import RECORDS

A4_MARGIN_PT = 16 / 25.4 * 72  # report.css's side margins
FIELD = re.compile(r"^[a-z0-9]+(_[a-z0-9]+)+$")


def words_past_the_page(pdf: Path) -> list[tuple[int, str]]:
    """(page, word) of every word past the right edge of the page's content box (the text's
    width, a cut table's side), or past the page's left edge."""
    out = subprocess.run(["pdftotext", "-bbox", str(pdf), "-"], capture_output=True,
                         text=True, check=True).stdout
    past = []
    pages = re.findall(r'<page width="([\d.]+)" height="[\d.]+">(.*?)</page>', out, re.S)
    for number, (width, body) in enumerate(pages, start=1):
        edge = float(width) - A4_MARGIN_PT + 1.0
        for x_min, x_max, word in re.findall(r'<word xMin="([\d.-]+)" yMin="[\d.-]+" '
                                             r'xMax="([\d.-]+)" yMax="[\d.-]+">(.*?)</word>',
                                             body):
            if float(x_max) > edge or float(x_min) < 0.0:
                past.append((number, unescape(word)))
    return past


def page_count(pdf: Path) -> int:
    info = subprocess.run(["pdfinfo", str(pdf)], capture_output=True, text=True,
                          check=True).stdout
    return int(re.search(r"Pages:\s+(\d+)", info).group(1))


needs_poppler = pytest.mark.skipif(shutil.which("pdftotext") is None,
                                   reason="poppler-utils (pdftotext) not installed")


@needs_poppler
def test_no_word_runs_past_the_page(fixture_report):
    assert words_past_the_page(fixture_report.pdf) == []


def _headers(html: str) -> list[str]:
    return [unescape(re.sub(r"<[^>]+>", "", h)).strip()
            for h in re.findall(r"<th[^>]*>(.*?)</th>", html, re.S)]


def test_no_header_is_a_field_name(fixture_report):
    fields = {c for r in RECORDS for t in r.tables for c in t.columns}
    headers = _headers(fixture_report.html.read_text(encoding="utf-8"))
    assert len(headers) > 100
    fixture = Path(__file__).resolve().parent / "fixtures" / "report_results.json"
    cases = {c["name"] for c in json.loads(fixture.read_text())["cases"]}  # names, not fields
    bad = [h for h in headers if h not in cases and (FIELD.match(h) or h in fields and "_" in h)]
    assert bad == []


def test_every_declared_column_has_words_and_its_unit():
    units = {"_percent": "(%)", "_hz": "(Hz)", "_mm": "(mm)", "_deg": "(deg)",
             "_n_per_m": "(N/m)", "_m_per_n": "(m/N)", "_rpm": "(rpm)"}
    for r in RECORDS:
        for t in r.tables:
            for column in t.columns:
                heading = words(column)
                assert heading != column or "_" not in column, (r.key, column)
                assert not FIELD.match(heading), (r.key, column, heading)
                unit = next((u for s, u in units.items() if column.endswith(s)), None)
                if unit is not None:
                    assert unit in heading, (r.key, column, heading)
    assert words("spindle_power_kg") == "spindle power (kg)"  # an undeclared column's rule


def _sobol_record():
    return next(r for r in RECORDS if r.key == "uncertainty")


def _rows(values):
    return [{"": f"/cases/0/uncertainty/sobol/{i}", "case": "case1", "output": "f1",
             "key": f"input {i}", "first": first, "first_error": first_error, "total": total,
             "total_error": total_error}
            for i, (first, first_error, total, total_error) in enumerate(values)]


def _results(rows):
    return {"cases": [{"uncertainty": {"sobol": [
        {k: v for k, v in row.items() if k not in ("", "case")} for row in rows]}}]}


def test_an_index_its_error_exceeds_is_below_its_error_never_noise():
    from reports.cells import Cells

    rows = _rows([(-4.30e-8, 1e-11, 0.91234, 0.0159), (0.000164, 0.00159, 0.0421, 0.0033)])
    table = generic_table(_sobol_record(), "sobol", rows, Cells(_results(rows)))
    shown = _by_header(table)
    # the case and the output every row shares: said once above the table, not in each row
    assert table["notes"][:2] == ["case: case1", "output: f1"]
    assert "case" not in shown[0] and "output" not in shown[0]
    first, first_error = shown[0]["first-order index"], shown[0]["± first"]
    total, total_error = shown[0]["total index"], shown[0]["± total"]
    assert first == "< 0.001" and first_error == "< 0.001"  # 4.3e-8: noise of a zero index
    assert total == "0.912" and total_error == "0.016"  # to the error's two figures, 3 at most
    assert shown[1]["first-order index"] == "< 0.002" and shown[1]["total index"] == "0.042"
    for row in shown:
        for text in row.values():
            digits = text.split(".")[1] if "." in text else ""
            assert len(digits) <= 3, text


def _by_header(table: dict) -> list[dict[str, str]]:
    names = [h["text"] for h in table["head"][0]]
    return [dict(zip(names, (cell["text"] for cell in row), strict=True))
            for row in table["rows"]]


def test_a_number_is_printed_to_its_errors_digits():
    assert error_decimals(0.0159) == 3 and error_decimals(1.59) == 1
    assert error_decimals(23.0) == 0 and error_decimals(0.11) == 2


def test_a_long_table_shows_the_rows_a_reader_compares_and_links_the_csv():
    from reports.cells import Cells

    rows = _rows([(0.01 * i, 0.001, 0.01 * i, 0.001) for i in range(30)])
    table = generic_table(_sobol_record(), "sobol", rows, Cells(_results(rows)))
    assert len(table["rows"]) == MAX_ROWS
    totals = [float(row["total index"]) for row in _by_header(table)]
    assert sorted(totals) == [round(0.01 * i, 3) for i in range(30 - MAX_ROWS, 30)]
    assert table["more"]["href"] == "tables/studies/uncertainty-sobol.csv"
    assert "largest total index" in table["more"]["text"]


def test_a_text_every_row_shares_is_said_once(fixture_report):
    html = fixture_report.html.read_text(encoding="utf-8")
    section = html[html.index('<section id="uncertainty">'):]
    section = section[:section.index("</section>")]
    # the V&V 20 verdict: its opening words per row, its meaning once under the table
    cells = re.findall(r"<td[^>]*>(.*?)</td>", section, re.S)
    assert "within 2 u_val" in cells and not any("does not matter" in c for c in cells)
    assert section.count('<p class="tablenote">|E| within 2 u_val:') == 1


def test_a_study_section_shows_a_picture_before_its_tables(fixture_report):
    html = fixture_report.html.read_text(encoding="utf-8")
    for anchor in ("uncertainty", "uncertainty-path"):
        section = html[html.index(f'<section id="{anchor}">'):]
        section = section[:section.index("</section>")]
        assert "<figure" in section, anchor
        assert section.index("<figure") < section.index("<table"), anchor


def test_the_full_tables_are_beside_the_report(fixture_report):
    html = fixture_report.html.read_text(encoding="utf-8")
    links = re.findall(r'href="([^"#]+\.csv)"', html)
    assert len(links) >= 3  # the uncertainty tables cut to their rows a reader compares
    for href in links:  # relative to the report, and there
        assert not Path(href).is_absolute() and (fixture_report.out / href).is_file(), href


def test_paths_are_relative_to_the_run(tmp_path, monkeypatch):
    from common.paths import display_path

    monkeypatch.chdir(tmp_path)
    (tmp_path / "scenes").mkdir()
    inside = tmp_path / "scenes" / "a.toml"
    assert display_path(inside) == "scenes/a.toml"
    assert display_path("/elsewhere/b.toml") == "/elsewhere/b.toml"


def test_the_campaign_beside_the_run_is_summarised(tmp_path, monkeypatch):
    """A correlation and identification beside results.json: the summary says what they
    found and the report has their section, linking their pages by relative paths."""
    from reports.campaign_summary import campaign_summary
    from reports.summary import campaign_line

    data = Path(__file__).resolve().parent / "data" / "campaign_records"
    for name in ("correlation", "identification"):
        (tmp_path / name).mkdir()
        shutil.copy(data / f"{name}.json", tmp_path / name / f"{name}.json")
    notes: list[str] = []
    scene = Path(__file__).resolve().parents[1] / "scenes" / "actuator-legs.toml"
    digest = hashlib.sha256(scene.read_bytes()).hexdigest()
    monkeypatch.chdir(scene.parents[1])  # the records name the scene from the run's folder
    summary = campaign_summary(tmp_path / "results.json", "scenes/actuator-legs.toml", digest,
                               notes)
    assert notes == [] and summary is not None
    assert summary["same_machine"]
    assert summary["correlation_page"] == "correlation/correlation.html"
    line = campaign_line(summary)
    assert line is not None and "after identification" in line
    identification = json.loads((data / "identification.json").read_text(encoding="utf-8"))
    assert all(p["key"] in line for p in identification["parameters"])


def test_a_table_declared_for_the_report_has_a_caption_in_words():
    from reports.table_words import CAPTIONS

    for r in RECORDS:
        if r.section is None or r.section.template is not None:
            continue
        for t in r.tables:
            assert (r.key, t.name) in CAPTIONS, (r.key, t.name)
    assert Table  # the declaration the captions name


def test_no_number_is_printed_beyond_its_stated_error(fixture_report):
    """Every value shown beside its stated error (the fixture's Sobol' indices, V&V 20 errors,
    the spread's mean and quantiles) carries no digit finer than that error's second
    significant figure (an index none past its third decimal)."""
    from reports.generic_tables import ERROR_OF, SHARE_DECIMALS, SHARES
    from reports.results import resolve

    results = json.loads((Path(__file__).resolve().parent / "fixtures" /
                          "report_results.json").read_text())
    html = fixture_report.html.read_text(encoding="utf-8")
    checked = 0
    for pointer, text in re.findall(r'<td class="num" data-src="([^"]+)">([^<]*)</td>', html):
        at, _, column = pointer.rpartition("/")
        if column not in ERROR_OF:
            continue
        error = resolve(results, f"{at}/{ERROR_OF[column]}")
        if not error:
            continue
        shown = text.removeprefix("< ").replace("\u2212", "-")
        decimals = len(shown.split(".")[1]) if "." in shown else 0
        allowed = error_decimals(error)
        assert decimals <= (min(allowed, SHARE_DECIMALS) if column in SHARES else allowed), \
            (pointer, text, error)
        checked += 1
    assert checked >= 20  # the check ran on the report's numbers, not on none


def test_an_interval_open_on_one_side_and_a_bound_rounded_up():
    """A quantile's interval with no draw below it prints its open side in words; a '< error'
    bound is rounded up, so the printed bound is never below the value."""
    from reports.cells import Cells

    record = next(r for r in RECORDS if r.key == "lobes")
    rows = [{"": "/cases/0/lobes/band/0", "case": "c", "model": "analytical", "samples": 256,
             "least_nominal_mm": 2.0, "least_q025_mm": 0.41,
             "least_q025_interval_mm": [None, 0.4567], "least_median_mm": 1.9,
             "least_q975_mm": 2.5, "level_error_percent": 0.1, "refused": None}]
    results = {"cases": [{"lobes": {"band": [{k: v for k, v in rows[0].items()
                                              if k not in ("", "case")}]}}]}
    shown = _by_header(generic_table(record, "band", rows, Cells(results)))[0]
    assert shown["its 95 % interval (mm)"] == "open – 0.46"
    sobol = _rows([(0.0044, 0.00449, 0.0232, 0.0234)])
    cells = _by_header(generic_table(_sobol_record(), "sobol", sobol, Cells(_results(sobol))))
    assert cells[0]["first-order index"] == "< 0.005"  # 0.0044 below 0.00449: never "< 0.004"
    assert cells[0]["total index"] == "< 0.024"


def test_a_study_that_ran_without_rows_keeps_its_section():
    """Every pose stable (no least depth) or a refused path: the study ran, so its section
    stays (saying what it found, or why it did not compute), never 'not asked'."""
    from reports.cells import Cells
    from reports.generic_tables import generic_sections, ran, refusals

    results = {"studies": {"stability_map": {"least": []}, "uncertainty_path": {
        "refused": "a draw leaves the workspace", "poses": []}}, "cases": []}
    for key, value in {r.key: None for r in RECORDS}.items():
        results["studies"].setdefault(key, value)
    assert ran(results, RECORDS, "stability-map") and ran(results, RECORDS, "uncertainty-path")
    assert not ran(results, RECORDS, "dynamic-stiffness")
    assert generic_sections(results, RECORDS, Cells(results))["stability-map"] == []
    assert refusals(results, RECORDS) == {
        "uncertainty-path": ["Not computed: a draw leaves the workspace"]}
    section = next(r.section for r in RECORDS if r.key == "stability_map")
    assert section is not None and "stable at every pose" in (section.nothing or "")
