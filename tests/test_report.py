"""The report (reports/): built from the small fixture results file, checked as a reader would.

- it builds (HTML and PDF) from tests/fixtures/report_results.json,
- every number printed in an HTML table equals its value in the JSON (within the printed
  rounding): each numeric cell names its source by JSON pointer (data-src),
- every referenced image exists and is a non-empty PNG,
- the PDF has the expected sections (pdftotext),
- a results file of the CI profile (no studies) still builds,
- a bad or missing results file gives a one-line ValueError naming the path, a failed render a
  one-line ReportError, and neither leaves partial output.
"""
from __future__ import annotations

import copy
import json
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest

from reports.build import ReportError, build_report
from reports.results import resolve

FIXTURES = Path(__file__).resolve().parent / "fixtures"
RESULTS = FIXTURES / "report_results.json"
SECTIONS = ("1 Summary", "2 Scene and set-up", "3 Table I reproduction", "4 Convergence",
            "5 Mode shapes", "6 Speed vs error", "7 Workspace maps",
            "8 Case 2 angle conventions and height calibration")
NUMBER = re.compile(r"^[+\-\u2212]?[\d\u2009]+(\.\d+)?$")


class _Cells(HTMLParser):
    """Table cells (with their attributes and text) and image sources of an HTML page."""

    def __init__(self):
        super().__init__()
        self.cells: list[dict] = []
        self.images: list[str] = []
        self.headings: list[str] = []
        self._open: list[dict] = []
        self._heading: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag in ("td", "span") and (tag == "td" or "data-src" in attrs):
            self._open.append({"tag": tag, "attrs": attrs, "text": ""})
        elif tag == "img":
            self.images.append(attrs["src"])
        elif tag == "h2":
            self._heading = []

    def handle_endtag(self, tag):
        if tag in ("td", "span") and self._open and self._open[-1]["tag"] == tag:
            self.cells.append(self._open.pop())
        elif tag == "h2" and self._heading is not None:
            self.headings.append("".join(self._heading).strip())
            self._heading = None

    def handle_data(self, data):
        for cell in self._open:
            cell["text"] += data
        if self._heading is not None:
            self._heading.append(data)


def _parse(html: str) -> _Cells:
    parser = _Cells()
    parser.feed(html)
    return parser


def _number(text: str) -> tuple[float, int]:
    """Printed value and its number of decimals (the rounding to compare within)."""
    clean = text.replace("\u2212", "-").replace("\u2009", "").replace("+", "").strip(" †")
    decimals = len(clean.split(".")[1]) if "." in clean else 0
    return float(clean), decimals


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    html, pdf = build_report(RESULTS, out)
    return {"out": out, "html": html, "pdf": pdf, "results": json.loads(RESULTS.read_text()),
            "page": _parse(html.read_text(encoding="utf-8"))}


def test_builds_html_and_pdf(built):
    assert built["html"] == built["out"] / "report.html"
    assert built["html"].stat().st_size > 10_000
    assert built["pdf"].read_bytes()[:5] == b"%PDF-"
    assert not list(built["out"].glob(".report-*")), "temporary directory left behind"


def test_papers_inconsistent_printed_errors_are_flagged(built):
    import html as html_lib
    text = html_lib.unescape(built["html"].read_text(encoding="utf-8"))
    notes = [c["paper"].get("printed_error_note") for c in built["results"]["cases"]
             if c.get("paper")]
    assert any(notes)
    for note in filter(None, notes):
        assert note in text


def test_table_numbers_equal_the_json(built):
    sourced = [c for c in built["page"].cells if "data-src" in c["attrs"]]
    assert len(sourced) > 300
    for cell in sourced:
        value = resolve(built["results"], cell["attrs"]["data-src"])
        text = cell["text"].strip()
        if isinstance(value, str):
            assert text.endswith(value) or value in text, (cell, value)
            continue
        printed, decimals = _number(text)
        expected = value * float(cell["attrs"].get("data-scale", 1))
        assert abs(printed - expected) <= 0.5 * 10**-decimals * (1 + 1e-9) + 1e-12, \
            (cell["attrs"]["data-src"], text, expected)


def test_every_printed_number_has_a_source(built):
    for cell in built["page"].cells:
        if cell["tag"] != "td":
            continue
        text = cell["text"].strip().rstrip("†")
        if NUMBER.match(text):
            assert "data-src" in cell["attrs"], f"number {text!r} printed without a source"


def test_table_i_rows_of_both_cases(built):
    """The paper's rows and our pairs of case1/case2 all appear, mode by mode."""
    srcs = {c["attrs"]["data-src"] for c in built["page"].cells if "data-src" in c["attrs"]}
    for i, case in enumerate(built["results"]["cases"]):
        for j, _ in enumerate(case["pairs"]):
            for key in ("f_fem_hz", "f_analytical_hz", "error_percent", "mac"):
                assert f"/cases/{i}/pairs/{j}/{key}" in srcs
        if case.get("paper"):
            for k in range(6):
                assert f"/cases/{i}/paper/fea_hz/{k}" in srcs
                assert f"/cases/{i}/paper/theory_hz/{k}" in srcs


