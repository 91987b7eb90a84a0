"""A test campaign's pages (reports/campaign_pages.py) from small hand-made dicts: the key
numbers printed, the unpaired test mode named, the unidentifiable parameter flagged and never
given as a confident number, no network reference (plotly.js inlined), a missing key refused
by name, the page written atomically."""
from __future__ import annotations

import copy
import json
import re

import pytest

from reports.campaign_charts import platform_ring
from reports.campaign_pages import (
    CampaignDataError,
    correlation_page,
    identification_page,
    write_page,
)
from results.campaign_records import SCHEMA


def pose(name: str, height: float, shift: float) -> dict:
    test = [41.25 + shift, 43.5 + shift, 77.75 + shift, 96.125 + shift]
    model = [40.5 + shift, 44.0 + shift, 79.0 + shift]
    joints = [[250.0, 0.0, height], [-125.0, 216.5, height], [-125.0, -216.5, height]]
    return {
        "name": name, "height_mm": height, "azimuth_deg": 25.0, "tilt_deg": 8.0,
        "source": "modes (UFF 55)", "data": f"{name}.unv", "test_hz": test,
        "test_damping_ratio": [0.012, 0.015, 0.018, 0.02],
        "model_hz": model,
        "mac": [[0.97, 0.02, 0.01], [0.03, 0.91, 0.05], [0.0, 0.1, 0.88], [0.1, 0.2, 0.3]],
        "pairs": [{"test_mode": k, "model_mode": k, "test_hz": test[k - 1],
                   "model_hz": model[k - 1], "mac": [0.97, 0.91, 0.88][k - 1],
                   "error_percent": 100 * (model[k - 1] / test[k - 1] - 1), "repeated": False}
                  for k in (1, 2, 3)],
        "unpaired_test_modes": [{"test_mode": 4, "test_hz": test[3],
                                 "reason": "no model mode with MAC >= 0.6"}],
        "unpaired_model_modes": [],
        "nodes": [{"id": 1, "xyz_mm": [0.0, 0.0, height], "body": "platform",
                   "distance_mm": 1.2, "directions": ["x", "y", "z"]},
                  {"id": 7, "xyz_mm": [120.0, 0.0, height / 2], "body": "leg 1",
                   "distance_mm": 0.4, "directions": ["z"]}],
        "machine": {"base_joints_mm": [[400.0, 0.0, 0.0], [-200.0, 346.4, 0.0],
                                       [-200.0, -346.4, 0.0]],
                    "platform_joints_mm": joints, "platform_centre_mm": [0.0, 0.0, height],
                    "platform_normal": [0.0, 0.0, 1.0], "platform_radius_mm": 250.0,
                    "leg_diameter_mm": 110.0}}


def correlation() -> dict:
    return {"record": "correlation", "schema": SCHEMA, "campaign": "campaigns/bench/campaign.toml",
            "scene": "scenes/actuator-legs.toml",
            "model": {"kind": "analytical", "description": "Timoshenko beams, s = 5"},
            "pairing": {"min_mac": 0.6, "max_frequency_ratio": 1.5,
                        "rule": "greatest MAC first"},
            "poses": [pose("mid", 640.0, 0.0), pose("high", 820.0, -3.0)],
            "summary": {"pairs": 6, "unpaired_test_modes": 2, "mean_abs_error_percent": 1.234,
                        "max_abs_error_percent": 2.468, "min_mac": 0.88}, "seconds": 0.5}


