"""Hard cases: extreme geometry and materials (slender, stocky, thin, other metals)."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from analytical.kinematics import pose_geometry
from analytical.model import natural_frequencies
from analytical.params import Material, Pose
from analytical.reach import WorkspaceError, layer_heights, sample_poses
from scene import Scene

from .base import SEED, Row, bare, uniform, untestable

# --- geometry --------------------------------------------------------------------------------

def _ratio_over_poses(m_a, opts_a, m_b, opts_b, poses) -> np.ndarray:
    return np.array([natural_frequencies(m_a, p, opts_a) / natural_frequencies(m_b, p, opts_b)
                     for p in poses])


def beam_theory_gap(scene: Scene, slenderness: float, poses: int = 50) -> float:
    """Largest |f Timoshenko / f Euler-Bernoulli - 1| over six modes and random poses of the
    scene's machine with legs of L/d = `slenderness` (L at the middle level pose)."""
    m = scene.manipulator
    length = pose_geometry(m, Pose(float(layer_heights(m, 3)[1]))).leg_lengths[0]
    machine = uniform(m, length / slenderness)
    sample = sample_poses(machine, poses, np.random.default_rng(SEED + 3))  # may raise
    ratio = _ratio_over_poses(machine, replace(scene.analytical, beam="timoshenko", modes=6),
                              machine, replace(scene.analytical, beam="euler-bernoulli",
                                               modes=6), sample)
    return float(np.abs(ratio - 1).max())


def slender_legs(scene: Scene) -> Row:
    """Slender legs (L/d = 30 at mid height): shear deformation and rotary inertia scale with
    (d/L)^2, so Euler-Bernoulli and Timoshenko beams agree within 1 % on six modes (the test
    also checks the (d/L)^2 scaling against L/d = 60)."""
    case = "slender legs, L/d = 30"
    try:
        gap = beam_theory_gap(scene, 30.0)
    except WorkspaceError as exc:
        return untestable(case, 0.01, exc)
    return Row(case, "|f Timoshenko / f Euler-Bernoulli - 1|, six modes, 50 poses", 0.01, gap,
               "relative")




def stocky_legs(scene: Scene) -> Row:
    """Stocky legs (L/d = 3 at mid height): shear flexibility and rotary inertia only lower
    the frequencies, so Timoshenko is below Euler-Bernoulli on every mode at every pose
    (measured: the largest f_T / f_EB - 1, which must not exceed rounding, 1e-9)."""
    m = scene.manipulator
    z = float(layer_heights(m, 3)[1])
    length = pose_geometry(m, Pose(z)).leg_lengths[0]
    stocky = uniform(m, length / 3)
    try:
        poses = sample_poses(stocky, 50, np.random.default_rng(SEED + 4))
    except WorkspaceError as exc:
        return untestable("stocky legs, L/d = 3", 1e-9, exc)
    ratio = _ratio_over_poses(stocky, replace(scene.analytical, beam="timoshenko", modes=6),
                              stocky, replace(scene.analytical, beam="euler-bernoulli",
                                              modes=6), poses)
    return Row("stocky legs, L/d = 3", "largest f Timoshenko / f Euler-Bernoulli - 1, six "
               "modes, 50 poses", 1e-9, float((ratio - 1).max()), "relative")


def thin_plate(scene: Scene) -> Row:
    """A 5 mm platform (half the scene's, if that is thinner) is lighter than the scene's and
    nothing stiffer is lost (the platform is rigid in the model), so no frequency falls
    (Courant-Fischer: less mass never lowers an eigenvalue). Measured: the largest fall,
    1 - f(thin) / f(scene's plate), against rounding (1e-9). A thinner plate only moves away
    from the base, so every pose of the scene's machine stays reachable."""
    m = scene.manipulator
    thickness = min(THIN_PLATE, 0.5 * m.platform_thickness)
    thin = replace(m, platform_thickness=thickness)
    poses = sample_poses(m, 50, np.random.default_rng(SEED + 5))
    opts = replace(scene.analytical, modes=6)
    ratio = _ratio_over_poses(thin, opts, m, opts, poses)
    return Row(f"thin plate, {thickness * 1e3:g} mm", "largest fall of a frequency from the "
               f"{m.platform_thickness * 1e3:g} mm plate to the {thickness * 1e3:g} mm one, 50 "
               "poses", 1e-9, float(max(0.0, (1 - ratio).max())), "relative")


THIN_PLATE = 0.005  # m


ALUMINIUM = (70e9, 2700.0)  # E (Pa), rho (kg/m^3)
TITANIUM = (113.8e9, 0.342, 4430.0)  # Ti-6Al-4V: E (Pa), Poisson ratio, rho


def aluminium_scaling(scene: Scene) -> Row:
    """With steel's Poisson ratio, an aluminium machine has K scaled by E and M by rho: every
    frequency scales by sqrt(E rho_steel / (E_steel rho)) exactly (to 1e-9)."""
    m = bare(scene.manipulator)
    e, rho = ALUMINIUM
    scale = e / m.material.youngs_modulus
    aluminium = replace(m, material=Material(e, m.material.shear_modulus * scale, rho))
    expected = math.sqrt(scale * m.material.density / rho)
    poses = sample_poses(m, 30, np.random.default_rng(SEED + 6))
    ratio = _ratio_over_poses(aluminium, scene.analytical, m, scene.analytical, poses)
    return Row("aluminium", "|f_Al / f_steel / sqrt(E_Al rho_steel / (E_steel rho_Al)) - 1|, "
               "steel's Poisson ratio", 1e-9, float(np.abs(ratio / expected - 1).max()),
               "relative")


def titanium_scaling(scene: Scene) -> Row:
    """A titanium machine (Ti-6Al-4V, its own Poisson ratio 0.342), Euler-Bernoulli legs:
    K = E K_E + G K_G with both parts positive semi-definite and M proportional to rho, so by
    Courant-Fischer every frequency ratio to steel lies between sqrt(E ratio / rho ratio) and
    sqrt(G ratio / rho ratio). No mode deviates from the sqrt(E / rho) scaling by more than a
    pure torsion mode would: |1 - sqrt((1 + nu_steel) / (1 + nu_Ti))| = 1.6 %."""
    m = bare(scene.manipulator)
    e, nu, rho = TITANIUM
    titanium = replace(m, material=Material(e, e / (2 * (1 + nu)), rho))
    expected = math.sqrt(e / m.material.youngs_modulus * m.material.density / rho)
    bound = abs(1 - math.sqrt((1 + m.material.poisson_ratio) / (1 + nu)))
    poses = sample_poses(m, 30, np.random.default_rng(SEED + 7))
    opts = replace(scene.analytical, beam="euler-bernoulli")
    ratio = _ratio_over_poses(titanium, opts, m, opts, poses)
    return Row("titanium", "|f_Ti / f_steel / sqrt(E ratio / rho ratio) - 1| against the pure "
               "torsion bound |1 - sqrt((1 + nu_steel) / (1 + nu_Ti))|, Euler-Bernoulli",
               bound + 1e-9, float(np.abs(ratio / expected - 1).max()), "relative")
