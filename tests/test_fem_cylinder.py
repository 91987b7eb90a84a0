"""Free-free solid steel cylinder (d = 0.1 m, L = 0.55 m): the 3D P2 solid against closed forms.

- six rigid-body modes, exactly;
- torsion: f_n = n / (2 L) sqrt(G / rho) is an exact 3D elasticity solution (rigid rotation of
  every cross-section, free ends traction-free) -> 0.1 %;
- first bending pair: free-free Timoshenko beam, frequency equation solved here from the exact
  transfer matrix of the Timoshenko ODEs (Cowper's shear coefficient) -> 1 %;
- first axial mode: rod f = (1 / 2L) sqrt(E / rho) with Love's (Rayleigh's) lateral-inertia
  correction f = f_rod / sqrt(1 + nu^2 k^2 r^2 / 2), k = pi / L -> 0.1 %.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import brentq

from analytical.params import Material
from fem_reference.assembly import stiffness_and_mass
from fem_reference.discretisation import discretise
from fem_reference.eigen import lowest_modes
from meshing import Assembly, Cylinder, MeshSettings, build_mesh

STEEL = Material(200e9, 77e9, 7820.0)
D, L = 0.1, 0.55
AXIS = np.array([1.0, 2.0, 2.0]) / 3.0  # a skew axis, so nothing lines up with the mesh axes


def timoshenko_free_free(n_root: int = 1) -> float:
    """n-th free-free bending frequency (Hz) of a Timoshenko beam: det of the end-force block of
    the exact transfer matrix y(L) = expm(A L) y(0), y = [w, psi, M, Q], vanishes."""
    e, g, rho = STEEL.youngs_modulus, STEEL.shear_modulus, STEEL.density
    nu = STEEL.poisson_ratio
    area, inertia = math.pi * D**2 / 4, math.pi * D**4 / 64
    kappa = 6 * (1 + nu) / (7 + 6 * nu)

    def det(f):
        w2 = (2 * math.pi * f) ** 2
        a = np.array([
            [0, 1, 0, 1 / (kappa * g * area)],  # w' = psi + Q / (kappa G A)
            [0, 0, 1 / (e * inertia), 0],  # psi' = M / EI
            [0, -rho * inertia * w2, 0, -1],  # M' = -Q - rho I w^2 psi
            [-rho * area * w2, 0, 0, 0],  # Q' = -rho A w^2 w
        ])
        t = expm(a * L)
        return np.linalg.det(t[2:, :2])  # M(L) = Q(L) = 0 from free w(0), psi(0)

    grid = np.linspace(50.0, 8000.0, 4000)
    vals = [det(f) for f in grid]
    roots = [brentq(det, grid[k], grid[k + 1], xtol=1e-10)
             for k in range(len(grid) - 1) if vals[k] * vals[k + 1] < 0]
    return roots[n_root - 1]


@pytest.fixture(scope="module")
def cylinder_modes():
    rod = Assembly((Cylinder("leg1", (0.0, 0.0, 0.0), tuple(L * AXIS), D / 2),))
    disc = discretise(build_mesh(rod, MeshSettings(0.02, rim_zone=0.15 * D)))
    k, m = stiffness_and_mass(disc, STEEL)
    modes = lowest_modes(k, m, 12)
    return disc, modes


def test_exactly_six_rigid_body_modes(cylinder_modes):
    _, modes = cylinder_modes
    f = modes.frequencies_hz
    assert np.all(np.abs(f[:6]) < 1e-3 * f[6])  # numerically zero (< 1 Hz against 1377 Hz)
    assert f[6] > 1000.0


def test_torsional_modes_are_exact(cylinder_modes):
    disc, modes = cylinder_modes
    exact = 1 / (2 * L) * math.sqrt(STEEL.shear_modulus / STEEL.density)
    # identify torsion by shape: the displacement is tangential about the axis everywhere
    x = disc.node_xyz - disc.node_xyz.mean(axis=0)
    radial = x - np.outer(x @ AXIS, AXIS)
    keep = np.linalg.norm(radial, axis=1) > D / 8
    tangent = np.cross(AXIS, radial[keep])
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    u = modes.vectors.reshape(disc.n_nodes, 3, -1)[keep][:, :, 6:]
    share = (np.einsum("nc,ncm->nm", tangent, u) ** 2).sum(0) / (u**2).sum(axis=(0, 1))
    torsion = modes.frequencies_hz[6:][np.argmax(share)]
    assert share.max() > 0.99 and np.sort(share)[-2] < 0.5
    assert torsion == pytest.approx(exact, rel=1e-3)


def test_first_bending_pair_matches_timoshenko(cylinder_modes):
    _, modes = cylinder_modes
    f = modes.frequencies_hz
    reference = timoshenko_free_free(1)
    assert f[6] == pytest.approx(reference, rel=0.01)
    assert f[7] == pytest.approx(reference, rel=0.01)
    assert abs(f[7] - f[6]) / f[6] < 1e-4  # the pair is degenerate up to mesh asymmetry


def test_first_axial_mode_matches_love_rod(cylinder_modes):
    disc, modes = cylinder_modes
    e, rho, nu = STEEL.youngs_modulus, STEEL.density, STEEL.poisson_ratio
    k = math.pi / L
    love = 1 / (2 * L) * math.sqrt(e / rho) / math.sqrt(1 + nu**2 * k**2 * (D / 2) ** 2 / 2)
    u = modes.vectors.reshape(disc.n_nodes, 3, -1)
    axial_share = np.linalg.norm(np.einsum("c,ncm->nm", AXIS, u), axis=0) / np.linalg.norm(
        u.reshape(-1, u.shape[2]), axis=0)
    axial = modes.frequencies_hz[6:][np.argmax(axial_share[6:])]
    assert axial == pytest.approx(love, rel=1e-3)
