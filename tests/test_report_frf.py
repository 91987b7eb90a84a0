"""The interactive charts of the dynamic-compliance studies in report.html (seconds: synthetic
records on the fixture results, no figure drawn, no FEM):

- the least-dynamic-stiffness map (results.studies.dynamic_stiffness): one polar panel per
  layer, a button per direction, colour log10 of the stiffness (N/m), the least pose starred,
  hover the pose, the stiffness, the peak's frequency and its mode; a cell without a stiffness
  has no point, a direction without any has no button;
- the tool's receptance of every case (results.cases[].tool_response): |H_xx|, |H_yy|, |H_zz|
  on log axes, both models' curves and the solid's direct-response peaks;
- both drawn in their study's section of the page (under its tables); a None record draws
  nothing, and a chart that cannot be drawn is a note, not a failure.
"""
from __future__ import annotations

import copy
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from reports import interactive
from reports.document import context, render_html
from reports.interactive_tool import dynamic_stiffness_map, tool_response
from results import validated
from studies import RECORDS

FIXTURE = Path(__file__).resolve().parent / "fixtures" / "report_results.json"
HEIGHTS, TILTS, AZIMUTHS = [500.0, 600.0], [[0.0, 5.0, 10.0], [0.0, 4.0, 8.0]], [0.0, 120.0, 240.0]


def _grid(value, missing=()):
    """[layer][ring][azimuth] of value(layer, ring, azimuth), None at the cells `missing`."""
    return [[[None if (iz, r, a) in missing else value(iz, r, a) for a in range(3)]
             for r in range(3)] for iz in range(2)]


def stiffness_record() -> dict:
    """x everywhere but one cell, y everywhere, z on the upper layer only."""
    base = {"x": 1e5, "y": 2e5, "z": 3e7}
    missing = {"x": {(1, 2, 1)}, "y": set(),
               "z": {(0, r, a) for r in range(3) for a in range(3)}}

    def k(d):
        return lambda iz, r, a: base[d] * (1 + 0.5 * iz + 0.1 * r + 0.01 * a)
    least = [{"direction": d, "stiffness_n_per_m": base[d] * (1.5 if d == "z" else 1.0),
              "frequency_hz": 20.0 + i, "mode": i + 1, "height_mm": HEIGHTS[d == "z"],
              "tilt_deg": 0.0, "azimuth_deg": 0.0} for i, d in enumerate("xyz")]
    return {"point_mm": [0.0, 0.0, -150.0], "damping": "modal ratio 0.03 for every mode",
            "analytical": "euler-bernoulli, s = 3, plate inertia", "lines": 100,
            "modes_summed": 8, "heights_mm": HEIGHTS, "tilts_deg": TILTS,
            "azimuths_deg": AZIMUTHS,
            "stiffness_n_per_m": {d: _grid(k(d), missing[d]) for d in "xyz"},
            "peak_hz": {d: _grid(lambda iz, r, a: 20.0 + r + iz, missing[d]) for d in "xyz"},
            "mode": {d: _grid(lambda iz, r, a: 1 + r % 2, missing[d]) for d in "xyz"},
            "least": least, "poses": 18, "seconds": 1.0}


def tool_record() -> dict:
    """Peaks along x (two) and z, none along y."""
    f = np.linspace(0.0, 100.0, 51)

    def magnitude(f0, g):
        return (g / np.abs(1 - (f / f0) ** 2 + 0.06j * f / f0)).tolist()

    def peak(d, mode, hz, m_per_n):
        return {"direction": d, "fem_mode": mode, "fem_direct_hz": hz,
                "fem_direct_m_per_n": m_per_n, "fem_frequency_error_percent": None,
                "fem_magnitude_error_percent": 0.01, "fem_modal_hz": hz * 1.0001,
                "fem_modal_m_per_n": m_per_n * 0.999,
                "fem_modal_magnitude_error_percent": -0.1, "analytical_hz": hz * 1.005,
                "frequency_error_percent": 0.5, "analytical_m_per_n": m_per_n * 1.01,
                "magnitude_error_percent": 1.0}
    static = [{"direction": d, "fem_m_per_n": g, "fem_error_percent": 0.01,
               "analytical_m_per_n": g * 1.01, "error_percent": 1.0}
              for d, g in (("x", 4e-7), ("y", 3e-7), ("z", 4e-9))]
    return {"point_mm": [0.0, 0.0, -150.0], "damping": "modal ratio 0.03 for every mode",
            "check_damping": "Rayleigh, alpha = 10 1/s, beta = 3e-05 s",
            "analytical": "euler-bernoulli, s = 3, plate inertia", "fem_mesh_size_mm": 35.2,
            "coarse_mesh_size_mm": 44.0, "static": static,
            "peaks": [peak("x", 1, 30.0, 7e-6), peak("x", 5, 80.0, 5e-8),
                      peak("z", 4, 90.0, 7e-8)],
            "unmatched": [{"direction": "y", "reason": "the solid's peak at 31 Hz (mode 2) "
                           "has none in the analytical model within 20 %"}],
            "curves": {"frequency_hz": f.tolist(),
                       "analytical_m_per_n": {"x": magnitude(30.0, 4e-7),
                                              "y": magnitude(32.0, 3e-7),
                                              "z": magnitude(90.0, 4e-9)},
                       "fem_m_per_n": {"x": magnitude(30.1, 4e-7), "y": magnitude(32.1, 3e-7),
                                       "z": magnitude(90.2, 4e-9)}},
            "seconds": 2.0}


