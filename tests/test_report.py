"""The report (reports/): built from the small fixture results file, checked as a reader would.

- it builds (HTML and PDF) from tests/fixtures/report_results.json,
- every number printed in an HTML table equals its value in the JSON (within the printed
  rounding): each numeric cell names its source by JSON pointer (data-src),
- every referenced image exists and is a non-empty PNG,
- the PDF has the expected sections (pdftotext),
- a results file of the CI profile (no studies) still builds, omitting the sections it has no
  data for; results without the paper's rows show nothing of the paper,
- the report names the project version, the commit and the scene file's sha256,
- a bad, missing or outdated results file gives a one-line ValueError naming the path, a failed
  render a one-line ReportError, and neither leaves partial output.
"""
from __future__ import annotations

import copy
import json
import re
import shutil
import subprocess
from html import unescape
from html.parser import HTMLParser
from pathlib import Path

import pytest

from reports.build import ReportError, build_report
from reports.results import resolve
from results import SCHEMA_VERSION, stub
from studies import RECORDS

FIXTURES = Path(__file__).resolve().parent / "fixtures"
RESULTS = FIXTURES / "report_results.json"
SECTIONS = ("1 Summary", "2 Fidelity: what the scene asked, what was chosen",
            "3 Scene and set-up", "4 Table I reproduction", "5 Convergence",
            "6 Mode shapes", "7 Speed vs error", "8 Workspace maps",
            "9 The model against the FEM over the workspace", "10 Joint orders",
            "11 Joint faces: rigid and distributing couplings",
            "12 Hard cases: numerical stability and physics checks",
            "13 Verifying the referee: published benchmarks",
            "14 Reading the paper: angle conventions and height calibration",
            "15 Input uncertainty: spread, Sobol' indices, V&V 20",
            "16 Input uncertainty over the workspace",
            "17 Other cases")
NUMBER = re.compile(r"^[+\-\u2212]?[\d\u2009]+(\.\d+)?(e[+\-\u2212]?\d+)?$")


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
    """Printed value and its number of decimals (the rounding to compare within); in
    scientific notation (2.5e-13) the decimals of the last printed digit's place (14)."""
    clean = text.replace("\u2212", "-").replace("\u2009", "").replace("+", "").strip(" †")
    mantissa, _, exponent = clean.partition("e")
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    return float(clean), decimals - int(exponent or 0)


