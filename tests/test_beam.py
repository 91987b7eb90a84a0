"""Frame elements against closed-form beam, bar and shaft theory (analytical/beam.py)."""
from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from analytical.beam import Section, assemble_beam, frame_element

E, G, RHO = 200e9, 77e9, 7820.0
NU = E / (2 * G) - 1
D = 0.1
SECTION = Section.solid_circle(D, NU)


def lowest_frequencies(k, m, fixed, count):
    free = np.setdiff1d(np.arange(k.shape[0]), fixed)
    w2 = scipy.linalg.eigh(k[np.ix_(free, free)], m[np.ix_(free, free)], eigvals_only=True)
    return np.sqrt(np.abs(w2[:count])) / (2 * math.pi)


def node_dofs(node, comps):
    return [6 * node + c for c in comps]


@pytest.mark.parametrize("theory", ["euler-bernoulli", "timoshenko"])
def test_element_matrices_are_symmetric_and_free_beam_has_six_rigid_modes(theory):
    k, m = frame_element(E, G, RHO, SECTION, 0.25, theory)
    assert np.allclose(k, k.T, rtol=0, atol=1e-9 * abs(k).max())
    assert np.allclose(m, m.T, rtol=0, atol=1e-12 * abs(m).max())
    eig_k = np.linalg.eigvalsh(k)
    assert eig_k.min() > -1e-9 * eig_k.max()  # positive semi-definite
    assert np.sum(eig_k < 1e-9 * eig_k.max()) == 6  # exactly six rigid-body modes
    assert np.linalg.eigvalsh(m).min() > 0  # consistent mass positive definite


def test_rigid_motions_cost_no_strain_energy():
    k, _ = frame_element(E, G, RHO, SECTION, 0.3, "timoshenko")
    L = 0.3
    # rotation about z by a small angle: u_y = theta x, theta_z = theta at both nodes
    rot_z = np.zeros(12)
    rot_z[[5, 11]] = 1.0
    rot_z[7] = L
    rot_y = np.zeros(12)
    rot_y[[4, 10]] = 1.0
    rot_y[8] = -L  # theta_y = -du_z/dx
    for mode in (rot_z, rot_y):
        assert np.linalg.norm(k @ mode) < 1e-9 * np.linalg.norm(k)


def test_cantilever_first_bending_matches_euler_bernoulli_closed_form():
    L = 0.55
    k, m = assemble_beam(E, G, RHO, SECTION, L, 10, "euler-bernoulli")
    f = lowest_frequencies(k, m, node_dofs(0, range(6)), 2)
    beta_l = 1.8751040687
    exact = beta_l**2 / (2 * math.pi) * math.sqrt(E * SECTION.second_moment_z
                                                  / (RHO * SECTION.area * L**4))
    assert f == pytest.approx([exact, exact], rel=1e-5)  # a pair: round section


def test_simply_supported_euler_bernoulli_modes():
    L = 1.2
    s = 12
    k, m = assemble_beam(E, G, RHO, SECTION, L, s, "euler-bernoulli")
    # pinned ends; axial and twist held at both ends keep those modes above the third bending
    fixed = node_dofs(0, [0, 1, 2, 3]) + node_dofs(s, [0, 1, 2, 3])
    f = lowest_frequencies(k, m, fixed, 6)
    base = math.pi / (2 * L**2) * math.sqrt(E * SECTION.second_moment_z / (RHO * SECTION.area))
    n = np.array([1, 1, 2, 2, 3, 3])
    exact = n**2 * base
    # Cubic Hermite elements with consistent mass overestimate by (k h)^4 / 1440 to leading order.
    bound = (n * math.pi / s) ** 4 / 1440
    rel = f / exact - 1
    assert np.all(rel > 0) and np.all(rel < 1.05 * bound + 1e-9)


def timoshenko_simply_supported(n, L, section, beam_e=E, beam_g=G, rho=RHO):
    """Lowest root of the Timoshenko dispersion relation for mode n of a pinned-pinned beam."""
    kw = n * math.pi / L
    I, A, kap = section.second_moment_z, section.area, section.shear_coefficient
    a = rho**2 * I / (kap * beam_g)
    b = -(rho * A + rho * I * kw**2 + rho * beam_e * I * kw**2 / (kap * beam_g))
    c = beam_e * I * kw**4
    w2 = (-b - math.sqrt(b * b - 4 * a * c)) / (2 * a)
    return math.sqrt(w2) / (2 * math.pi)


def test_thick_simply_supported_beam_matches_timoshenko_theory_not_euler_bernoulli():
    L, s = 0.5, 20  # L/d = 5: shear and rotary inertia lower f1 by several percent
    fixed = node_dofs(0, [0, 1, 2, 3]) + node_dofs(s, [1, 2])
    exact = timoshenko_simply_supported(1, L, SECTION)
    k, m = assemble_beam(E, G, RHO, SECTION, L, s, "timoshenko")
    f_timo = lowest_frequencies(k, m, fixed, 1)[0]
    k, m = assemble_beam(E, G, RHO, SECTION, L, s, "euler-bernoulli")
    f_eb = lowest_frequencies(k, m, fixed, 1)[0]
    assert f_timo == pytest.approx(exact, rel=1e-4)
    assert f_eb / exact - 1 > 0.02  # Euler-Bernoulli is measurably stiffer here


