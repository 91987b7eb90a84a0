"""The compiled eigenvalue kernel (analytical/lanes.py) gives LAPACK's frequencies: 1e-9 on
every shipped scene and on random machines, repeated eigenvalues (level poses of a symmetric
machine) counted once per copy, batches of any length; without numba it says so in one line
and LAPACK solves."""
from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np
import pytest

from analytical.batch_model import CHUNK, assemble_batch
from analytical.batch_solve import FULL_LANE_BYTES, batch_frequencies, frequencies, standard_form
from analytical.kinematics import PoseError
from analytical.lanes import LANES
from analytical.modal import ModalError
from analytical.pose_batch import pose_batch
from analytical.reach import level_band
from common.stiffness import Stiffness
from scene import load_scene
from tests.conftest import ROOT

pytest.importorskip("numba")
SCENES = sorted((ROOT / "scenes").glob("*.toml"))
TOLERANCE = 1e-9


def poses_of(manipulator, count: int, seed: int):
    """Reachable poses: level ones (tilt 0: a symmetric machine's repeated modes) and random."""
    rng = np.random.default_rng(seed)
    band = level_band(manipulator)
    heights = rng.uniform(band.low, band.high, 4 * count)
    tilts = np.where(np.arange(4 * count) % 4 == 0, 0.0, rng.uniform(-0.3, 0.3, 4 * count))
    poses = pose_batch(manipulator, heights, rng.uniform(0, 2 * math.pi, 4 * count), tilts)
    return poses.take(np.flatnonzero(poses.feasible)[:count])


def both(manipulator, poses, options, count: int):
    """The kernel's frequencies (the whole solve on it, and its eigenvalues after LAPACK's
    standard form, which must agree) against LAPACK's."""
    model = assemble_batch(manipulator, poses, options)
    whole = frequencies(replace(model, stiffness=model.stiffness.copy(),
                                mass=model.mass.copy()), count)
    form = standard_form(model)
    lapack = batch_frequencies(form, count, kernel="lapack")
    lanes = batch_frequencies(form, count, kernel="lanes")
    assert np.abs(whole / lapack - 1).max() <= TOLERANCE
    return lanes, lapack


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_every_shipped_scene_gets_lapacks_frequencies(path):
    scene = load_scene(path)
    poses = poses_of(scene.manipulator, 70, seed=len(path.stem))  # one full group, one short
    assert len(poses) > CHUNK
    lanes, lapack = both(scene.manipulator, poses, scene.analytical, scene.analytical.modes)
    assert np.abs(lanes / lapack - 1).max() <= TOLERANCE


def test_the_best_model_and_every_eigenvalue():
    """The 126-coordinate model with solid joint ends, and every eigenvalue of a small one (the
    bisection's whole spectrum, the smallest at the end of its range)."""
    scene = load_scene(ROOT / "scenes" / "paper.toml")
    poses = poses_of(scene.manipulator, 9, seed=3)
    best = replace(scene.analytical, elements=5, beam="timoshenko", shear="hutchinson",
                   joint_ends="solid")
    lanes, lapack = both(scene.manipulator, poses, best, 6)
    assert np.abs(lanes / lapack - 1).max() <= TOLERANCE
    small = replace(scene.analytical, elements=1)
    lanes, lapack = both(scene.manipulator, poses, small, 18)
    assert np.abs(lanes / lapack - 1).max() <= TOLERANCE


def test_level_poses_of_a_symmetric_machine_keep_their_repeated_modes():
    scene = load_scene(ROOT / "scenes" / "paper.toml")
    band = level_band(scene.manipulator)
    poses = pose_batch(scene.manipulator, np.linspace(band.low, band.high, 5), 0.0, 0.0)
    lanes, lapack = both(scene.manipulator, poses, scene.analytical, 6)
    pairs = np.isclose(lapack[:, 1:], lapack[:, :-1], rtol=1e-9)
    assert pairs.any(axis=1).all()  # the level machine's twin modes are there, in LAPACK's
    assert np.abs(lanes / lapack - 1).max() <= TOLERANCE


