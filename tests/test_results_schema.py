"""The results schema (results/schema.py): what the pipeline writes is what the reports read;
a file of another schema version, a wrong type or an unknown field is refused in one line."""
from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest

import results as schema
from studies import RECORDS

FIXTURE = Path(__file__).resolve().parent / "fixtures" / "report_results.json"


@pytest.fixture(scope="module")
def written():
    return json.loads(FIXTURE.read_text())


def test_the_fixture_is_a_results_file_of_this_schema(written):
    checked = schema.validated(written, RECORDS)
    assert checked["schema"] == schema.SCHEMA_VERSION
    assert json.loads(schema.dumps(checked)) == written  # nothing added, nothing lost


def test_an_older_results_file_names_its_version_and_the_remedy(written):
    old = dict(written, schema=1)
    with pytest.raises(ValueError) as info:
        schema.validated(old, RECORDS, "out/results.json")
    text = str(info.value)
    assert text.startswith("out/results.json: results schema 1") and "rerun `make`" in text
    assert "\n" not in text


def test_a_value_the_writer_gets_wrong_is_caught_before_writing(written):
    bad = copy.deepcopy(written)
    bad["cases"][0]["fem"]["dofs"] = np.int64(5)  # not a JSON integer
    with pytest.raises(ValueError, match=r"cases\[0\]\.fem\.dofs: input should be a valid "
                                         r"integer"):
        schema.validated(bad, RECORDS)
    bad = copy.deepcopy(written)
    bad["cases"][0]["pairs"][0]["mac"] = float("nan")
    with pytest.raises(ValueError, match=r"cases\[0\]\.pairs\[0\]\.mac: input should be a "
                                         r"finite number"):
        schema.validated(bad, RECORDS)


def test_platform_motion_of_both_models_is_six_rows_per_reported_mode(written):
    for case in written["cases"]:
        modes = len(case["fem"]["frequencies_hz"])
        for model in ("analytical", "fem"):
            motion = np.asarray(case[model]["platform_motion"])
            assert motion.shape == (6, modes)


def _pair(mode, error, vs_limit=None):
    return {"fem_mode": mode, "error_percent": error, "error_vs_reference_percent": vs_limit}


def test_errors_are_read_in_two_mode_ranges_against_the_best_reference():
    pairs = [_pair(1, -0.5, -0.6), _pair(3, 0.9, 1.0), _pair(4, 4.0, 4.1), _pair(6, -4.5, -4.4)]
    assert schema.worst_by_mode_range(pairs) == (1.0, 4.4)  # vs the h -> 0 limit
    assert schema.worst_by_mode_range([_pair(1, -0.5), _pair(2, 0.2)]) == (0.5, None)
    assert schema.mode_ranges(pairs) == ("f1–f3", "f4–f6")


def test_an_output_s_declared_table_is_one_row_per_item_with_its_parent_s_fields():
    """results.outputs.Rows: "*" walks every item of a list, "../" reaches the object that
    encloses it, an index reaches into a list; rows in the file's order."""
    from results.outputs import Rows

    data = {"poses": [{"name": "low", "pairs": [{"f": 1.0, "ci": [0.9, 1.1]},
                                                 {"f": 2.0, "ci": [1.8, 2.2]}]},
                      {"name": "high", "pairs": []},
                      {"name": "mid", "pairs": [{"f": 3.0, "ci": [2.7, 3.3]}]}]}
    table = Rows("pairs", "poses/*/pairs/*", (("pose", "../name"), ("f_hz", "f"),
                                              ("low", "ci/0")))
    assert table.rows(data) == [{"pose": "low", "f_hz": 1.0, "low": 0.9},
                                {"pose": "low", "f_hz": 2.0, "low": 1.8},
                                {"pose": "mid", "f_hz": 3.0, "low": 2.7}]
