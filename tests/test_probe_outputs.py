"""The probe of issue 20, kept: one representative bad input of each class that could write
outside out/, feed the report doctored results, or put a cache where it was not asked.

Each test says what a user must find: exit status 2, one line on stderr naming what was typed
(or the file) and why, and nothing written anywhere (no out/, no cache, no file beside them).
The command lines run in-process, as in tests/test_cli.py.
"""
from __future__ import annotations

import copy
import json
import math
from dataclasses import replace
from pathlib import Path

import pytest

from common.paths import MAX_LENGTH, OutsideTree, UnsafeName, distinct_stems, file_stem, inside
from results import MAX_DEPTH, SCHEMA_VERSION
from results.tables import write_tables
from rps import app as cli
from studies import RECORDS
from tests.conftest import PAPER_SCENE, ROOT

# warnings of numpy or any library never reach the user raw: each is an error here
pytestmark = pytest.mark.filterwarnings("error")

RESULTS = ROOT / "tests" / "fixtures" / "report_results.json"


def everything_under(folder: Path) -> list[str]:
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*"))


def refused(capsys, code: int, *needles: str) -> str:
    """The one stderr line of a refusal (exit 2), holding every needle."""
    err = capsys.readouterr().err
    assert code == 2, err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), lines
    assert all(n in lines[0] for n in needles), lines[0]
    return lines[0]


# ---------------------------------------------------------------- case names from a scene
def scene_with_case(tmp_path: Path, *toml_keys: str) -> Path:
    """The paper's scene with its last case renamed to each of `toml_keys` (TOML quoted keys,
    escapes as typed in the file)."""
    text = PAPER_SCENE.read_text(encoding="utf-8")
    body = text.split("[cases.case2_literal]")[1]
    text = text.split("[cases.case2_literal]")[0]
    for key in toml_keys:
        text += f'[cases."{key}"]' + body
    path = tmp_path / "scene" / "scene.toml"
    path.parent.mkdir()
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("keys, shown, why", [
    (["../../escape"], "'../../escape'", "path separator"),
    (["/tmp/escape"], "'/tmp/escape'", "path separator"),
    (["a\\\\b"], "'a\\\\b'", "path separator"),
    (["nul\\u0000byte"], "'nul\\x00byte'", "U+0000"),
    (["CON"], "'CON'", "Windows reserves"),
    (["lpt1.txt"], "'lpt1.txt'", "Windows reserves"),
    ([".."], "'..'", "starts with a dot"),
    (["x" * (MAX_LENGTH + 1)], "'xxxx", f"more than {MAX_LENGTH}"),
    (["level pose", "level_pose"], "'level pose' and 'level_pose'", "rename one"),
    (["Tilted", "tilted"], "'Tilted' and 'tilted'", "rename one"),
], ids=["traversal", "absolute", "backslash", "nul", "reserved", "reserved-extension",
        "dot-dot", "too-long", "collision", "collision-by-case"])
def test_an_unsafe_case_name_is_refused_at_load_and_nothing_is_written(
        tmp_path, capsys, keys, shown, why):
    scene = scene_with_case(tmp_path, *keys)
    work = tmp_path / "work"
    work.mkdir()
    code = cli.main(["validate", "--scene", str(scene), "--out", str(work / "out"),
                     "--cache", str(work / "cache"), "--no-report"])
    refused(capsys, code, str(scene), shown, why)
    assert everything_under(tmp_path) == ["scene", "scene/scene.toml", "work"]


def test_harmless_characters_are_written_as_underscores(tmp_path):
    results = json.loads(RESULTS.read_text())
    results["cases"][0]["name"] = "niveau élevé: z 543"
    write_tables(results, tmp_path, RECORDS)
    written = [p for p in everything_under(tmp_path / "tables")
               if not p.startswith("studies")]  # the studies' tables are named by their keys
    assert {"niveau__lev___z_543.csv", "niveau__lev___z_543.md"} <= set(written)
    assert len(written) == 2 * len(results["cases"])
    assert file_stem("level pose") == "level_pose" and file_stem("café") == "caf_"


def test_a_writer_given_an_unsafe_name_refuses_it_before_writing(tmp_path):
    results = json.loads(RESULTS.read_text())
    results["cases"][0]["name"] = "../../escape"
    stage = tmp_path / "stage"
    stage.mkdir()
    with pytest.raises(UnsafeName, match="'../../escape' holds a path separator"):
        write_tables(results, stage, RECORDS)
    assert everything_under(tmp_path) == ["stage"]
    with pytest.raises(UnsafeName, match="'a b' and 'a_b'"):
        distinct_stems(["a b", "a_b"], "case name")


def test_every_write_is_checked_to_stay_inside_its_folder(tmp_path):
    stage = tmp_path / "stage"
    (stage / "tables").mkdir(parents=True)
    (stage / "linked").symlink_to(tmp_path)
    assert inside(stage, "tables", "case1.csv") == stage / "tables" / "case1.csv"
    for parts in (("..", "escape.csv"), ("/tmp/escape.csv",), ("tables", "..", "..", "x"),
                  ("linked", "escape.csv"), ()):
        with pytest.raises(OutsideTree):
            inside(stage, *parts)


