"""The static figures of the studies report.pdf used to show as tables only
(reports/study_figures.py, reports/study_maps.py): each drawn from a small synthetic record,
and `make_figures` listing them by section anchor with their captions and chart keys."""
from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest

from reports import cut_figures, figure_set, study_figures, study_maps
from reports.interactive import chart_key
from results import validated
from studies import RECORDS
from tests.test_report_frf import stiffness_record, tool_record

FIXTURE = Path(__file__).resolve().parent / "fixtures" / "report_results.json"
HEIGHTS, TILTS, AZIMUTHS = [500.0, 600.0], [[0.0, 5.0, 10.0], [0.0, 4.0, 8.0]], [0.0, 120.0, 240.0]


@pytest.fixture(scope="module")
def raw() -> dict:
    return json.loads(FIXTURE.read_text(encoding="utf-8"))


def _png(path: Path) -> None:
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", path


def _curve(model: str, scale: float, rpm: np.ndarray) -> dict:
    depth = scale * (1.0 + 0.5 * np.sin(rpm / 700.0) ** 2)
    kind = ["flip" if i % 7 == 0 else "hopf" for i in range(len(rpm))]
    return {"model": model, "critical_depth_mm": [None] + depth[1:].tolist(),
            "chatter_frequency_hz": [None] + [300.0] * (len(rpm) - 1),
            "kind": [None] + kind[1:], "max_error_percent": 0.5}


def _summary(model: str, depth: float | None) -> dict:
    return {"model": model, "least_depth_mm": depth, "least_rpm": 3000.0, "kind": "hopf",
            "chatter_frequency_hz": 300.0, "best_rpm": 9000.0, "best_depth_mm": 3.0,
            "error_percent": None, "fem_error_percent": None}


def lobes_record(band: bool = True) -> dict:
    rpm = np.linspace(2000.0, 12000.0, 40)
    thin = rpm[::4]
    record = {
        "method": "sdm", "spindle_rpm": rpm.tolist(),
        "analytical": _curve("analytical (euler-bernoulli, s = 3)", 1.0, rpm),
        "fem": _curve("FEM (35.2 mm)", 1.05, rpm), "fem_coarse": _curve("FEM (44 mm)", 1.1, rpm),
        "fem_mesh_size_mm": 35.2, "coarse_mesh_size_mm": 44.0,
        "error_percent": [None] + [-4.8] * 39, "fem_error_percent": [None] + [4.5] * 39,
        "median_error_percent": -4.8, "max_error_percent": 4.8,
        "summary": [_summary("analytical", 1.0), _summary("FEM", 1.05)], "band": None,
        "seconds": 1.0}
    if band:
        record["band"] = {
            "samples": 256, "model": "euler-bernoulli, s = 3",
            "inputs": ["material.youngs_modulus_gpa"], "spindle_rpm": thin.tolist(),
            "nominal_depth_mm": [1.2] * len(thin), "q025_depth_mm": [0.9] * len(thin),
            "median_depth_mm": [1.2] * len(thin),
            "q975_depth_mm": [1.6] * (len(thin) - 1) + [None],
            "least_nominal_mm": 1.0, "least_q025_mm": 0.8, "least_q025_interval_mm": [0.7, 0.85],
            "least_median_mm": 1.0, "least_q975_mm": 1.2, "level_error_percent": 0.3,
            "refused": None, "seconds": 3.0}
    return record


def stability_record(layers: int = 2) -> dict:
    heights = [450.0 + 50 * i for i in range(layers)]
    tilts = [[0.0, 5.0, 10.0] for _ in range(layers)]

    def grid(value):
        return [[[None if (iz, r, a) == (0, 2, 1) else value(iz, r, a) for a in range(3)]
                 for r in range(3)] for iz in range(layers)]
    return {"point_mm": [0.0, 0.0, -150.0], "method": "sdm",
            "analytical": "euler-bernoulli, s = 3", "damping": "modal ratio 0.03",
            "speeds": 60, "spindle_rpm_range": [2000.0, 12000.0], "heights_mm": heights,
            "tilts_deg": tilts, "azimuths_deg": AZIMUTHS,
            "least_depth_mm": grid(lambda iz, r, a: 1.0 + 0.1 * iz + 0.05 * r + 0.01 * a),
            "least_rpm": grid(lambda iz, r, a: 3000.0),
            "best_rpm": grid(lambda iz, r, a: 9000.0),
            "best_depth_mm": grid(lambda iz, r, a: 3.0),
            "chatter_frequency_hz": grid(lambda iz, r, a: 300.0), "max_error_percent": 0.5,
            "least": [{"depth_mm": 1.0, "spindle_rpm": 3000.0, "chatter_frequency_hz": 300.0,
                       "kind": "hopf", "height_mm": heights[-1], "tilt_deg": 0.0,
                       "azimuth_deg": 0.0}],
            "poses": 9 * layers, "estimated_seconds": 1.0, "seconds": 1.0}


def test_sobol_bars_mark_an_index_below_its_error(raw, tmp_path):
    spread = copy.deepcopy(raw["cases"][0]["uncertainty"])
    spread["sobol"][1]["total_error"] = 2 * spread["sobol"][1]["total"]  # not resolved
    spread["sobol"][2]["first_error"] = 2 * abs(spread["sobol"][2]["first"])
    spread["sobol"][3].update(first=None, first_error=None, total=None, total_error=None)
    assert study_figures.has_sobol(spread)
    study_figures.sobol_bars(spread, tmp_path / "sobol.png")
    _png(tmp_path / "sobol.png")
    assert "hatched grey" in study_figures.sobol_caption(raw["cases"][0], spread)