def test_fixed_free_axial_bar_and_torsional_shaft():
    L, s = 0.8, 40
    k, m = assemble_beam(E, G, RHO, SECTION, L, s, "euler-bernoulli")
    axial = [6 * n for n in range(s + 1)]
    twist = [6 * n + 3 for n in range(s + 1)]
    f_axial = lowest_frequencies(k[np.ix_(axial, axial)], m[np.ix_(axial, axial)], [0], 2)
    f_twist = lowest_frequencies(k[np.ix_(twist, twist)], m[np.ix_(twist, twist)], [0], 2)
    c_axial, c_twist = math.sqrt(E / RHO), math.sqrt(G / RHO)  # J = I_p for a circle
    wavenumbers = np.array([1, 3]) * math.pi / (2 * L)
    # Linear elements with consistent mass overestimate by (k h)^2 / 24 to leading order.
    bound = (wavenumbers * L / s) ** 2 / 24
    for f, c in ((f_axial, c_axial), (f_twist, c_twist)):
        exact = c * wavenumbers / (2 * math.pi)
        rel = f / exact - 1
        assert np.all(rel > 0) and np.all(rel < 1.05 * bound + 1e-9)


def test_timoshenko_rods_converge_as_h_to_the_fourth_from_below():
    """The averaged (consistent + lumped) rod mass of the Timoshenko element: axial and
    torsional frequencies below the exact ones by (k h)^4 / 480 to leading order."""
    L = 0.8
    c_axial, c_twist = math.sqrt(E / RHO), math.sqrt(G / RHO)
    wavenumbers = np.array([1, 3]) * math.pi / (2 * L)
    for s in (5, 10):
        k, m = assemble_beam(E, G, RHO, SECTION, L, s, "timoshenko")
        for offset, c in ((0, c_axial), (3, c_twist)):
            dofs = [6 * n + offset for n in range(s + 1)]
            f = lowest_frequencies(k[np.ix_(dofs, dofs)], m[np.ix_(dofs, dofs)], [0], 2)
            rel = f / (c * wavenumbers / (2 * math.pi)) - 1
            bound = (wavenumbers * L / s) ** 4 / 480
            assert np.all(rel < 0) and np.all(-rel < 1.1 * bound), (s, rel, bound)


def test_unknown_theory_and_bad_length_are_rejected():
    with pytest.raises(ValueError, match="'bernoulli'"):
        frame_element(E, G, RHO, SECTION, 0.1, "bernoulli")
    with pytest.raises(ValueError, match="-0.1"):
        frame_element(E, G, RHO, SECTION, -0.1)


def test_each_bending_plane_uses_its_own_second_moment_and_shear_parameter():
    """A thin rectangle (I_y != I_z): each plane's Timoshenko frequency is its own."""
    b, h = 0.02, 0.1  # width along local y, height along local z
    area = b * h
    i_y, i_z = b * h**3 / 12, h * b**3 / 12  # x-z bending on I_y, x-y bending on I_z
    section = Section(area, i_y, i_z, 1e-9, i_y + i_z, 5 / 6)
    L, s = 0.4, 20
    k, m = assemble_beam(E, G, RHO, section, L, s, "timoshenko")
    xy = [6 * n + c for n in range(s + 1) for c in (1, 5)]  # (u_y, theta_z)
    xz = [6 * n + c for n in range(s + 1) for c in (2, 4)]  # (u_z, theta_y)
    for plane, moment in ((xy, i_z), (xz, i_y)):
        sub = np.ix_(plane, plane)
        f = lowest_frequencies(k[sub], m[sub], [0, len(plane) - 2], 1)[0]
        one_plane = Section(area, moment, moment, 1e-9, 2 * moment, 5 / 6)
        exact = timoshenko_simply_supported(1, L, one_plane)
        assert f == pytest.approx(exact, rel=2e-4)


def test_shear_coefficients_of_a_solid_circle():
    """Cowper 6(1+nu)/(7+6nu) and Hutchinson 6(1+nu)^2/(7+12nu+4nu^2): 0.8863 and 0.9249 at
    nu = 0.2987 (Hutchinson, J. Appl. Mech. 68:87, 2001); both 6/7 at nu = 0."""
    from analytical.beam import circle_shear_coefficient
    assert circle_shear_coefficient(0.2987, "cowper") == pytest.approx(0.8863, abs=1e-4)
    assert circle_shear_coefficient(0.2987, "hutchinson") == pytest.approx(0.9249, abs=1e-4)
    assert circle_shear_coefficient(0.0, "cowper") == circle_shear_coefficient(0.0, "hutchinson")
    with pytest.raises(ValueError, match="shear = 'x'"):
        circle_shear_coefficient(0.3, "x")


