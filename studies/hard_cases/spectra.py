"""Hard cases: repeated eigenvalues and checked eigen-solutions."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from analytical.batch_model import assemble_batch
from analytical.batch_solve import frequencies
from analytical.kinematics import PoseError, pose_geometry
from analytical.model import analyse, natural_frequencies
from analytical.params import Pose
from analytical.pose_batch import pose_batch
from analytical.reach import layer_heights, sample_poses
from common.modes import clusters
from scene import Scene

from .base import SEED, Row, bare, checked_residuals, random_rotation, turned

# --- repeated eigenvalues --------------------------------------------------------------------

def repeated_pairs(scene: Scene, runs: int = 1000, modes: int = 8) -> Row:
    """Level poses have the mechanism's three-fold symmetry, so their modes come in exactly
    repeated pairs. Over `runs` random layout turns, heights and rigid rotations of the whole
    machine, every pair of the unturned machine stays repeated (relative split below 1e-9) and
    every frequency stays the unturned machine's (to 1e-9)."""
    m, opts = bare(scene.manipulator), replace(scene.analytical, modes=modes)
    rng = np.random.default_rng(SEED)
    heights = layer_heights(m, 2)
    worst = 0.0
    for _ in range(runs):
        z = float(rng.uniform(*heights))
        reference = natural_frequencies(m, Pose(z), opts)
        groups = [g for g in clusters(reference, 1e-6) if len(g) > 1 and g[-1] < modes - 1]
        machine = turned(m, float(rng.uniform(0, 2 * math.pi)))
        geometry = pose_geometry(machine, Pose(z)).transformed(random_rotation(rng),
                                                               rng.standard_normal(3))
        f = analyse(machine, Pose(z), opts, geometry=geometry).frequencies_hz
        split = max((f[g[-1]] / f[g[0]] - 1 for g in groups), default=0.0)
        worst = max(worst, split, float(np.max(np.abs(f / reference - 1))))
    return Row("repeated pairs, 1,000 random symmetric poses",
               "every repeated pair of a level pose stays repeated and every frequency stays "
               "put under layout turns, heights and rigid rotations", 1e-9, worst, "relative")


def turned_layout(scene: Scene, poses: int = 300) -> Row:
    """A layout turned by gamma, posed at azimuth phi + gamma, is the same machine turned:
    its frequencies equal the unturned ones at phi (to 1e-9), at random tilted poses."""
    m, opts = bare(scene.manipulator), scene.analytical
    rng = np.random.default_rng(SEED + 1)
    worst = 0.0
    for pose in sample_poses(m, poses, rng):
        gamma = float(rng.uniform(0, 2 * math.pi))
        f = natural_frequencies(turned(m, gamma),
                                Pose(pose.height, pose.azimuth + gamma, pose.tilt), opts)
        worst = max(worst, float(np.max(np.abs(f / natural_frequencies(m, pose, opts) - 1))))
    return Row("leg layout turned", "frequencies of a turned layout equal the unturned ones at "
               "the turned azimuth (300 random poses)", 1e-9, worst, "relative")


# --- eigen-solutions checked ----------------------------------------------------------------

def eigen_residuals(scene: Scene, elements=(1, 2, 3, 5, 10)) -> Row:
    """Every eigenpair the analytical model returns satisfies K x = omega^2 M x to a relative
    residual |K x - omega^2 M x| / |K x| below 1e-8, over the scene's cases, s = 1..10 and
    both beam theories (M-orthonormality is checked by solve_modes to 1e-6 and measured in
    the test to 1e-10)."""
    worst = 0.0
    for case in scene.cases.values():
        for s in elements:
            for beam in ("euler-bernoulli", "timoshenko"):
                opts = replace(scene.analytical, elements=s, beam=beam,
                               modes=min(12, 18 * s))
                try:
                    modal = analyse(scene.manipulator, case.pose, opts).modal
                except PoseError:
                    continue
                worst = max(worst, float(checked_residuals(modal).max()))
    return Row("eigen-solutions checked", "relative residual of every analytical eigenpair "
               "(scene cases, s = 1..10, both beam theories)", 1e-8, worst, "relative")


def mode_count(scene: Scene) -> Row:
    """Asking for n modes returns exactly n, for every n from 1 to the 18 s coordinates."""
    case = next(iter(scene.cases.values()))
    s = scene.analytical.elements
    wrong = sum(len(natural_frequencies(scene.manipulator, case.pose,
                                        replace(scene.analytical, modes=n))) != n
                for n in range(1, 18 * s + 1))
    return Row("mode count", "modes returned minus modes asked, every n = 1..18 s", 0.0,
               float(wrong), "modes")


def no_spurious_zero_mode(scene: Scene, poses: int = 2000) -> Row:
    """No mode collapses towards zero anywhere in the workspace: at random reachable poses the
    lowest frequency stays above a third of the level pose's at the same height (a spurious
    mechanism or a lost constraint would send it to zero). Measured as the worst shortfall
    below 1/3 (0 when it holds)."""
    m, opts = scene.manipulator, replace(scene.analytical, modes=1)
    sample = sample_poses(m, poses, np.random.default_rng(SEED + 2))
    z = np.array([p.height for p in sample])

    def f1(azimuths, tilts):
        batch = pose_batch(m, z, azimuths, tilts)
        return frequencies(assemble_batch(m, batch, opts), 1)[:, 0]

    ratio = f1([p.azimuth for p in sample], [p.tilt for p in sample]) / f1(0.0, 0.0)
    lowest = float(ratio.min())
    return Row("no spurious near-zero mode", "f1 at 2,000 random poses over f1 of the level "
               "pose at that height stays above 1/3 (measured: 1/3 minus the lowest ratio)",
               0.0, max(0.0, 1 / 3 - lowest), note=f"lowest ratio {lowest:.3f}")
