"""docs/scenes.md is generated from the declarations that validate scenes, and kept current."""
from __future__ import annotations

import tomllib

from common.settings import declared
from scene.docs import DOC, TABLES, render
from tests.conftest import PAPER_SCENE


def test_committed_scene_docs_are_current():
    assert DOC.read_text(encoding="utf-8") == render(), (
        "docs/scenes.md is stale: run `.venv/bin/python -m rps scene-docs`")


def test_every_key_of_the_paper_scene_is_documented():
    documented = {spec.scene_key(name) for _, _, classes in TABLES for cls in classes
                  for name, spec, _ in declared(cls) if spec.scene}
    raw = tomllib.loads(PAPER_SCENE.read_text(encoding="utf-8"))
    used = set()
    for key, value in raw.items():
        if key == "cases":
            for case in value.values():
                used |= set(case)
        elif key == "calibration":
            used |= set(value["height"])
        elif key == "uncertainty":  # its own keys, and each input's table under its address
            for name, item in value.items():
                used |= set(item) if isinstance(item, dict) else {name}
        elif isinstance(value, dict):
            used |= set(value)
        else:
            used.add(key)
    assert used <= documented, sorted(used - documented)


def test_committed_campaign_docs_are_current():
    from modaltest.docs import DOC as CAMPAIGN_DOC
    from modaltest.docs import render as render_campaigns
    assert CAMPAIGN_DOC.read_text(encoding="utf-8") == render_campaigns(), (
        "docs/campaigns.md is stale: run `.venv/bin/python -m rps scene-docs`")


def test_the_commands_are_listed_from_their_registry():
    """rps/README.md's table and `rps --help` name every registered command: a command is
    declared once, in its module."""
    from rps.app import build_parser
    from rps.commands import COMMANDS
    from rps.docs import README, current

    text = README.read_text(encoding="utf-8")
    assert text == current(text, COMMANDS), (
        "rps/README.md is stale: run `.venv/bin/python -m rps scene-docs`")
    described = build_parser().description.replace("\n", " ")
    for command in COMMANDS:
        assert f"`{command.name}`" in text and f" {command.name}" in described, command.name


def test_every_output_file_is_documented_from_its_declaration():
    """docs/outputs.md is generated from the declarations every command writes through
    (results.outputs, the bench's), so a user's script has a schema to rely on."""
    from results.outputs import OUTPUTS
    from rps.docs import OUTPUTS_DOC, outputs_markdown

    text = OUTPUTS_DOC.read_text(encoding="utf-8")
    assert text == outputs_markdown(), (
        "docs/outputs.md is stale: run `.venv/bin/python -m rps scene-docs`")
    for output in OUTPUTS:
        assert f"## `{output.file}`" in text