def _printed_element(E, G, rho, s: Section, L: float, timoshenko: bool):
    """The element as the references print it, entry by entry (Przemieniecki's stiffness,
    Friedman & Kosmatka's consistent translational and rotary mass; the module doc)."""
    k, m = np.zeros((12, 12)), np.zeros((12, 12))
    rod = np.array([[5, 1], [1, 5]]) / 12 if timoshenko else np.array([[2, 1], [1, 2]]) / 6
    bar = np.array([[1.0, -1.0], [-1.0, 1.0]])
    for index, stiff, inertia in (([0, 6], E * s.area, s.area), ([3, 9], G * s.torsion_constant,
                                                                   s.polar_moment)):
        k[np.ix_(index, index)] = stiff / L * bar
        m[np.ix_(index, index)] = rho * inertia * L * rod
    for index, i, sign in (([1, 5, 7, 11], s.second_moment_z, 1.0),
                           ([2, 4, 8, 10], s.second_moment_y, -1.0)):
        p = 12 * E * i / (s.shear_coefficient * G * s.area * L**2) if timoshenko else 0.0
        c = E * i / ((1 + p) * L**3)
        kb = c * np.array([[12, 6 * L, -12, 6 * L],
                           [6 * L, (4 + p) * L**2, -6 * L, (2 - p) * L**2],
                           [-12, -6 * L, 12, -6 * L],
                           [6 * L, (2 - p) * L**2, -6 * L, (4 + p) * L**2]])
        a, b = 13 / 35 + 7 * p / 10 + p**2 / 3, (11 / 210 + 11 * p / 120 + p**2 / 24) * L
        cc, d = 9 / 70 + 3 * p / 10 + p**2 / 6, (13 / 420 + 3 * p / 40 + p**2 / 24) * L
        e, f = (1 / 105 + p / 60 + p**2 / 120) * L**2, (1 / 140 + p / 60 + p**2 / 120) * L**2
        mb = rho * s.area * L / (1 + p)**2 * np.array([[a, b, cc, -d], [b, e, d, -f],
                                                       [cc, d, a, -b], [-d, -f, -b, e]])
        if timoshenko:
            g, h = (1 / 10 - p / 2) * L, (2 / 15 + p / 6 + p**2 / 3) * L**2
            kk = (1 / 30 + p / 6 - p**2 / 6) * L**2
            mb = mb + rho * i / ((1 + p)**2 * L) * np.array(
                [[6 / 5, g, -6 / 5, g], [g, h, -g, -kk], [-6 / 5, -g, 6 / 5, -g], [g, -kk, -g, h]])
        flip = np.outer([1, sign, 1, sign], [1, sign, 1, sign])  # theta_y = -dw/dx
        k[np.ix_(index, index)] = flip * kb
        m[np.ix_(index, index)] = flip * mb
    return k, m


@pytest.mark.parametrize("theory", ["euler-bernoulli", "timoshenko"])
def test_the_element_is_the_printed_matrices_entry_by_entry(theory):
    """frame_element evaluates the printed closed forms as fixed patterns times factors of the
    length: the same matrices to round-off, for random sections and materials, one length or
    many (each element its own)."""
    rng = np.random.default_rng(7)
    for trial in range(40):
        outer = rng.uniform(0.004, 0.3)
        s = Section.circle(outer, outer * rng.uniform(0.0, 0.95) if trial % 2 else 0.0,
                           rng.uniform(0.2, 0.45), "hutchinson")
        if trial % 3 == 0:  # any section: I_y, I_z, J and I_p apart (a swap would show)
            i = s.second_moment_y
            s = Section(s.area, i * rng.uniform(0.3, 1.0), i * rng.uniform(1.0, 3.0),
                        i * rng.uniform(0.2, 1.5), i * rng.uniform(1.5, 4.0),
                        rng.uniform(0.5, 0.9))
        E, G, rho = rng.uniform(5e10, 4e11), rng.uniform(2e10, 1.6e11), rng.uniform(1e3, 2e4)
        lengths = rng.uniform(0.001, 2.0, size=(2, 3))
        k, m = frame_element(E, G, rho, s, lengths, theory)
        for idx in np.ndindex(lengths.shape):
            want_k, want_m = _printed_element(E, G, rho, s, lengths[idx], theory == "timoshenko")
            for got, want in ((k[idx], want_k), (m[idx], want_m)):
                assert np.abs(got - want).max() <= 1e-14 * np.abs(want).max()
        one_k, _ = frame_element(E, G, rho, s, float(lengths[0, 0]), theory)
        # alone or in a batch: numpy's vector paths round by array shape and processor, so
        # the same element to round-off, not to the bit (tests/README.md)
        assert one_k.shape == (12, 12)
        assert np.abs(one_k - k[0, 0]).max() <= 1e-14 * np.abs(k[0, 0]).max()