@pytest.fixture(scope="module")
def built(fixture_report):
    html = fixture_report.html
    return {"out": fixture_report.out, "html": html, "pdf": fixture_report.pdf,
            "results": json.loads(RESULTS.read_text()),
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
        if isinstance(value, str):  # in full, or its opening words (a V&V 20 verdict)
            assert text.endswith(value) or value in text or value.startswith(text), (cell, value)
            continue
        if text.startswith("< "):  # an index its sampling error exceeds: below the error
            assert abs(value) < _number(text[2:])[0] * (1 + 1e-9), (cell, value)
            continue
        if isinstance(value, list):  # an interval, "lo – hi" ("open": no bound that side)
            for part, v in zip(text.split(" – "), value, strict=True):
                if v is None:
                    assert part == "open", (cell, value)
                    continue
                printed, decimals = _number(part)
                assert abs(printed - v) <= 0.5 * 10**-decimals * (1 + 1e-9) + 1e-12, (cell, v)
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


def test_static_pictures_exist_for_the_pdf_and_the_page_is_self_contained(built):
    """Every static picture the PDF shows is a non-empty PNG under figures/; report.html
    refers to no file: its pictures are embedded (data: URIs) and its charts inline, each
    chart with its static twin among the PDF's pictures."""
    names = {p.name for p in (built["out"] / "figures").glob("*.png")}
    for case in ("case1", "case2"):
        for k in range(1, 7):
            assert f"mode_{case}_fem_{k}.png" in names
            assert f"mode_{case}_beam_{k}.png" in names
        assert f"mac_{case}.png" in names
        assert f"element_convergence_{case}.png" in names
        assert f"fem_refinement_{case}.png" in names
    assert {"speed_vs_error.png", "workspace_polar.png", "workspace_height.png"} <= names
    for name in names:
        path = built["out"] / "figures" / name
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
        assert path.stat().st_size > 2_000, name
    assert all(src.startswith("data:image/png;base64,") for src in built["page"].images)
    text = built["html"].read_text(encoding="utf-8")
    markup = re.sub(r"<script\b.*?</script>", "", text, flags=re.S)
    # nothing fetched from outside; links only to the files beside it (the full tables as
    # CSV, a campaign's pages)
    outside = re.search(r"""(?<![\w-])(src=["'](?!data:)|href=["'](?!data:|#|tables/studies/"""
                        r"""[\w-]+\.csv|correlation/|identification/))""", markup)
    assert not outside, markup[outside.start() - 80:outside.end() + 80]
    twins = {"speed": "speed_vs_error", "workspace_map": "workspace_polar",
             "workspace_height": "workspace_height", "validation_map": "workspace_validation",
             "modes": "mode_{}_fem_1", "sweep": "stiffness_sweep_{}",
             "uncertainty": "sobol_{}", "uncertainty_path": "uncertainty_path",
             "dynamic_stiffness": "dynamic_stiffness", "tool_response": "tool_response_{}",
             "lobes": "lobes_{}", "stability_map": "stability_map"}
    keys = re.findall(r'data-chart="([^"]+)"', text)
    assert len(keys) >= 8
    # every chart has its static twin in report.pdf, a study's section's too
    assert {"uncertainty", "uncertainty_path"} <= {k.partition(":")[0] for k in keys}
    main = {c["name"] for c in built["results"]["cases"] if c["paper"]}
    for key in keys:
        kind, _, case = key.partition(":")
        if kind == "uncertainty" and case not in main:  # report.pdf draws the main cases'
            continue
        stem = twins.get(kind, kind + "_{}").format(case)
        assert f"{stem}.png" in names, key


def test_sections_in_html_and_pdf(built):
    assert [h for h in built["page"].headings][:len(SECTIONS)] == list(SECTIONS)
    if shutil.which("pdftotext") is None:
        pytest.skip("pdftotext (poppler-utils) not installed")
    text = subprocess.run(["pdftotext", "-layout", str(built["pdf"]), "-"], check=True,
                          capture_output=True, text=True).stdout
    for title in SECTIONS + ("Case 1: symmetric pose", "Case 2: tilted pose",
                             "Calibrated values", "Environment", "page 1 of"):
        assert title in text, title
    assert "\f" in text  # more than one page


def _ci_profile(results: dict) -> dict:
    """What a CI-profile run writes: case1/case2, no refinement, variants or studies (each
    case's FEM error and limit from two meshes: the fixture's numbers stand in for them)."""
    ci = copy.deepcopy(results)
    ci["profile"] = "ci"
    ci["studies"] = {**stub(RECORDS, "scene"),
                     "reachable_workspace": results["studies"]["reachable_workspace"]}
    ci["cases"] = [c for c in ci["cases"] if c["name"] in ("case1", "case2")]
    for case in ci["cases"]:
        case.update(stub(RECORDS, "case"), fem_refinement=None)
    ci["cases"][1]["fem"]["vtu"] = None  # and one case without its mode file
    return ci


def _build_variant(results: dict, folder: Path) -> tuple[Path, Path]:
    """The report of a changed copy of the fixture, built beside the fixture's mode files."""
    (folder / "results.json").write_text(json.dumps(results))
    shutil.copytree(FIXTURES / "modes", folder / "modes")
    return build_report(folder / "results.json", folder, records=RECORDS)


def test_ci_profile_results_build(tmp_path):
    results = _ci_profile(json.loads(RESULTS.read_text()))
    campaign = Path(__file__).resolve().parent / "data" / "campaign_records"
    for name in ("correlation", "identification"):  # `make`'s campaign beside the run
        (tmp_path / name).mkdir()
        shutil.copy(campaign / f"{name}.json", tmp_path / name)
    html, pdf = _build_variant(results, tmp_path)
    page = html.read_text(encoding="utf-8")
    # the whole chain in one report: the campaign named in the summary, with its section
    summary = unescape(page[page.index('<section id="summary">'):
                            page.index('<section id="fidelity">')])
    assert "Test campaign campaigns/actuator-legs/campaign.toml (another machine than this " \
        "report's: actuator-legs)" in summary and "after identification" in summary
    assert '<section id="campaign">' in page
    assert '<a href="identification/identification.html">' in page
    assert "/work/" not in page and "/tmp/" not in page  # no path of the machine it ran on
    assert "names no FEM mode file" in page
    assert "Without a refinement study (profile ci): from the run's mesh and the next coarser" \
        in page  # the FEM's error column is explained where it comes from
    headings = _parse(page).headings
    for absent in ("Convergence", "Speed vs error", "Workspace maps", "Joint orders",
                   "Joint faces", "Reading the paper"):  # sections without data: omitted
        assert not any(absent in h for h in headings), absent
    assert ("Not in these results (profile ci): convergence studies, speed vs error, "
            "workspace maps, workspace validation, both joint orders, both joint-face couplings, "
            "hard cases") in page
    assert headings[:5] == ["1 Summary", "2 Fidelity: what the scene asked, what was chosen",
                            "3 Scene and set-up", "4 Table I reproduction",
                            "5 Mode shapes"]  # numbered without gaps
    assert pdf.stat().st_size > 10_000
    if shutil.which("pdftotext"):
        from tests.test_report_pages import words_past_the_page

        assert words_past_the_page(pdf) == []
    parsed = _parse(page)
    for cell in parsed.cells:
        if "data-src" in cell["attrs"] and not isinstance(
                resolve(results, cell["attrs"]["data-src"]), str):
            printed, decimals = _number(cell["text"])
            assert abs(printed - resolve(results, cell["attrs"]["data-src"])
                       * float(cell["attrs"].get("data-scale", 1))) <= 0.5 * 10**-decimals + 1e-9


def test_chosen_solid_legs_state_their_map_model_and_its_own_error(tmp_path):
    """Issue 51: with solid legs chosen, the fidelity table says how maps solve them (modes a
    part, coordinates before and after) and the error that costs, each number from the
    JSON."""
    results = _ci_profile(json.loads(RESULTS.read_text()))
    results["fidelity"]["analytical"]["batched"] = {
        "part_modes": 18, "coordinates": 171, "coordinates_kept": 315,
        "error_percent": 0.000468, "check_error_percent": 0.000476, "check_poses": 9}
    html, _ = _build_variant(results, tmp_path)
    page = _parse(html.read_text(encoding="utf-8"))
    sources = {c["attrs"]["data-src"]: c["text"].strip() for c in page.cells
               if "data-src" in c["attrs"]}
    q = "/fidelity/analytical/batched"
    assert sources[f"{q}/part_modes"] == "18" and sources[f"{q}/coordinates"] == "171"
    assert sources[f"{q}/coordinates_kept"] == "315"
    assert sources[f"{q}/error_percent"] == "0.0005"


def _assert_untouched(out: Path, before: dict[str, bytes]) -> None:
    after = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    assert after == before
    assert not [p for p in out.iterdir() if p.name.startswith(".")], "temporary files left"


@pytest.mark.parametrize("content, message", [
    (None, "results file not found"),
    ("{ not json", "not valid JSON"),
    ('{"schema": 99, "cases": []}',
     f"results schema 99, this version reads schema {SCHEMA_VERSION}"),
    ('{"schema": 2, "cases": []}',
     f"results schema 2, this version reads schema {SCHEMA_VERSION}: rerun `make`"),
    ('{"cases": []}', "results schema None"),
    (f'{{"schema": {SCHEMA_VERSION}, "cases": []}}', "profile: field required"),
])
def test_bad_results_file(tmp_path, content, message):
    path = tmp_path / "results.json"
    if content is not None:
        path.write_text(content)
    out = tmp_path / "out"
    with pytest.raises(ValueError) as info:
        build_report(path, out, records=RECORDS)
    text = str(info.value)
    assert str(path) in text and message in text and "\n" not in text
    assert not out.exists(), "output directory created for a bad results file"


def test_bad_value_names_the_field(tmp_path):
    results = json.loads(RESULTS.read_text())
    results["cases"][0]["pairs"][2]["mac"] = "high"
    path = tmp_path / "results.json"
    path.write_text(json.dumps(results))
    with pytest.raises(ValueError, match=r"cases\[0\]\.pairs\[2\]\.mac: input should be a "
                                         r"valid number, got 'high'"):
        build_report(path, tmp_path / "out", records=RECORDS)


def test_results_without_cases_or_with_an_unknown_field_are_refused(tmp_path):
    results = json.loads(RESULTS.read_text())
    for change, message in ((lambda r: r.update(cases=[]), "cases: the results hold no case"),
                            (lambda r: r["cases"][0]["pose"].pop("centre_mm"),
                             "cases[0].pose.centre_mm: field required"),
                            (lambda r: r["cases"][0]["fem"].update(colour="red"),
                             "cases[0].fem.colour: extra inputs are not permitted")):
        broken = copy.deepcopy(results)
        change(broken)
        path = tmp_path / "results.json"
        path.write_text(json.dumps(broken))
        with pytest.raises(ValueError) as info:
            build_report(path, tmp_path / "out", records=RECORDS)
        assert message in str(info.value) and "\n" not in str(info.value)


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
        build_report(tmp_path / "results.json", out, records=RECORDS)
    assert "broken.vtu" in str(info.value) and "\n" not in str(info.value)
    _assert_untouched(out, before)


@pytest.mark.parametrize("content", [None, '{"schema": 1, "cases": []}'],
                         ids=["missing", "outdated"])
def test_cli_bad_results_file_is_one_line_and_status_2(tmp_path, capsys, content):
    from rps.app import main as rps_main

    def main(argv):
        return rps_main(["report", *argv])

    path = tmp_path / "results.json"
    if content is not None:
        path.write_text(content)
    assert main(["--results", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(path) in err and err.startswith("error: ")
    if content is not None:
        assert "schema 1" in err and "rerun `make`" in err
    assert not (tmp_path / "out").exists()


def test_report_names_version_commit_and_scene_digest(built):
    srcs = {c["attrs"]["data-src"] for c in built["page"].cells if "data-src" in c["attrs"]}
    assert {"/environment/project_version", "/environment/git_commit", "/scene/sha256"} <= srcs
    env = built["results"]["environment"]
    head = built["html"].read_text(encoding="utf-8").split("</header>")[0]
    assert f"rps-elastodynamics {env['project_version']}" in head
    assert env["git_commit"][:12] in head


def test_repeated_pair_with_two_limits_is_flagged(built):
    from reports.case_tables import repeated_limit_notes

    case = next(c for c in built["results"]["cases"] if c["fem_refinement"]
                and any(p["repeated"] for p in c["pairs"]))
    notes = repeated_limit_notes(case)  # none when the pair's limits print alike (harmonic legs)
    assert all("are a repeated pair" in text for text, _ in notes)
    for text, _ in notes:
        assert text in html_text(built)
    # members drawn apart within their estimated error: said so, not flagged
    near = copy.deepcopy(case)
    group = [p["fem_mode"] for p in near["pairs"] if p["repeated"]][:2]
    limits = near["fem_refinement"]["extrapolated_hz"]
    estimate = near["fem_estimated_error_percent"][group[0] - 1]
    limits[group[1] - 1] = limits[group[0] - 1] * (1 + 0.5 * estimate / 100)
    (text, beyond), = repeated_limit_notes(near)
    assert "are a repeated pair" in text and "within their estimated error" in text and not beyond
    # members 1 and 2 drawn apart by far more than their estimated error: said so
    wide = copy.deepcopy(case)
    group = [p["fem_mode"] for p in wide["pairs"] if p["repeated"]][:2]
    limits = wide["fem_refinement"]["extrapolated_hz"]
    limits[group[1] - 1] = limits[group[0] - 1] * 1.01
    flagged = [n for n in repeated_limit_notes(wide) if n[1]]
    assert flagged and "more than their estimated error" in flagged[0][0]


def html_text(built) -> str:
    import html as html_lib
    return html_lib.unescape(built["html"].read_text(encoding="utf-8"))


def test_convergence_panels_say_what_the_limit_is():
    from reports.figures import limit_note

    ref = {"status": ["ok", "order bounded by theory", "non-monotone"],
           "observed_order": [1.3, 1.424, None],
           "extrapolated_hz": [99.0, 98.0, 100.5], "frequencies_hz": [[101, 101, 101],
                                                                      [100, 99, 100.5]]}
    assert limit_note(ref, 0) == ""
    assert limit_note(ref, 1) == "p = 1.42 (theory)"  # extrapolated, not the finest mesh
    assert limit_note(ref, 2) == "non-monotone, limit = finest"


def _without_paper(results: dict) -> dict:
    bare = copy.deepcopy(results)
    for case in bare["cases"]:
        case["paper"] = None
        case["description"] = case["name"]  # the scene's titles name the paper's table
    bare["scene"]["calibrated"] = []  # whose reasons cite the paper
    bare["studies"]["angle_conventions"] = []
    bare["studies"]["height_calibration"] = None
    return bare


def test_results_without_paper_rows_show_nothing_of_the_paper(tmp_path):
    html, _ = _build_variant(_without_paper(json.loads(RESULTS.read_text())), tmp_path)
    page = html.read_text(encoding="utf-8")
    headings = _parse(page).headings
    assert "4 Analytical vs FEM" in headings and "7 Speed vs error" in headings
    for absent in ("Table I", "paper FEA", "Reading the paper", "the paper's 0.82 s",
                   "Section 2 text"):
        assert absent not in page, absent


def test_tables_drop_the_paper_columns_without_paper_rows():
    from results.tables import case_csv, case_markdown

    case = json.loads(RESULTS.read_text())["cases"][0]
    assert case_csv(case).startswith("mode,paper_fea_hz,paper_theory_hz,paper_error_percent,")
    bare = dict(case, paper=None)
    assert case_csv(bare).startswith("mode,fem_hz,fem_estimated_error_percent,analytical_hz")
    assert "paper" not in case_markdown(bare)
    rows = case_csv(bare).splitlines()
    assert len(rows) == len(case["pairs"]) + 1 and all(r.count(",") == 5 for r in rows)


def test_the_verification_section_shows_every_benchmark_mode(built):
    """Every reference mode of every published benchmark, with its source cited and its
    deviation, order, stated error and band read from results.studies.fem_verification."""
    import html as html_lib
    record = built["results"]["studies"]["fem_verification"]
    assert record and len(record["cases"]) >= 5
    srcs = {c["attrs"]["data-src"] for c in built["page"].cells if "data-src" in c["attrs"]}
    text = html_lib.unescape(built["html"].read_text(encoding="utf-8"))
    for i, case in enumerate(record["cases"]):
        assert case["source"] in text and case["tolerance_reason"] in text
        for k, _ in enumerate(case["modes"]):
            for key in ("reference_hz", "deviation_percent", "stated_error_percent",
                        "tolerance_percent"):
                assert f"/studies/fem_verification/cases/{i}/modes/{k}/{key}" in srcs


def test_the_refinement_tables_state_the_gci_beside_richardson(built):
    srcs = {c["attrs"]["data-src"] for c in built["page"].cells if "data-src" in c["attrs"]}
    for i, case in enumerate(built["results"]["cases"]):
        ref = case["fem_refinement"]
        if not ref or f"/cases/{i}/fem_refinement/mesh_sizes_mm/0" not in srcs:
            continue  # no refinement table for this case (the other cases have none)
        for r, _ in enumerate(ref["mesh_sizes_mm"]):
            assert f"/cases/{i}/fem_refinement/gci_percent_max/{r}" in srcs
        # the stated error is the larger of the two estimates, mode by mode
        for rich, grid, stated in zip(ref["richardson_error_percent"], ref["gci_percent"],
                                      ref["estimated_error_percent"]):
            assert stated == [max(a, b) for a, b in zip(rich, grid)]
