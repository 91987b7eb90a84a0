"""Real legs in the FEM reference: stepped, hollow legs and joint and drive springs.

Physics as the specification: springs far stiffer than the legs are the rigid joints; a softer
drive never raises a frequency (min-max); a clamped hollow tube bends as the beam of a hollow
circle; a junction of two equal solid parts only adds plane sections; a very soft drive leaves
the platform and the legs riding on three axial springs (a closed form); the two independent
discretisations agree on a stepped hollow leg, both from above.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
import scipy.linalg as la

from analytical.kinematics import pose_geometry
from common.leg_profile import LegProfile
from common.stiffness import Stiffness
from fem_reference import FemRuntime, solve_pose
from fem_reference.assembly import lame
from fem_reference.eigen import lowest_modes
from fem_reference.guard import estimate_raw_dofs
from fem_reference.meridian import estimate_raw_dofs as estimate_harmonic
from fem_reference.meridian import leg_harmonics, part_size
from meshing.bodies import pose_assembly

COARSE = 0.04  # m: 0.4 d, the harmonic legs' error there is ~1e-4 (fem_reference/README.md)
# A stepped hollow actuator on the paper's machine: a 100/60 mm housing 300 mm long and a 60/30
# mm rod (the shortest leg must leave a rod as long as its diameter: actuator_min 400 mm)
STEPPED = LegProfile(0.3, 0.1, 0.06, 0.06, 0.03)
# The stiffnesses of a real machine's joints and drive (N/um and N m/urad in the scene)
REAL = dict(actuator_axial=250e6, base_joint_translational=800e6, base_joint_rotational=2e6,
            platform_joint_translational=600e6)


def _solve(scene, manipulator, case="case2", size=COARSE, **options):
    geometry = pose_geometry(manipulator, scene.case(case).pose)
    opts = replace(scene.fem, modes=6, **{"legs": "harmonic", **options}).with_size(size)
    return solve_pose(manipulator, geometry, opts, FemRuntime(use_cache=False))


@pytest.mark.parametrize("coupling", ["rigid", "distributing"])
def test_springs_far_stiffer_than_the_legs_are_the_rigid_joints(scene, coupling):
    """Every spring of a real machine times 1e9 (k_a 2.5e17 N/m against a leg's E A / L of
    3e9 N/m): the frequencies of the rigid joints within 1e-4 (the springs' compliance is
    1e-8 of the legs'; measured 3e-8 rigid, 2e-9 distributing)."""
    rigid = _solve(scene, scene.manipulator, coupling=coupling).frequencies_hz
    stiff = replace(scene.manipulator, stiffness=Stiffness(**REAL).scaled(1e9))
    f = _solve(scene, stiff, coupling=coupling).frequencies_hz
    np.testing.assert_allclose(f, rigid, rtol=1e-4)
    real = _solve(scene, replace(scene.manipulator, stiffness=Stiffness(**REAL)),
                  coupling=coupling).frequencies_hz
    assert np.all(real < 0.7 * rigid)  # the real springs matter: 54-353 Hz against 105-739 Hz


def test_a_softer_drive_never_raises_a_frequency(scene):
    """K(k_a) decreases with k_a in the Loewner order, M does not change: by min-max every
    eigenvalue is non-increasing as the drive softens (rigid first)."""
    previous = None
    for k_a in (0.0, 1e10, 1e9, 250e6, 1e8, 1e7):
        m = replace(scene.manipulator, stiffness=Stiffness(actuator_axial=k_a,
                                                           base_joint_translational=800e6))
        f = _solve(scene, m).frequencies_hz
        if previous is not None:
            assert np.all(f <= previous * (1 + 1e-9)), (k_a, f, previous)
        previous = f
    assert previous[0] < 0.8 * _solve(scene, scene.manipulator).frequencies_hz[0]


def test_a_clamped_hollow_tube_bends_as_a_beam(scene):
    """Harmonic n = 1 of a 50/40 mm steel tube 2 m long (L / D = 40), face z = 0 held, the other
    free: the Euler-Bernoulli cantilever f_k = (beta_k L)^2 / (2 pi L^2) sqrt(E I / (rho A)),
    I = pi (R^4 - r^4) / 4, from below (shear and rotary inertia only lower it: by about
    (beta_k r_g)^2 (1 + E / (kappa G)) / 2, 0.07 % for mode 1 and 0.4 % for mode 2 with
    r_g = 16 mm, kappa ~ 0.53; measured -0.02 % and -0.53 %)."""
    material = scene.manipulator.material
    lam, mu = lame(material)
    radius, inner, length = 0.025, 0.02, 2.0
    size = part_size(0.02, radius, inner)
    assert size <= 0.5 * (radius - inner)  # two elements across the wall, at least
    leg = leg_harmonics(radius, length, lam, mu, material.density, size, (1,), inner)
    assert len(leg.axis_nodes) == 0  # a tube has no axis
    k, m = leg.stiffness[1], leg.mass
    free = np.setdiff1d(np.arange(k.shape[0]),
                        (3 * leg.face_nodes[0][:, None] + np.arange(3)).ravel())
    f = np.sqrt(lowest_modes(k[free][:, free], m[free][:, free], 2).eigenvalues) / (2 * math.pi)
    area, second = math.pi * (radius**2 - inner**2), math.pi * (radius**4 - inner**4) / 4
    beam = np.array([1.875104069, 4.694091133]) ** 2 / (2 * math.pi * length**2) * math.sqrt(
        material.youngs_modulus * second / (material.density * area))
    assert np.all(f <= beam)
    assert (beam - f)[0] / beam[0] < 3e-3 and (beam - f)[1] / beam[1] < 1.5e-2


def test_a_junction_of_two_equal_solid_parts_adds_only_plane_sections(scene):
    """A stepped leg whose housing and rod are the uniform leg (100 mm solid both, rigid drive)
    is the same solid but at the junction, where two faces meet, each tied to the junction
    point H. Rigid coupling: the uniform leg with its section at H held plane and undeformed,
    a constraint (min-max: never lower); it blocks the section's shear warping and Poisson
    contraction in a stocky leg (L / d ~ 5.5), measured +0.15-0.22 % on f1-f3 and +0.61-0.65 %
    on f4-f6, converged (the same at 40 and 20 mm to 0.003 %). Distributing coupling: the two
    faces only agree on average, a relaxation (never higher), measured -0.001 to -0.011 %."""
    same = replace(scene.manipulator, leg=LegProfile(0.3, 0.1, 0.0, 0.1, 0.0))
    uniform = _solve(scene, scene.manipulator).frequencies_hz
    f = _solve(scene, same).frequencies_hz
    assert np.all(f >= uniform) and np.all(f <= uniform * 1.01)
    uniform = _solve(scene, scene.manipulator, coupling="distributing").frequencies_hz
    f = _solve(scene, same, coupling="distributing").frequencies_hz
    assert np.all(f <= uniform) and np.all(f >= uniform * (1 - 2e-4))


@pytest.mark.parametrize("case, k_a, tolerance", [("case1", 1e6, 5e-4), ("case2", 1e6, 2e-3),
                                                  ("case2", 1e4, 3e-5)])
def test_a_very_soft_drive_leaves_the_platform_on_three_axial_springs(scene, case, k_a,
                                                                      tolerance):
    """A drive of 1 or 0.01 N/um with rigid joints: the lowest three modes are the platform on
    three axial springs k_eff = (1/k_a + L / (E A))^-1 along the legs (K = sum k_eff n n^T,
    n_i = [e_i; (A_i - o) x e_i]). The spring sits at the base joint of a uniform leg (F_b), so
    each leg rides on it: it translates along e_i with A_i's axial motion and pivots about its R
    axis a_i with A_i's motion along b_i = a_i x e_i (mass m_l (n n^T + (1/3 + R^2 / (4 L^2))
    p p^T), p_i = [b_i; (A_i - o) x b_i]: the legs, 3 x 34 kg, outweigh the 20 kg platform).
    A_i's motion along a_i bends the leg (R at the base, S at the top: a cantilever of ~18
    N/um): in the soft limit it is held, c_i^T x = 0, c_i = [a_i; (A_i - o) x a_i], and the
    closed form is (K, M) restricted to those motions. What remains is the legs' bending
    against the drive, (f / f_bend)^2 ~ k_a / k_bend: 1e-4 at 1 N/um (2e-3 on case 2's f2,
    whose mode is closest to the bending ones), 1e-6 at 0.01 N/um (measured)."""
    m = replace(scene.manipulator, stiffness=Stiffness(actuator_axial=k_a))
    geometry = pose_geometry(m, scene.case(case).pose)
    f = _solve(scene, m, case).frequencies_hz
    mat = m.material
    radius = 0.5 * m.leg_diameter
    area = math.pi * radius**2
    o = geometry.platform_centre
    k, legs, held = np.zeros((6, 6)), np.zeros((6, 6)), []
    for i in range(3):
        length, e, a = geometry.leg_lengths[i], geometry.leg_directions[i], geometry.joint_axes[i]
        arm = geometry.platform_points[i] - o
        n, p, c = (np.r_[v, np.cross(arm, v)] for v in (e, np.cross(a, e), a))
        k += np.outer(n, n) / (1 / k_a + length / (mat.youngs_modulus * area))
        legs += mat.density * area * length * (np.outer(n, n) + (1 / 3 + radius**2 / (
            4 * length**2)) * np.outer(p, p))
        held.append(c)
    mp = mat.density * math.pi * m.platform_radius**2 * m.platform_thickness
    r2, h = m.platform_radius, m.platform_thickness
    inertia = geometry.rotation @ np.diag([mp * (3 * r2**2 + h**2) / 12] * 2
                                          + [mp * r2**2 / 2]) @ geometry.rotation.T
    free = la.null_space(np.array(held))
    w = la.eigh(free.T @ k @ free, free.T @ (la.block_diag(mp * np.eye(3), inertia) + legs)
                @ free, eigvals_only=True)
    closed = np.sqrt(w) / (2 * math.pi)
    np.testing.assert_allclose(f[:3], closed, rtol=tolerance)
    assert f[3] > 4 * f[2]  # the axial-spring modes are the lowest three, well apart


@pytest.mark.slow
def test_harmonic_and_tetrahedral_stepped_hollow_legs_agree_from_above(scene):
    """A stepped hollow leg (STEPPED) with the real springs, case 2: the harmonic legs at 40 mm
    (their tubes at min(h, w / 2, w h / D), converged to 1e-5: 20 mm changes f1-f6 by <= 7e-6)
    are the reference; the tetrahedra (one element across a wall at these sizes) converge to it
    from above, measured 0.02-0.07 % at 30 mm and 0.01-0.05 % at 20 mm (their own error at
    these sizes on uniform legs, fem_reference/README.md: 0.05-0.09 %; one element across a
    wall here): within 0.15 % and closer at 20 mm. Both dof estimates lie above the counts,
    and the two models' leg-axis motions of mode 1 agree (hollow parts read by their
    sections' mean motion)."""
    m = replace(scene.manipulator, leg=STEPPED, actuator_min=0.4,
                stiffness=Stiffness(**REAL))
    geometry = pose_geometry(m, scene.case("case2").pose)
    harmonic = _solve(scene, m)
    assembly = pose_assembly(m, geometry)
    assert harmonic.raw_dofs <= estimate_harmonic(assembly, COARSE)
    errors = []
    for size in (0.03, 0.02):
        tet = _solve(scene, m, size=size, legs="tetrahedra")
        assert tet.raw_dofs <= estimate_raw_dofs(assembly, replace(scene.fem.mesh, size=size))
        errors.append(tet.frequencies_hz / harmonic.frequencies_hz - 1)
    assert np.all(errors[0] > 0) and np.all(errors[1] > 0)
    assert np.all(errors[1] < errors[0]) and np.all(errors[0] < 1.5e-3)
    stations = [0.0, 0.25, 0.5, 0.505, 0.75, 1.0]
    a = harmonic.leg_axis_displacements(stations)[..., 0].ravel()
    b = tet.leg_axis_displacements(stations)[..., 0].ravel()
    assert (a @ b) ** 2 / ((a @ a) * (b @ b)) > 0.999
    tw = harmonic.leg_axis_twists(stations)
    assert tw.shape == (3, len(stations), 6) and np.all(np.isfinite(tw))