@pytest.fixture(scope="module")
def fixture_raw() -> dict:
    return json.loads(FIXTURE.read_text(encoding="utf-8"))


def _results(raw: dict, stiffness, tool):
    """The fixture results with these records (the first case's tool response; the others
    None), checked against the schema: the synthetic records are records the run may write."""
    raw = copy.deepcopy(raw)
    raw["studies"]["dynamic_stiffness"] = stiffness
    for i, case in enumerate(raw["cases"]):
        case["tool_response"] = tool if i == 0 else None
    return validated(raw, RECORDS, "test results")


def _page(results, tmp_path, monkeypatch) -> tuple[str, dict, list[str]]:
    """report.html of these results without its pictures (none drawn: the sections that need
    them are left out) and without the mode viewers; (page, charts, notes)."""
    monkeypatch.setattr(interactive, "mode_viewer", lambda *args: None)
    figs = {"cases": {c["name"]: {"modes": {"pairs": [], "fem_note": None}}
                      for c in results["cases"]}, "notes": []}
    ctx = context(results, tmp_path / "results.json", figs, RECORDS)
    notes: list[str] = []
    charts = interactive.build_charts(results, FIXTURE, notes)
    return render_html(dict(ctx, notes=ctx["notes"] + notes), charts, tmp_path), charts, notes


def _section(page: str, anchor: str) -> str:
    found = re.search(rf'<section id="{anchor}">.*?</section>', page, re.S)
    assert found, anchor
    return found.group(0)


def test_both_charts_are_drawn_in_their_sections(fixture_raw, tmp_path, monkeypatch):
    results = _results(fixture_raw, stiffness_record(), tool_record())
    page, charts, notes = _page(results, tmp_path, monkeypatch)
    assert not [n for n in notes if "dynamic_stiffness" in n or "tool_response" in n], notes
    name = results["cases"][0]["name"]
    stiffness = _section(page, "dynamic-stiffness")
    assert 'data-chart="dynamic_stiffness"' in stiffness
    # a picture first, then the table (reports/README.md, "Every section")
    assert stiffness.index('data-chart="dynamic_stiffness"') < stiffness.index("<table")
    assert "1 / max |H_dd|" in stiffness and "N/m" in stiffness
    tool = _section(page, "tool-response")
    assert f'data-chart="tool_response:{name}"' in tool
    assert tool.count("data-chart=") == 1  # the other cases have no record
    assert "m/N" in tool and "direct frequency response" in tool
    block = re.search(r'<script type="application/json" id="rps-charts">(.*?)</script>', page,
                      re.S)
    assert block
    shown = json.loads(block.group(1))
    assert {"dynamic_stiffness", f"tool_response:{name}"} <= set(shown)
    hover = " ".join(t.get("hovertemplate", "") for t in
                     shown["dynamic_stiffness"]["figure"]["data"])
    for field in ("z = ", " mm", "θ = ", "φ = ", "N/m", " Hz", "mode"):
        assert field in hover, field
    assert charts["dynamic_stiffness"]["section"] == "dynamic-stiffness"
    assert charts[f"tool_response:{name}"]["section"] == "tool-response"


def test_none_records_draw_nothing(fixture_raw, tmp_path, monkeypatch):
    results = _results(fixture_raw, None, None)
    page, charts, notes = _page(results, tmp_path, monkeypatch)
    assert not [k for k in charts if k.startswith(("dynamic_stiffness", "tool_response"))]
    assert 'id="dynamic-stiffness"' not in page and 'id="tool-response"' not in page
    assert not [n for n in notes if "dynamic_stiffness" in n or "tool_response" in n]


def test_a_chart_that_cannot_be_drawn_is_a_note(fixture_raw, tmp_path, monkeypatch):
    results = _results(fixture_raw, stiffness_record(), tool_record())
    del results["cases"][0]["tool_response"]["curves"]  # type: ignore[misc]
    page, charts, notes = _page(results, tmp_path, monkeypatch)
    assert "dynamic_stiffness" in charts
    assert not [k for k in charts if k.startswith("tool_response")]
    assert [n for n in notes if n.startswith("interactive tool_response:")
            and n.endswith("not drawn (its tables are shown)")], notes
    assert 'id="tool-response"' in page  # its tables still are


