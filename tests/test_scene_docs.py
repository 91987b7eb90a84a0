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
