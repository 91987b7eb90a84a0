"""The README's code blocks are run, not just read: its Python runs and prints what its comment
says, its scene loads and is reachable, every option of its command synopsis exists, and its
layout names every room of the project."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def blocks(language: str) -> list[str]:
    """The README's fenced blocks of one language ("" for a plain block), in order."""
    fenced = re.findall(r"^```(\w*)\n(.*?)^```$", README, re.S | re.M)
    return [text for lang, text in fenced if lang == language]


def test_the_python_blocks_run_and_print_what_their_comments_say():
    assert blocks("python")
    for code in blocks("python"):
        *body, last = code.strip().splitlines()
        expression, _, comment = last.partition("#")
        namespace: dict = {}
        exec("\n".join(body), namespace)
        value = np.asarray(eval(expression, namespace))
        stated = [float(x) for x in re.findall(r"\d+\.\d+", comment)]
        assert stated, f"no values stated in {last!r}"
        assert np.round(value[:len(stated)], 2).tolist() == stated, (last, value[:len(stated)])


def test_the_scene_blocks_load_and_are_reachable(tmp_path):
    from scene import load_scene
    from studies.reachable import check

    assert blocks("toml")
    for k, text in enumerate(blocks("toml")):
        path = tmp_path / f"readme_{k}.toml"
        path.write_text(text, encoding="utf-8")
        scene = load_scene(path)
        check(scene, "full")  # every case reachable, the studies' workspace not empty


def test_every_option_of_the_command_synopsis_exists():
    from rps.app import build_parser

    parser = build_parser()
    commands = parser._subparsers._group_actions[0].choices  # noqa: SLF001 - argparse
    synopsis = [b for b in blocks("sh") if b.lstrip().startswith("rps analytical")]
    assert synopsis
    for line in re.split(r"\n(?=rps )", synopsis[0]):
        name = line.split()[1]
        known = {o for a in commands[name]._actions for o in a.option_strings}  # noqa: SLF001
        typed = set(re.findall(r"(--[a-z-]+)", line))
        assert typed <= known, f"rps {name}: {sorted(typed - known)} not in its parser"


def test_the_layout_names_every_room():
    from tests.test_architecture import FLOORS

    layout = next(b for b in blocks("") if b.lstrip().startswith("common/"))
    listed = set(re.findall(r"^(\w+)/", layout, re.M))
    assert set(FLOORS) <= listed, set(FLOORS) - listed
    assert all((ROOT / name).is_dir() for name in listed), listed


@pytest.mark.parametrize("target", ["run", "test", "bench", "report", "readme", "clean-cache"])
def test_the_make_targets_the_readme_names_exist(target):
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    assert re.search(rf"^{re.escape(target)}:", makefile, re.M), target


def test_the_timings_block_is_rendered_from_the_recorded_timings():
    """The README's timings are what `make` and `make test` measured of themselves
    (docs/timings.json, written by `make readme-timings` from bench/timings.jsonl), rendered,
    never typed by hand."""
    import json

    from pipeline.make_timing import KINDS, README_END, README_START, RECORD_KEYS, render

    records = json.loads((ROOT / "docs" / "timings.json").read_text(encoding="utf-8"))
    assert set(records) <= set(KINDS)
    for record in records.values():
        assert set(record) == set(RECORD_KEYS)
        assert record["seconds"] > 0 and record["machine"]["cpu_count"] >= 1
        assert re.fullmatch(r"[0-9a-f]{40}", record["commit"])
    block = README.split(README_START, 1)[1].split(README_END, 1)[0]
    assert block == "\n" + render(records)


def test_make_records_its_own_timing_and_only_when_it_succeeds(tmp_path, monkeypatch):
    import json
    import time

    import pipeline.make_timing as timing

    monkeypatch.setattr(timing, "_cache_empty", lambda: True)
    (tmp_path / ".setup-begin").write_text(f"{time.time() - 42.0:.9f}")
    timing.setup_end(tmp_path)
    timing.begin(tmp_path, "make")
    entry = timing.end(tmp_path, "make")
    assert entry is not None and timing.kind(entry) == "fresh"
    assert 42.0 <= entry["setup_seconds"] < 60.0 and entry["seconds"] >= 0.0
    timing.begin(tmp_path, "test")  # a failed recipe never reaches `end`: nothing recorded
    lines = (tmp_path / timing.TIMINGS).read_text().splitlines()
    assert [json.loads(line)["target"] for line in lines] == ["make"]
    found = timing.newest(tmp_path / timing.TIMINGS, entry["machine"])
    assert set(found) == {"fresh"} and "fresh clone" in timing.render(found)