def identification() -> dict:
    fit = [{"pose": p, "modes": [
        {"test_mode": 1, "test_hz": 41.25, "before_hz": 43.1, "after_hz": 41.3,
         "error_before_percent": 4.48, "error_after_percent": 0.12, "mac_after": 0.97},
        {"test_mode": 2, "test_hz": 43.5, "before_hz": 46.2, "after_hz": 43.4,
         "error_before_percent": 6.21, "error_after_percent": -0.23, "mac_after": 0.92}]}
        for p in ("mid", "high")]
    return {"record": "identification", "schema": SCHEMA,
            "campaign": "campaigns/bench/campaign.toml",
            "scene": "scenes/actuator-legs.toml", "identified_scene": "identified.toml",
            "identified_scene_check": "accepted",
            "parameters": [
                {"key": "stiffness.actuator_axial_n_per_um", "unit": "N/um", "initial": 160.0,
                 "value": 131.2, "ci95": [120.1, 143.3], "bounds": [16.0, 1600.0],
                 "identifiable": True, "at_bound": False, "relative_std_percent": 4.1,
                 "reason": "well seen by modes 1 and 2"},
                {"key": "joints.base_rotational_n_m_per_rad", "unit": "N m/rad",
                 "initial": 5.0e4, "value": 987654.0, "ci95": [1.0, 9.9e9],
                 "bounds": [5.0e3, 5.0e6], "identifiable": False, "at_bound": False,
                 "relative_std_percent": 850.0, "reason": "no test mode is sensitive to it"}],
            "residual_rms_percent_before": 6.3, "residual_rms_percent_after": 0.8,
            "noise": {"frequency_percent": 0.8, "source": "residuals", "degrees_of_freedom": 2},
            "singular_values": [12.5, 0.003], "parameter_correlation": [[1.0, -0.2],
                                                                         [-0.2, 1.0]],
            "fit": fit, "evaluations": 14, "seconds": 2.3, "correlation_after": correlation(),
            "model": {"kind": "analytical", "description": "Timoshenko beams, s = 5"},
            "optimiser": "least squares (trust region)",
            "validation": [
                {"pose": "mid", "test_mode": 1, "model_mode": 1, "test_hz": 41.25,
                 "model_hz": 43.1, "e_percent": 4.48, "e_identified_percent": 0.12,
                 "u_num_percent": 0.01, "u_input_percent": 1.5, "u_d_percent": 0.8,
                 "u_val_percent": 1.7, "verdict": "the model's error matters: delta_model = "
                 "4.48 +- 3.4 % (E beyond 2 u_val)"},
                {"pose": "high", "test_mode": 2, "model_mode": 2, "test_hz": 43.5,
                 "model_hz": 46.2, "e_percent": 6.21, "e_identified_percent": -0.23,
                 "u_num_percent": 0.01, "u_input_percent": None, "u_d_percent": None,
                 "u_val_percent": 0.01, "verdict": "the model's error matters"}],
            "validation_note": "u_input: the scene's [uncertainty] through the fitted model"}


PLOTLY = re.compile(r"<script>.*?</script>", re.S)


def own_text(html: str) -> str:
    """The page without its inlined scripts (plotly.js names URLs of its own)."""
    return PLOTLY.sub("", html)


def chart_data(html: str) -> dict:
    block = re.search(r'<script type="application/json" id="rps-charts">(.*?)</script>', html,
                      re.S)
    assert block
    return json.loads(block.group(1))


def offline(html: str) -> None:
    assert not re.search(r"<script[^>]*\ssrc", html, re.I)
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:)?//""", own_text(html), re.I)
    assert "<link" not in own_text(html).lower()
    assert "http://" not in own_text(html) and "https://" not in own_text(html)
    assert html.count("<script>") == 2  # plotly.js, inlined once, and the drawer


@pytest.fixture(scope="module")
def correlation_html() -> str:
    return correlation_page(correlation())


@pytest.fixture(scope="module")
def identification_html() -> str:
    return identification_page(identification())


def test_the_correlation_page_holds_the_numbers(correlation_html):
    text = own_text(correlation_html)
    for s in ("campaigns/bench/campaign.toml", "scenes/actuator-legs.toml",
              "Timoshenko beams, s = 5", "Pose mid", "Pose high", "640.0 mm", "1.23", "2.47",
              "41.25", "40.50", "−", "0.970", "1.20", "96.12", "93.12"):
        assert s.replace("−", "-") in text, s
    assert "%+.2f" % (100 * (40.5 / 41.25 - 1)) in text  # the error of pair 1
    assert "Test mode 4 (96.12 Hz) unpaired: no model mode with MAC &gt;= 0.6" in text
    offline(correlation_html)


def test_a_pair_with_a_repeated_model_group_is_said():
    data = correlation()
    data["poses"][0]["pairs"][1]["repeated"] = True
    assert "paired, repeated group" in correlation_page(data)


def test_the_correlation_page_draws_mac_and_machine(correlation_html):
    charts = chart_data(correlation_html)
    assert set(charts) == {"mac:0", "machine:0", "mac:1", "machine:1"}
    mac = charts["mac:0"]["figure"]
    assert len(mac["layout"]["shapes"]) == 3  # the pairs outlined
    assert mac["data"][0]["z"][1][1] == pytest.approx(0.91)
    scene = charts["machine:0"]["figure"]["layout"]["scene"]
    assert scene["aspectmode"] == "data"
    names = {t.get("name") for t in charts["machine:0"]["figure"]["data"]}
    assert {"legs", "platform", "base joints", "nodes: platform", "nodes: leg 1"} <= names
    hover = " ".join(str(t.get("text")) for t in charts["machine:0"]["figure"]["data"])
    assert "node 7 on leg 1" in hover and "measured: z" in hover