# ---------------------------------------------------------------- results files, on read
def doctored(change) -> dict:
    results = copy.deepcopy(json.loads(RESULTS.read_text()))
    change(results)
    return results


def _set(path: str, value):
    def change(results):
        *keys, last = path.split("/")
        target = results
        for key in keys:
            target = target[int(key)] if isinstance(target, list) else target[key]
        target[int(last) if isinstance(target, list) else last] = value
    return change


BAD_RESULTS = {
    "negative FEM frequency": (doctored(_set("cases/0/fem/frequencies_hz/0", -114.6)),
                               "cases[0].fem.frequencies_hz[0]: input should be greater than 0"),
    "huge FEM frequency": (doctored(_set("cases/0/fem/frequencies_hz/5", 1e308)),
                           "cases[0].fem.frequencies_hz[5]: input should be less than or equal"),
    "unsorted analytical": (doctored(_set("cases/1/analytical/frequencies_hz/0", 1000.0)),
                            "cases[1].analytical.frequencies_hz: frequencies must ascend"),
    "NaN FEM frequency": (doctored(_set("cases/0/fem/frequencies_hz/2", math.nan)),
                          "cases[0].fem.frequencies_hz[2]: input should be a finite number"),
    "negative paired frequency": (doctored(_set("cases/0/pairs/0/f_fem_hz", -114.6)),
                                  "cases[0].pairs[0].f_fem_hz: input should be greater than 0"),
    "traversal case name": (doctored(_set("cases/0/name", "../../escape")),
                            "cases[0].name: case name holds a path separator"),
    "mode file outside": (doctored(_set("cases/0/fem/vtu", "../../elsewhere.vtu")),
                          "cases[0].fem.vtu: expected a path relative to the results file"),
    "two names, one file": (doctored(_set("cases/1/name", "Case1")),
                            "'case1' and 'Case1' would both be written as"),
    "deep nesting": ("[" * 100_000 + "]" * 100_000,
                     f"nested 100000 deep; a results file nests {MAX_DEPTH} at most"),
    "not JSON": ("results, but not JSON", "not valid JSON"),
    "not UTF-8": (b"\xff\xfe{}", "is not UTF-8 text"),
    "wrong schema version": ({"schema": SCHEMA_VERSION - 1, "cases": []},
                             f"results schema {SCHEMA_VERSION - 1}, this version reads"),
    "missing file": (None, "results file not found"),
}


def results_file(tmp_path: Path, content) -> Path:
    path = tmp_path / "in" / "results.json"
    path.parent.mkdir()
    if isinstance(content, bytes):
        path.write_bytes(content)
    elif isinstance(content, str):
        path.write_text(content)
    elif content is not None:
        path.write_text(json.dumps(content))
    return path


@pytest.mark.parametrize("label", list(BAD_RESULTS))
def test_python_m_reports_refuses_bad_results_in_one_line(tmp_path, capsys, label):
    from rps.app import main as rps_main

    def main(argv):
        return rps_main(["report", *argv])

    content, needle = BAD_RESULTS[label]
    path = results_file(tmp_path, content)
    before = everything_under(tmp_path)
    code = main(["--results", str(path), "--out", str(tmp_path / "out")])
    refused(capsys, code, str(path), needle)
    assert everything_under(tmp_path) == before  # no out/, no staging folder, no lock


@pytest.mark.parametrize("label", ["negative FEM frequency", "huge FEM frequency",
                                   "deep nesting", "missing file"])
def test_rps_readme_refuses_bad_results_and_leaves_the_readme(tmp_path, capsys, monkeypatch,
                                                               label):
    import reports.readme

    def must_not_write(*args):
        raise AssertionError("the README was updated from a bad results file")

    monkeypatch.setattr(reports.readme, "update_readme", must_not_write)
    content, needle = BAD_RESULTS[label]
    path = results_file(tmp_path, content)
    refused(capsys, cli.main(["readme", "--results", str(path)]), str(path), needle)


# ---------------------------------------------------------------- caches where they are asked
def test_joint_end_zones_land_under_the_cache_directory_of_the_run(tmp_path, monkeypatch,
                                                                    scene):
    import joint_ends.cache
    from analytical.model import natural_frequencies
    from solvers.compare import with_cache_dir

    default = tmp_path / "default-cache"  # where zones went whatever --cache said (issue 20)
    monkeypatch.setattr(joint_ends.cache, "cache_root", lambda: default)
    run_scene = with_cache_dir(scene, tmp_path / "cache")
    options = replace(run_scene.analytical, beam="timoshenko", joint_ends="solid",
                      end_zone=0.45)  # a zone of its own, built here whatever ran before
    natural_frequencies(scene.manipulator, scene.case("case1").pose, options)
    entries = everything_under(tmp_path / "cache")
    assert entries[0] == "joint_ends" and len(entries) == 3, entries  # one .json, one .npz
    assert not default.exists()
    assert options == replace(options, cache_dir=None)  # where it is stored changes nothing
