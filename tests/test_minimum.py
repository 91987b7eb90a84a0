"""The least natural frequency over the reachable workspace (`analytical.minimum`).

A minimum search is proved by what it must not miss: on every shipped scene (both
architectures) and on random 3-PRS machines with inclined rails, the adaptive search's least
f1 is a reachable pose whose f1 is the model's there; it is never above the least value of a
dense map of the same workspace by more than 0.05 % (the dense map: the whole box on
13 x 36 x 6 points and its boundary face, where f1 is least, on 100 x 72); and no pose of a
fine map around it is lower by more than 0.05 % (it is converged where it stopped). The search
is often below the dense map: its least value sits where a second limit starts to bind on the
boundary, a corner a grid steps over.
"""
from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from analytical.minimum import grid_frequencies, workspace_minimum
from analytical.model import natural_frequencies
from analytical.params import ModelOptions
from analytical.reach import level_band, max_tilts
from analytical.reach import reachable as feasible
from scene import load_scene

SCENES = sorted((Path(__file__).resolve().parents[1] / "scenes").glob("*.toml"))
MODEL = ModelOptions(elements=1, modes=1)  # the search is under test, not the beam model
TOLERANCE = 5e-4


def dense_minimum(m, options, mode: int = 1) -> float:
    band = level_band(m)
    least = math.inf
    for nz, nphi, fractions in ((13, 36, np.linspace(0.0, 1.0, 6)),
                                (100, 72, np.array([1.0]))):
        heights = np.linspace(band.low, band.high, nz)
        phis = np.linspace(0.0, 2 * math.pi, nphi, endpoint=False)
        top = max_tilts(m, heights, phis, 1e-9)
        z, p, u = np.meshgrid(heights, phis, fractions, indexing="ij")
        hz = grid_frequencies(m, options, z, p, u * top[:, :, None])[..., mode - 1]
        least = min(least, float(np.nanmin(hz)))
    return least


def local_minimum(m, options, pose) -> float:
    """The least f1 of a fine map around `pose`: +-2 mm, +-2 degrees of azimuth, the tilt
    from 0.97 of the reachable one to all of it."""
    band = level_band(m)
    heights = np.clip(pose.height + np.linspace(-2e-3, 2e-3, 9), band.low, band.high)
    phis = pose.azimuth + np.radians(np.linspace(-2.0, 2.0, 9))
    top = max_tilts(m, heights, phis, 1e-10)
    z, p, u = np.meshgrid(heights, phis, np.linspace(0.97, 1.0, 7), indexing="ij")
    return float(np.nanmin(grid_frequencies(m, options, z, p, u * top[:, :, None])))


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_the_search_finds_the_least_f1_of_every_shipped_scene(path):
    m = load_scene(path).manipulator
    found = workspace_minimum(m, MODEL)
    assert feasible(m, found.pose)
    assert natural_frequencies(m, found.pose, MODEL)[0] == pytest.approx(found.frequency_hz,
                                                                          rel=1e-12)
    dense = dense_minimum(m, MODEL)
    assert found.frequency_hz <= dense * (1 + TOLERANCE), (found, dense)
    assert local_minimum(m, MODEL, found.pose) >= found.frequency_hz * (1 - TOLERANCE)


def test_a_higher_mode_and_the_scene_model():
    """f3 with the scene's own model: the same guarantees against the dense map of f3."""
    scene = load_scene(SCENES[0].parent / "paper.toml")
    options = replace(scene.analytical, modes=3)
    found = workspace_minimum(scene.manipulator, options, mode=3)
    assert found.mode == 3 and feasible(scene.manipulator, found.pose)
    hz = natural_frequencies(scene.manipulator, found.pose, options)
    assert hz[2] == pytest.approx(found.frequency_hz, rel=1e-12)
    dense = dense_minimum(scene.manipulator, options, mode=3)
    assert found.frequency_hz <= dense * (1 + TOLERANCE), (found, dense)


def test_random_3prs_machines_with_inclined_rails():
    from tests.test_prs import random_machines

    for m in random_machines(1, seed=7):
        found = workspace_minimum(m, MODEL)
        assert feasible(m, found.pose)
        assert found.frequency_hz <= dense_minimum(m, MODEL) * (1 + TOLERANCE)
        assert local_minimum(m, MODEL, found.pose) >= found.frequency_hz * (1 - TOLERANCE)