def test_random_machines_get_lapacks_frequencies():
    """3-PRS machines of tests/test_prs.py (a drive spring on every other) and 3-RPS machines
    around the paper's with random radii, legs, joint springs and payloads."""
    from tests.test_prs import random_machines

    scene = load_scene(ROOT / "scenes" / "paper.toml")
    rng = np.random.default_rng(40)
    machines = list(random_machines(4, seed=40))
    machines += list(random_machines(2, seed=41, drive=False))
    paper = scene.manipulator
    for _ in range(6):
        machines.append(replace(
            paper, base_radius=paper.base_radius * rng.uniform(0.8, 1.3),
            platform_radius=paper.platform_radius * rng.uniform(0.7, 1.1),
            leg_diameter=paper.leg_diameter * rng.uniform(0.6, 1.6),
            stiffness=Stiffness(actuator_axial=rng.choice([0.0, rng.uniform(5e7, 5e8)]),
                                base_joint_translational=rng.choice([0.0, 3e8]),
                                platform_joint_rotational=rng.choice([0.0, 2e6]))))
    checked = 0
    for m in machines:
        try:
            poses = poses_of(m, 20, seed=checked)
        except PoseError:
            continue
        if len(poses) == 0:
            continue
        lanes, lapack = both(m, poses, scene.analytical, 6)
        assert np.abs(lanes / lapack - 1).max() <= TOLERANCE
        checked += 1
    assert checked >= 8


def test_without_numba_one_line_says_so_and_lapack_solves(monkeypatch):
    import builtins

    scene = load_scene(ROOT / "scenes" / "paper.toml")
    poses = poses_of(scene.manipulator, 5, seed=1)
    form = standard_form(assemble_batch(scene.manipulator, poses, scene.analytical))
    expected = batch_frequencies(form, 6, kernel="lapack")
    real_import = builtins.__import__

    def no_kernels(name, globals=None, locals=None, fromlist=(), level=0):
        if "lane_kernels" in name or "lane_kernels" in (fromlist or ()):
            raise ImportError("No module named 'numba'", name="numba")
        return real_import(name, globals, locals, fromlist, level)

    monkeypatch.setattr(builtins, "__import__", no_kernels)
    from analytical.lanes import KernelFallback

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        got = batch_frequencies(form, 6)
    said = [w for w in caught if issubclass(w.category, KernelFallback)]
    assert len(said) == 1 and "\n" not in str(said[0].message)
    assert "numba" in str(said[0].message) and "LAPACK" in str(said[0].message)
    assert np.array_equal(got, expected)


def test_the_whole_solve_on_the_kernel_is_taken_where_it_fits_and_finds_a_mechanism():
    """The paper's scene (54 coordinates) is solved wholly on the kernel, leaving K and M as
    they were; a pose whose stiffness is not positive definite is named as LAPACK names it."""
    scene = load_scene(ROOT / "scenes" / "paper.toml")
    n = 18 * scene.analytical.elements
    assert 2 * n * n * LANES * 8 <= FULL_LANE_BYTES
    model = assemble_batch(scene.manipulator, poses_of(scene.manipulator, 70, seed=2),
                           scene.analytical)
    before = model.stiffness.copy(), model.mass.copy()
    frequencies(model, 6)
    assert np.array_equal(model.stiffness, before[0]) and np.array_equal(model.mass, before[1])
    model.stiffness[66] = -np.eye(n)  # in the short last group
    with pytest.raises(ModalError, match="pose 66: the stiffness matrix is not positive "
                                         "definite: the structure is a mechanism"):
        frequencies(model, 6)
    copy = replace(model, stiffness=model.stiffness.copy(), mass=model.mass.copy())
    with pytest.raises(ModalError, match="pose 66: the stiffness matrix is not positive"):
        batch_frequencies(standard_form(copy), 6, kernel="lapack")
