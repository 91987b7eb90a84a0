"""Shared fixtures: the paper's scene and its two cases."""
from __future__ import annotations

from pathlib import Path

import pytest

from scene import load_scene

ROOT = Path(__file__).resolve().parents[1]
PAPER_SCENE = ROOT / "scenes" / "paper.toml"


@pytest.fixture(scope="session")
def scene():
    return load_scene(PAPER_SCENE)


@pytest.fixture(scope="session")
def manipulator(scene):
    return scene.manipulator