def test_images_exist_and_are_not_empty(built):
    images = built["page"].images
    names = {Path(src).name for src in images}
    for case in ("case1", "case2"):
        for k in range(1, 7):
            assert f"mode_{case}_fem_{k}.png" in names
            assert f"mode_{case}_beam_{k}.png" in names
        assert f"mac_{case}.png" in names
        assert f"element_convergence_{case}.png" in names
        assert f"fem_refinement_{case}.png" in names
    assert {"speed_vs_error.png", "workspace_polar.png", "workspace_height.png"} <= names
    for src in images:
        path = built["out"] / src
        assert path.is_file(), src
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", src
        assert path.stat().st_size > 2_000, src


def test_sections_in_html_and_pdf(built):
    assert [h for h in built["page"].headings][:len(SECTIONS)] == list(SECTIONS)
    if shutil.which("pdftotext") is None:
        pytest.skip("pdftotext (poppler-utils) not installed")
    text = subprocess.run(["pdftotext", "-layout", str(built["pdf"]), "-"], check=True,
                          capture_output=True, text=True).stdout
    for title in SECTIONS + ("9 Other cases", "Case 1: symmetric pose", "Case 2: tilted pose",
                             "Calibrated values", "Environment", "page 1 of"):
        assert title in text, title
    assert "\f" in text  # more than one page


def _ci_profile(results: dict) -> dict:
    """What a CI-profile run writes: case1/case2, no refinement, variants or studies."""
    ci = copy.deepcopy(results)
    ci["profile"] = "ci"
    ci["studies"] = {}
    ci["cases"] = [c for c in ci["cases"] if c["name"] in ("case1", "case2")]
    for case in ci["cases"]:
        for key in ("fem_refinement", "models", "element_convergence", "fem_variants",
                    "speed_vs_error"):
            case.pop(key, None)
        case["fem_estimated_error_percent"] = case["fem_reference_hz"] = None
        for pair in case["pairs"]:
            for key in ("fem_estimated_error_percent", "f_reference_hz",
                        "error_vs_reference_percent"):
                pair.pop(key, None)
    ci["cases"][1]["fem"].pop("vtu")  # and one case without its mode file
    ci["cases"][1]["analytical"].pop("leg_axis_shapes")
    return ci


def test_ci_profile_results_build(tmp_path):
    results = _ci_profile(json.loads(RESULTS.read_text()))
    (tmp_path / "results.json").write_text(json.dumps(results))
    shutil.copytree(FIXTURES / "modes", tmp_path / "modes")
    html, pdf = build_report(tmp_path / "results.json", tmp_path)
    page = html.read_text(encoding="utf-8")
    assert "No element-convergence study in this results file" in page
    assert "No workspace map in this results file" in page
    assert "names no FEM mode file" in page
    assert pdf.stat().st_size > 10_000
    parsed = _parse(page)
    for cell in parsed.cells:
        if "data-src" in cell["attrs"] and not isinstance(
                resolve(results, cell["attrs"]["data-src"]), str):
            printed, decimals = _number(cell["text"])
            assert abs(printed - resolve(results, cell["attrs"]["data-src"])
                       * float(cell["attrs"].get("data-scale", 1))) <= 0.5 * 10**-decimals + 1e-9


def _assert_untouched(out: Path, before: dict[str, bytes]) -> None:
    after = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    assert after == before
    assert not [p for p in out.iterdir() if p.name.startswith(".")], "temporary files left"


@pytest.mark.parametrize("content, message", [
    (None, "results file not found"),
    ("{ not json", "not valid JSON"),
    ('{"schema": 99, "cases": []}', "schema 99"),
    ('{"schema": 1, "cases": []}', "'cases' must be a non-empty list"),
    ('{"schema": 1, "scene": {}, "environment": {}, "cases": [{"name": "case1"}]}',
     "lacks 'pose'"),
])
def test_bad_results_file(tmp_path, content, message):
    path = tmp_path / "results.json"
    if content is not None:
        path.write_text(content)
    out = tmp_path / "out"
    with pytest.raises(ValueError) as info:
        build_report(path, out)
    text = str(info.value)
    assert str(path) in text and message in text and "\n" not in text
    assert not out.exists(), "output directory created for a bad results file"


def test_bad_value_names_the_field(tmp_path):
    results = json.loads(RESULTS.read_text())
    results["cases"][0]["pairs"][2]["mac"] = "high"
    path = tmp_path / "results.json"
    path.write_text(json.dumps(results))
    with pytest.raises(ValueError, match=r"cases\[0\]\.pairs\[2\]\.mac must be a number"):
        build_report(path, tmp_path / "out")


def test_failed_render_keeps_the_previous_report(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "report.html").write_text("previous report")
    (out / "report.pdf").write_bytes(b"%PDF-previous")
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    results = _ci_profile(json.loads(RESULTS.read_text()))
    results["cases"][0]["fem"]["vtu"] = "modes/broken.vtu"
    (tmp_path / "modes").mkdir()
    (tmp_path / "modes" / "broken.vtu").write_text("<VTKFile> truncated")
    (tmp_path / "results.json").write_text(json.dumps(results))
    with pytest.raises(ReportError) as info:
        build_report(tmp_path / "results.json", out)
    assert "broken.vtu" in str(info.value) and "\n" not in str(info.value)
    _assert_untouched(out, before)


def test_cli_one_line_error(tmp_path, capsys):
    from reports.__main__ import main

    missing = tmp_path / "nowhere.json"
    assert main(["--results", str(missing), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(missing) in err and err.startswith("error: ")
    assert not (tmp_path / "out").exists()