def test_stiffness_map_skips_cells_and_directions_without_a_stiffness():
    record = stiffness_record()
    record["stiffness_n_per_m"]["z"] = _grid(lambda *_: None)  # the tool never moves along z
    fig = dynamic_stiffness_map(record)
    assert fig is not None
    buttons = fig.layout.updatemenus[0].buttons
    assert [b.label for b in buttons] == ["k_x", "k_y"]
    traces = {t.name: t for t in fig.data}
    # the level pose once, then two tilted rings of three azimuths; x misses one cell
    assert len(traces["k_x, z = 500 mm"].r) == 7
    assert len(traces["k_x, z = 600 mm"].r) == 6
    assert len(traces["k_y, z = 600 mm"].r) == 7
    assert [t.visible for t in fig.data] == [t.name.startswith(("k_x", "least k_x"))
                                            for t in fig.data]
    assert list(buttons[1].args[0]["visible"]) == [t.name.startswith(("k_y", "least k_y"))
                                                 for t in fig.data]
    x = traces["k_x, z = 600 mm"]
    stored = record["stiffness_n_per_m"]["x"][1]
    for (height, tilt, azimuth, k, hz, mode), colour in zip(x.customdata, x.marker.color):
        r = TILTS[1].index(tilt)
        a = AZIMUTHS.index(azimuth)
        assert height == HEIGHTS[1] and k == pytest.approx(stored[r][a], rel=1e-6)
        assert hz == record["peak_hz"]["x"][1][r][a] and mode == record["mode"]["x"][1][r][a]
        assert colour == pytest.approx(math.log10(k), abs=1e-4)  # the colour: log10 (N/m)
    bar = traces["k_x, z = 500 mm"].marker  # one colour bar a direction, one scale
    assert bar.showscale and not x.marker.showscale and "N/m" in bar.colorbar.title.text
    assert (bar.cmin, bar.cmax) == (x.marker.cmin, x.marker.cmax)
    assert bar.cmin == pytest.approx(5.0, abs=1e-4)  # log10 of the least x, 1e5 N/m
    assert len(bar.colorbar.tickvals) == len(bar.colorbar.ticktext) >= 2
    star = traces["least k_x"]
    assert star.marker.symbol == "star" and list(star.r) == [0.0] and list(star.theta) == [0.0]
    assert star.subplot == traces["k_x, z = 500 mm"].subplot  # its layer's panel
    assert "least" in star.hovertemplate and "N/m" in star.hovertemplate
    assert traces["least k_y"].subplot == traces["k_y, z = 500 mm"].subplot


def test_stiffness_map_of_a_direction_on_some_layers_only():
    fig = dynamic_stiffness_map(stiffness_record())
    assert fig is not None
    names = [t.name for t in fig.data]
    assert "k_z, z = 600 mm" in names
    assert "k_z, z = 500 mm" in names  # a panel per layer, empty where nothing is stored
    empty = next(t for t in fig.data if t.name == "k_z, z = 500 mm")
    assert len(empty.r) == 0 and not empty.marker.showscale  # the bar on a drawn panel
    assert next(t for t in fig.data if t.name == "k_z, z = 600 mm").marker.showscale
    assert next(t for t in fig.data if t.name == "least k_z").subplot == next(
        t for t in fig.data if t.name == "k_z, z = 600 mm").subplot
    titles = fig.layout.updatemenus[0].buttons[2].args[1]
    assert titles["annotations[0].text"] == "z = 500 mm: –"


def test_stiffness_map_without_any_stiffness_is_none():
    record = stiffness_record()
    for d in "xyz":
        record["stiffness_n_per_m"][d] = _grid(lambda *_: None)
    assert dynamic_stiffness_map(record) is None


def test_tool_response_chart():
    record = tool_record()
    fig = tool_response(record, "tilted")
    assert fig is not None
    assert [a.text for a in fig.layout.annotations] == ["|H_xx|", "|H_yy|", "|H_zz|"]
    for axis in ("yaxis", "yaxis2", "yaxis3"):
        assert fig.layout[axis].type == "log"
    assert "m/N" in fig.layout.yaxis.title.text and "Hz" in fig.layout.xaxis.title.text
    lines = [t for t in fig.data if t.mode == "lines"]
    assert len(lines) == 6
    assert {t.name for t in lines} == {"analytical model", "FEM, modal sum"}
    x_analytical = next(t for t in lines if t.name == "analytical model" and t.xaxis == "x")
    assert list(x_analytical.y) == pytest.approx(record["curves"]["analytical_m_per_n"]["x"],
                                                 rel=1e-5)
    assert "m/N" in x_analytical.hovertemplate and "Hz" in x_analytical.hovertemplate
    peaks = [t for t in fig.data if t.mode == "markers"]
    assert [(t.xaxis, len(t.x)) for t in peaks] == [("x", 2), ("x3", 1)]  # none along y
    assert [t.showlegend for t in peaks] == [True, False]
    assert list(peaks[0].x) == [30.0, 80.0] and list(peaks[0].y) == [7e-6, 5e-8]
    for field in ("FEM mode", "direct response", "modal sum", "analytical", "m/N", "Hz", "%"):
        assert field in peaks[0].hovertemplate, field


def test_tool_response_without_curves_is_none():
    record = tool_record()
    record["curves"] = {"frequency_hz": [], "analytical_m_per_n": {}, "fem_m_per_n": {}}
    assert tool_response(record, "tilted") is None