def test_sobol_bars_without_indices_refuse(raw, tmp_path):
    spread = dict(raw["cases"][0]["uncertainty"], sobol=[])
    assert not study_figures.has_sobol(spread)
    with pytest.raises(ValueError):
        study_figures.sobol_bars(spread, tmp_path / "none.png")


@pytest.mark.parametrize("keep", ["both", "validation", "modes"])
def test_validation_and_spread(raw, tmp_path, keep):
    spread = copy.deepcopy(raw["cases"][0]["uncertainty"])
    if keep == "validation":
        spread["modes"] = []
    elif keep == "modes":
        spread["validation"] = []
    study_figures.validation_spread(spread, tmp_path / "vv.png")
    _png(tmp_path / "vv.png")
    caption = study_figures.validation_caption(raw["cases"][0], spread)
    assert ("V&V 20" in caption) == (keep != "modes")


def test_path_band_with_and_without_stiffness(raw, tmp_path):
    path = copy.deepcopy(raw["studies"]["uncertainty_path"])
    study_figures.path_band(path, tmp_path / "path.png")
    _png(tmp_path / "path.png")
    assert "stiffness" not in study_figures.path_caption(path)
    for p in path["poses"]:
        p.update(least_nominal_n_per_m=2e5, least_q025_n_per_m=1.8e5,
                 least_median_n_per_m=2e5, least_q975_n_per_m=2.2e5)
    study_figures.path_band(path, tmp_path / "path_k.png")
    _png(tmp_path / "path_k.png")
    assert "least dynamic stiffness" in study_figures.path_caption(path)


def test_dynamic_stiffness_map_draws_each_direction_at_its_least(tmp_path):
    ds = stiffness_record()
    # x and y least on the lower layer, z (only on the upper layer) there
    assert study_maps.stiffness_panels(ds) == [("x", 0), ("y", 0), ("z", 1)]
    study_maps.dynamic_stiffness_map(ds, tmp_path / "k.png")
    _png(tmp_path / "k.png")
    assert "along z at z = 600 mm" in study_maps.stiffness_caption(ds)


def test_tool_response(tmp_path):
    cut_figures.tool_response(tool_record(), tmp_path / "tool.png")
    _png(tmp_path / "tool.png")
    empty = tool_record()
    empty["curves"] = {"frequency_hz": [], "analytical_m_per_n": {}, "fem_m_per_n": {}}
    assert cut_figures.tool_directions(empty) == []


@pytest.mark.parametrize("band", [True, False])
def test_lobes_with_and_without_the_band(tmp_path, band):
    record = lobes_record(band)
    cut_figures.case_lobes(record, tmp_path / "lobes.png")
    _png(tmp_path / "lobes.png")
    assert ("Shaded" in cut_figures.lobes_caption({"name": "c", "description": "C"}, record)
            ) == band


def test_stability_map_picks_at_most_four_layers_with_the_least(tmp_path):
    sm = stability_record(layers=7)
    layers = study_maps.stability_layers(sm)
    assert len(layers) == 4 and 6 in layers and 0 in layers
    study_maps.stability_map(sm, tmp_path / "sm.png")
    _png(tmp_path / "sm.png")
    assert "4 of the 7 heights" in study_maps.stability_caption(sm)
    assert study_maps.stability_layers(stability_record(layers=2)) == [0, 1]


def test_make_figures_lists_the_study_figures_by_section(raw, tmp_path, monkeypatch):
    doc = copy.deepcopy(raw)
    doc["studies"]["dynamic_stiffness"] = stiffness_record()
    doc["studies"]["stability_map"] = stability_record()
    for i, case in enumerate(doc["cases"]):
        case["tool_response"] = tool_record() if i == 0 else None
        case["lobes"] = lobes_record(band=i == 1) if i < 2 else None
    results = validated(doc, RECORDS, "test results")
    monkeypatch.setattr(figure_set, "mode_figures", lambda *args: {"pairs": [], "fem_note": None})

    def broken(record, path):
        raise ValueError("cannot draw this")
    monkeypatch.setattr(cut_figures, "tool_response", broken)  # a failure is a note
    fig_dir = tmp_path / "figures"
    fig_dir.mkdir()
    figs = figure_set.make_figures(results, tmp_path / "results.json", fig_dir)
    studies = figs["studies"]
    assert list(studies) == ["uncertainty", "uncertainty-path", "dynamic-stiffness", "lobes",
                             "stability-map"]  # tool-response: its only figure failed
    assert any("tool response: cannot draw this" in n for n in figs["notes"])
    names = [c["name"] for c in results["cases"]]
    main = [c["name"] for c in results["cases"] if c["paper"]] or names  # the main cases'
    assert [e["chart"] for e in studies["uncertainty"]] == [
        x for n in main for x in (chart_key("uncertainty", n), None)]
    assert [e["chart"] for e in studies["lobes"]] == [chart_key("lobes", n) for n in names[:2]]
    assert studies["stability-map"][0]["chart"] == chart_key("stability_map")
    assert studies["dynamic-stiffness"][0]["chart"] == chart_key("dynamic_stiffness")
    assert studies["uncertainty-path"][0]["chart"] == chart_key("uncertainty_path")
    for entries in studies.values():
        for e in entries:
            _png(e["src"])
            assert e["src"].parent == fig_dir
            assert e["caption"].endswith(".") and "(" in e["caption"]
