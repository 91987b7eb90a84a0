"""The plain-language verdict is written from the numbers of results.json."""
from __future__ import annotations

import json
from pathlib import Path

from results.verdict import case_verdict, headline

RESULTS = json.loads((Path(__file__).resolve().parent / "fixtures" /
                      "report_results.json").read_text())


def test_verdict_quotes_the_worst_errors_and_the_fem_error():
    case = RESULTS["cases"][0]
    text = " ".join(case_verdict(case))
    low = max(abs(p["error_percent"]) for p in case["pairs"] if p["fem_mode"] <= 3)
    high = max(abs(p["error_percent"]) for p in case["pairs"] if p["fem_mode"] > 3)
    fem = max(case["fem_estimated_error_percent"])
    for value in (low, high, fem):
        assert f"{value:.2f} %" in text
    assert f"{min(p['mac'] for p in case['pairs']):.3f}" in text
    assert "paper's own theory-vs-ANSYS errors" in text


def test_verdict_without_refinement_or_paper_says_so():
    case = dict(RESULTS["cases"][0], fem_estimated_error_percent=None, paper=None)
    text = " ".join(case_verdict(case))
    assert "not estimated" in text and "paper" not in text


def test_verdict_grades_follow_the_numbers():
    case = json.loads(json.dumps(RESULTS["cases"][0]))
    for p in case["pairs"]:
        p["error_percent"] = -7.5 if p["fem_mode"] > 3 else 0.4
    text = " ".join(case_verdict(case))
    assert "agree closely" in text and "disagree, differing by up to 7.50 %" in text
    assert "Over case1" in headline(RESULTS)


def test_best_model_sentence_names_the_most_accurate_variant():
    from results.verdict import best_model
    pair = lambda mode, err: {"fem_mode": mode, "error_percent": 9.0,  # noqa: E731
                              "error_vs_reference_percent": err}
    case = {"models": {
        "coarse": {"pairs": [pair(1, 0.5), pair(4, 4.0)]},
        "fine": {"pairs": [pair(1, -0.6), pair(4, 0.2)]},
    }}
    assert best_model(case) == ("fine", 0.6, 0.2)
    assert best_model({"models": {}}) is None


def test_readme_block_quotes_the_workspace_p95_of_the_run_model():
    from reports.readme import README_END, README_START, readme_block

    block = readme_block(RESULTS)
    assert block.startswith(README_START) and block.endswith(README_END)
    wv = RESULTS["studies"]["workspace_validation"]
    default = wv["default_model"]
    p95_row = next(line for line in block.splitlines()
                   if line.startswith("|  | p95 |"))  # the first p95 row: the run's model
    assert p95_row.split("|")[3:-1] == [f" {v:.2f} " for v in wv["per_mode"][default]["p95"]]
    assert f"the run's model is {default}" in block
    assert f"{wv['worst_pose']['worst_error_percent']:.2f} %" in block


def test_readme_block_without_workspace_validation_has_no_workspace_table():
    from reports.readme import readme_block

    studies = dict(RESULTS["studies"], workspace_validation=None)
    assert "over the workspace" not in readme_block(dict(RESULTS, studies=studies))


def test_readme_block_quotes_each_coupling_and_each_models_worst_error():
    from reports.readme import readme_block

    block = readme_block(RESULTS).splitlines()
    for case in RESULTS["studies"]["joint_couplings"]:
        for reading in case["readings"]:
            row = next(line for line in block
                       if line.startswith(f"| {case['case']} | {reading['coupling']} |"))
            worst = [max(abs(e) for e in m["error_percent"])
                     for m in reading["models"].values()]
            assert row.split("|")[4:-1] == [f" {w:.3f} " for w in worst]
    assert readme_block(dict(RESULTS, studies=dict(RESULTS["studies"], joint_couplings=[]))
                        ).count("Joint faces rigid") == 0