def test_the_platform_is_a_circle_of_its_radius_in_its_plane():
    machine = pose("p", 500.0, 0.0)["machine"]
    machine["platform_normal"] = [0.0, 0.6, 0.8]
    ring = platform_ring(machine)
    d = ring - [0.0, 0.0, 500.0]
    assert (d ** 2).sum(axis=1) ** 0.5 == pytest.approx([250.0] * len(ring))
    assert d @ [0.0, 0.6, 0.8] == pytest.approx([0.0] * len(ring), abs=1e-9)


def test_the_identification_page_flags_the_unidentifiable_key(identification_html):
    text = own_text(identification_html)
    for s in ("131.2", "120.1 … 143.3", "16 … 1600", "6.30", "0.80", "identified.toml",
              "estimated from the fit&#39;s residuals", "+4.48", "-0.23", "Pose mid",
              "least squares (trust region)", "Model: analytical: Timoshenko beams"):
        assert s in text, s
    row = re.search(r'<tr class="unidentified">(.*?)</tr>', text, re.S)
    assert row and "joints.base_rotational_n_m_per_rad" in row.group(1)
    assert "NOT IDENTIFIED" in row.group(1) and ">NO<" in row.group(1)
    assert "not to be trusted" in row.group(1)
    assert "no test mode is sensitive to it" in row.group(1)
    # the value appears only inside the flagged, muted note
    assert re.search(r'<span class="muted">\(the fit ended at 9\.877e\+05', row.group(1))
    assert text.count("9.877e+05") == 1
    assert re.search(r'class="warning">Not identifiable[^<]*<code>joints\.base_rotational',
                     text)
    offline(identification_html)


def test_the_identification_page_draws_its_charts(identification_html):
    charts = chart_data(identification_html)
    assert {"singular", "parameter_correlation", "fit:0", "fit:1", "after-mac:0",
            "after-machine:1"} <= set(charts)
    assert charts["singular"]["figure"]["layout"]["yaxis"]["type"] == "log"
    heat = charts["parameter_correlation"]["figure"]["data"][0]
    assert (heat["zmin"], heat["zmax"]) == (-1, 1)
    bars = charts["fit:0"]["figure"]["data"]
    assert [b["name"] for b in bars] == ["before", "after"]
    assert "Correlation after the fit" in identification_html
    assert "V&amp;V 20" in identification_html and "E beyond 2 u_val" in identification_html


def test_a_missing_key_is_refused_by_name():
    data = correlation()
    del data["poses"][1]["machine"]["platform_normal"]
    with pytest.raises(KeyError, match=r"poses\[1\]\.machine\.platform_normal: field required"):
        correlation_page(data)
    data = identification()
    del data["parameters"][1]["identifiable"]
    with pytest.raises(CampaignDataError, match=r"parameters\[1\]\.identifiable: field required"):
        identification_page(data)
    data = identification()
    del data["correlation_after"]["summary"]
    with pytest.raises(KeyError, match=r"correlation_after\.summary: field required"):
        identification_page(data)
    data = correlation()
    data["schema"] = 99
    with pytest.raises(ValueError, match="schema 99"):
        correlation_page(data)


def test_nulls_and_empty_lists_are_drawn_as_dashes():
    data = correlation()
    p = data["poses"][0]
    p["test_damping_ratio"] = None
    p["mac"], p["nodes"], p["pairs"] = [], [], []
    p["unpaired_model_modes"] = [{"model_mode": 3, "model_hz": 79.0}]
    data["summary"].update(mean_abs_error_percent=None, min_mac=None)
    html = correlation_page(data)
    assert "Model mode 3 (79.00 Hz) unpaired" in html
    assert "mac:0" not in chart_data(html)
    ident = copy.deepcopy(identification())
    ident["singular_values"], ident["parameter_correlation"] = [], []
    assert "Singular values" not in own_text(identification_page(ident))


def test_write_page_is_atomic(tmp_path, correlation_html):
    target = tmp_path / "out" / "correlation.html"
    write_page(correlation_html, target)
    assert target.read_text(encoding="utf-8") == correlation_html
    assert [p.name for p in target.parent.iterdir()] == ["correlation.html"]
