"""A scene file: a machine, its poses and the fidelity it asks for, read once into SI.

    from scene import load_scene
    s = load_scene("scenes/paper.toml")   # SceneError (one line) on bad input

`load` parses and checks every key through its declaration (common.settings), `docs` writes
docs/scenes.md from the same declarations, `fidelity` declares the [fidelity] table. This room
stands apart from the run: it imports the models' option declarations (analytical, fem_reference,
meshing) and `common`, never the studies, the run or the reports.
"""
from __future__ import annotations

from .cases import CaseSettings, HeightCalibration
from .fidelity import FidelitySettings
from .load import (
                   Case,
                   FemStudy,
                   Scene,
                   SceneError,
                   load_scene,
                   parse_scene,
)

__all__ = ["Case", "CaseSettings", "FemStudy", "FidelitySettings", "HeightCalibration", "Scene",
           "SceneError", "load_scene", "parse_scene"]
