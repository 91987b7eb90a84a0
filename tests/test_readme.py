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
