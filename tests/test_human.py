"""What people read in the terminal: numbers rounded by what they measure, and the summary
table at the end of a validation run, computed from the results it summarises."""
from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

from rps.human import case_summary, number, payload_lines, significant, summary

FIXTURE = Path(__file__).resolve().parent / "fixtures" / "report_results.json"


@pytest.fixture(scope="module")
def results():
    return json.loads(FIXTURE.read_text(encoding="utf-8"))


@pytest.mark.parametrize("key, value, text", [
    ("frequencies_hz", 194.98765432101234, "194.99"),
    ("height_mm", 543.599999999, "543.60"),
    ("tilt_deg", -11.999999999, "-12.00"),
    ("estimated_error_percent", 0.021345678, "0.0213"),
    ("estimated_error_percent", 4.1934, "4.19"),
    ("seconds", 0.0022412345, "0.00224"),
    ("timings.solve", 12.3456, "12.3"),
    ("mesh_size_m", 0.04, "0.04"),
    ("observed_order", 1.87654321, "1.877"),
    ("dofs", 13212, "13212"),
    ("model", "fem", "fem"),
])
def test_numbers_are_rounded_by_their_unit(key, value, text):
    assert number(key, value) == text


def test_significant_figures_never_use_an_exponent():
    assert significant(0.000123456) == "0.000123"
    assert significant(123456.7) == "123457"


def test_payload_lines_flatten_and_round():
    lines = payload_lines({"case": "case1", "pose": {"height_mm": 543.6000001},
                           "frequencies_hz": [114.729409, 194.98765]})
    assert lines == ["          case: case1", "pose.height_mm: 543.60",
                     "frequencies_hz: 114.73, 194.99"]


def test_a_case_row_takes_the_worst_error_of_each_mode_range(results):
    case = results["cases"][0]
    row = case_summary(case)
    low = max(abs(p["error_percent"]) for p in case["pairs"] if p["fem_mode"] <= 3)
    high = max(abs(p["error_percent"]) for p in case["pairs"] if p["fem_mode"] > 3)
    assert (row["low_percent"], row["high_percent"]) == (low, high)
    assert row["fem_error_percent"] == max(case["fem_estimated_error_percent"])
    assert row["lowest_mac"] == min(p["mac"] for p in case["pairs"])
    assert (row["low_range"], row["high_range"]) == ("f1–f3", "f4–f6")


def test_the_verdict_follows_the_worst_error(results):
    case = copy.deepcopy(results["cases"][0])
    for p in case["pairs"]:
        p["error_percent"] = 0.5 * p["error_percent"] / max(
            abs(q["error_percent"]) for q in results["cases"][0]["pairs"])
    assert case_summary(case)["verdict"] == "agree closely"  # worst 0.5 %
    case["pairs"][-1]["error_percent"] = -12.0
    assert case_summary(case)["verdict"] == "disagree"


def test_summary_names_every_case_and_where_the_outputs_are(results, tmp_path):
    text = summary(results, tmp_path, report=True)
    for case in results["cases"]:
        row = case_summary(case)
        line = next(x for x in text.splitlines() if x.startswith(case["name"] + " "))
        assert f"{significant(row['low_percent'])} %" in line
        assert f"{significant(row['fem_error_percent'])} %" in line
        assert row["verdict"] in line
    assert str(tmp_path.resolve() / "report.html") in text
    assert str(tmp_path.resolve() / "results.json") in text


def test_summary_of_a_ci_run_says_the_fem_error_is_not_estimated(results, tmp_path):
    ci = copy.deepcopy(results)
    for case in ci["cases"]:
        case["fem_estimated_error_percent"] = None
    text = summary(ci, tmp_path, report=False)
    assert "no refinement study" in text and "report.html" not in text
