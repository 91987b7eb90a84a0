"""Real machines in the analytical model (issue 23): actuator legs, joint and drive springs.

A leg is a housing and a rod, each solid or hollow; joints and the drive are springs. The
specification, as closed forms and identities:
- a hollow circle's section and shear coefficient reduce to the solid's and to the thin tube's;
- a stepped cantilever of beam elements converges to the exact stepped Euler-Bernoulli
  frequency (the transcendental 8 x 8 determinant of two segments);
- springs far stiffer than the legs are the rigid joints; softening a spring never raises a
  frequency (min-max: K' <= K);
- with a soft drive, the three lowest modes are those of the rigid mechanism (rigid legs on
  ideal joints, the platform and its payload) on three axial springs, derived below;
- the batched workspace model is the per-pose model, springs and stepped legs included.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
import scipy.linalg as la
import scipy.optimize as so

from analytical.batch_model import assemble_batch
from analytical.batch_solve import batch_frequencies, standard_form
from analytical.beam import Section, circle_shear_coefficient, frame_element
from analytical.kinematics import pose_geometry
from analytical.model import natural_frequencies
from analytical.params import ModelOptions, Pose
from analytical.pose_batch import pose_batch
from common.errors import InputError
from common.leg_profile import LegProfile
from common.payload import Payload, payload_mass_matrix
from common.plate import plate_inertia, plate_mass, rigid_mass_matrix
from common.rigid_body import skew
from common.stiffness import Stiffness, joint_spring_matrix
from scene import parse_scene
from tests.conftest import PAPER_SCENE

# issue 23's example values, SI
ACTUATOR = Stiffness(250e6, 800e6, 2e6, 600e6)
TUBES = LegProfile(0.25, 0.1, 0.07, 0.06, 0.03)  # housing 100/70 mm, rod 60/30 mm
TIMOSHENKO = ModelOptions(elements=6, beam="timoshenko", modes=8)


@pytest.fixture(scope="module")
def paper():
    import tomllib
    return parse_scene(tomllib.loads(PAPER_SCENE.read_text()))


def stepped(m, profile=TUBES):
    return replace(m, leg=profile, leg_diameter=profile.largest_diameter)


# ------------------------------------------------------------------ sections and closed forms

@pytest.mark.parametrize("form, thin", [("cowper", lambda nu: 2 * (1 + nu) / (4 + 3 * nu)),
                                        ("hutchinson", lambda nu: (1 + nu) / (2 + nu))])
def test_a_hollow_circles_shear_coefficient_spans_solid_to_thin_tube(form, thin):
    for nu in (0.1, 0.3, 0.45):
        assert circle_shear_coefficient(nu, form, 0.0) == circle_shear_coefficient(nu, form)
        assert circle_shear_coefficient(nu, form, 1 - 1e-9) == pytest.approx(thin(nu), 1e-7)
        ks = [circle_shear_coefficient(nu, form, m) for m in np.linspace(0, 0.99, 12)]
        assert np.all(np.diff(ks) < 0)  # a thinner wall shears more


def test_a_hollow_sections_properties_are_the_differences_of_two_circles():
    tube = Section.circle(0.1, 0.07, 0.3)
    outer, inner = Section.circle(0.1, 0.0, 0.3), Section.circle(0.07, 0.0, 0.3)
    for name in ("area", "second_moment_y", "second_moment_z", "torsion_constant",
                 "polar_moment"):
        assert getattr(tube, name) == pytest.approx(getattr(outer, name) - getattr(inner, name),
                                                    rel=1e-12)


def stepped_cantilever_exact(e, rho, parts, count=3):
    """Lowest `count` circular frequencies of a clamped-free Euler-Bernoulli beam of segments
    [(length, area, second moment)]: w_j = a cos bx + b sin bx + c cosh bx + d sinh bx per
    segment, clamped at 0, w, w', EI w'', EI w''' continuous at the step, free at the tip."""
    def basis(beta, x):  # rows: w, w', w'', w''' of the four functions at x
        c, s, ch, sh = math.cos(beta * x), math.sin(beta * x), math.cosh(beta * x), \
            math.sinh(beta * x)
        return np.array([[c, s, ch, sh], [-s, c, sh, ch], [-c, -s, ch, sh], [s, -c, sh, ch]]) \
            * np.array([1, beta, beta**2, beta**3])[:, None]

    def det(omega):
        betas = [(omega**2 * rho * a / (e * i)) ** 0.25 for _, a, i in parts]
        (l1, _, i1), (l2, _, i2) = parts
        m = np.zeros((8, 8))
        m[0:2, 0:4] = basis(betas[0], 0.0)[0:2]
        left, right = basis(betas[0], l1), basis(betas[1], 0.0)
        scale = np.array([1, 1, i1, i1])[:, None], np.array([1, 1, i2, i2])[:, None]
        m[2:6, 0:4], m[2:6, 4:8] = scale[0] * left, -scale[1] * right
        m[6:8, 4:8] = basis(betas[1], l2)[2:4]
        return np.linalg.det(m / np.abs(m).max(axis=1, keepdims=True))

    grid = np.linspace(1.0, 3e4, 30000)
    values = np.array([det(w) for w in grid])
    roots = [so.brentq(det, grid[k], grid[k + 1]) for k in np.flatnonzero(
        np.sign(values[:-1]) != np.sign(values[1:]))]
    return np.array(roots[:count])


def test_a_stepped_hollow_cantilever_converges_to_its_exact_frequencies():
    e, g, rho = 200e9, 77e9, 7820.0
    housing, rod = Section.circle(0.05, 0.035, 0.3), Section.circle(0.03, 0.015, 0.3)
    lengths = (0.6, 0.5)
    exact = stepped_cantilever_exact(e, rho, [(lengths[0], housing.area, housing.second_moment_y),
                                              (lengths[1], rod.area, rod.second_moment_y)])
    errors = []
    for s in (4, 8, 16):
        k, m = np.zeros((6 * (2 * s + 1),) * 2), np.zeros((6 * (2 * s + 1),) * 2)
        for part, (section, length) in enumerate(((housing, lengths[0]), (rod, lengths[1]))):
            ke, me = frame_element(e, g, rho, section, length / s, "euler-bernoulli")
            for j in range(s):
                sl = slice(6 * (part * s + j), 6 * (part * s + j) + 12)
                k[sl, sl] += ke
                m[sl, sl] += me
        free = slice(6, None)  # clamped at node 0
        w2 = la.eigh(k[free, free], m[free, free], eigvals_only=True)
        bending = np.sqrt(w2[w2 > 0])
        # the bending modes come in pairs (y and z): take one of each pair
        pairs = bending[::2][:3]
        errors.append(np.abs(pairs / exact - 1))
    assert errors[-1].max() < 1e-5
    assert np.all(errors[-1] <= errors[0])  # converging with s


# ------------------------------------------------------------------ springs in the machine

def test_springs_a_billion_times_stiffer_are_the_rigid_joints(paper):
    m = paper.manipulator
    for pose in (paper.cases["case1"].pose, paper.cases["case2"].pose):
        rigid = natural_frequencies(m, pose, TIMOSHENKO)
        stiff = natural_frequencies(replace(m, stiffness=ACTUATOR.scaled(1e9)), pose,
                                    TIMOSHENKO)
        assert np.abs(stiff / rigid - 1).max() < 1e-6
        rigid = natural_frequencies(stepped(m), pose, TIMOSHENKO)
        stiff = natural_frequencies(stepped(replace(m, stiffness=ACTUATOR.scaled(1e9))), pose,
                                    TIMOSHENKO)
        assert np.abs(stiff / rigid - 1).max() < 1e-6


@pytest.mark.parametrize("name", ["actuator_axial", "base_joint_translational",
                                  "base_joint_rotational", "platform_joint_translational"])
def test_softening_a_spring_never_raises_a_frequency(paper, name):
    m = stepped(replace(paper.manipulator, payload=Payload(35.0, (0.0, 0.0, 0.12),
                                                           (0.4, 0.4, 0.25))))
    pose = paper.cases["case2"].pose
    previous = None
    for factor in (100.0, 10.0, 1.0, 0.1, 0.01):
        f = natural_frequencies(replace(m, stiffness=ACTUATOR.scaled(factor, {name})), pose,
                                TIMOSHENKO)
        if previous is not None:
            assert np.all(f <= previous * (1 + 1e-12))
        previous = f


def test_a_joint_spring_is_isotropic_in_translation_and_free_about_an_r_axis():
    axis = np.array([0.6, 0.8, 0.0])
    k = joint_spring_matrix("R", axis, 3.0, 5.0)
    assert np.allclose(k[:3, :3], 3.0 * np.eye(3)) and np.allclose(k[3:, 3:] @ axis, 0.0)
    normal = np.array([0.8, -0.6, 0.0])
    assert normal @ k[3:, 3:] @ normal == pytest.approx(5.0)
    assert not joint_spring_matrix("S", None, 3.0, 0.0)[3:, 3:].any()


def rigid_mechanism_frequencies(m, pose, k_axial):
    """The 3-RPS (R at the base, S on the platform) with rigid legs, ideal joints and an
    axial spring of stiffness k_axial[i] in every leg: the platform's twist xi = (v_o, w)
    about o moves each A_i by J_i xi, J_i = [I, -[r_i x]], r_i = A_i - o. The R joint holds A_i
    in the leg's plane, a_i . J_i xi = 0 (three constraints: xi = N eta); the leg turns about
    a_i at omega_i = (a_i x e_i) . J_i xi / L_i and its sliding part moves along e_i at
    delta_i' = e_i . J_i xi, the spring's stretch. Kinetic energy: the platform and payload,
    each housing turning about a_i through B_i, each rod turning and sliding (for a uniform
    leg the whole leg slides, its spring at the base joint). Returns the three frequencies, Hz.
    """
    g = pose_geometry(m, pose)
    rho = m.material.density
    mass = rigid_mass_matrix(plate_mass(m.platform_shape, m.platform_radius,
                                        m.platform_thickness, rho),
                             plate_inertia(m.platform_shape, m.platform_radius,
                                           m.platform_thickness, rho), g.rotation) \
        + payload_mass_matrix(m.payload, g.rotation)
    stiffness = np.zeros((6, 6))
    constraints = []
    for i in range(3):
        r = g.platform_points[i] - g.platform_centre
        jac = np.hstack([np.eye(3), -skew(r)])
        e, a, length = g.leg_frames[i][:, 0], g.joint_axes[i], g.leg_lengths[i]
        constraints.append(a @ jac)
        slide, turn = e @ jac, np.cross(a, e) @ jac / length
        # every part of the leg: (start, end, outer, inner); the sliding part's mass
        turning, sliding = 0.0, 0.0
        for part in m.leg_parts(length):
            area = math.pi * (part.outer**2 - part.inner**2) / 4
            mp = rho * area * part.length
            centre = 0.5 * (part.start + part.end)
            across = mp * (part.length**2 / 12 + (part.outer**2 + part.inner**2) / 16)
            turning += across + mp * centre**2  # about a_i through B_i
            if part.name in ("rod", "leg"):
                sliding += mp
        mass += turning * np.outer(turn, turn) + sliding * np.outer(slide, slide)
        stiffness += k_axial[i] * np.outer(slide, slide)
    basis = la.null_space(np.array(constraints))
    w2 = la.eigh(basis.T @ stiffness @ basis, basis.T @ mass @ basis, eigvals_only=True)
    return np.sqrt(w2) / (2 * math.pi)


@pytest.mark.parametrize("profile", [LegProfile(), TUBES], ids=["uniform", "tubes"])
def test_a_soft_drive_leaves_the_rigid_mechanism_on_three_axial_springs(paper, profile):
    base = replace(paper.manipulator, payload=Payload(35.0, (0.02, 0.0, 0.12), (0.4, 0.4, 0.25)))
    m = stepped(base, profile) if profile.stepped else base
    pose = paper.cases["case2"].pose
    g = pose_geometry(m, pose)
    e_mod = m.material.youngs_modulus
    gaps = []
    for k_a in (1e6, 1e5):  # N/m, against legs of order 1e9 N/m axially
        legs = [sum(p.length / (e_mod * math.pi * (p.outer**2 - p.inner**2) / 4)
                    for p in m.leg_parts(length)) for length in g.leg_lengths]
        k_eff = [1.0 / (1.0 / k_a + c) for c in legs]
        expected = rigid_mechanism_frequencies(m, pose, k_eff)
        model = natural_frequencies(replace(m, stiffness=Stiffness(actuator_axial=k_a)), pose,
                                    TIMOSHENKO)[:3]
        gaps.append(np.abs(model / expected - 1).max())
    # the legs' own compliance and inertia perturb the mechanism by O(k_a / k_leg); the gap
    # falls with k_a as that ratio
    assert gaps[-1] < 2e-3 and gaps[-1] < gaps[0]


@pytest.mark.parametrize("order", [("R", "S"), ("S", "R")])
def test_the_batched_model_is_the_per_pose_model_with_springs_and_tubes(paper, order):
    springs = Stiffness(250e6, 800e6, 2e6 if order[0] == "R" else 0.0, 600e6,
                        3e6 if order[1] == "R" else 0.0)
    m = stepped(replace(paper.manipulator, base_joint=order[0], platform_joint=order[1],
                        stiffness=springs))
    options = ModelOptions(elements=3, beam="timoshenko", modes=8)
    phis, tilts = np.array([0.0, 0.4, 2.0]), np.array([0.0, 0.15, 0.25])
    height = paper.cases["case1"].pose.height
    poses = pose_batch(m, height, phis, tilts)
    batch = batch_frequencies(standard_form(assemble_batch(m, poses, options)), 8)
    for k in range(len(phis)):
        single = natural_frequencies(m, Pose(height, phis[k], tilts[k]), options)
        assert np.abs(batch[k] / single - 1).max() < 1e-10


# ------------------------------------------------------------------ the scene's keys

def _scene(paper, **tables):
    import tomllib
    raw = tomllib.loads(PAPER_SCENE.read_text())
    for name, table in tables.items():
        if name == "manipulator":
            raw["manipulator"].update(table)
        else:
            raw[name] = table
    return raw


LEG = {"housing_length_mm": 250.0, "housing_outer_diameter_mm": 100.0,
       "housing_inner_diameter_mm": 70.0, "rod_outer_diameter_mm": 60.0,
       "rod_inner_diameter_mm": 30.0}


def test_a_scene_with_every_key_reads_in_si(paper):
    raw = _scene(paper, leg=LEG, stiffness={"actuator_axial_n_per_um": 250.0,
                                            "base_joint_translational_n_per_um": 800.0,
                                            "base_joint_rotational_nm_per_urad": 2.0,
                                            "platform_joint_translational_n_per_um": 600.0})
    del raw["manipulator"]["leg_diameter_mm"]
    raw["manipulator"]["actuator_min_mm"] = 330.0  # 80 mm of rod (>= 1.2 x 60) out of 250 mm
    m = parse_scene(raw).manipulator
    assert m.leg == TUBES and m.leg_diameter == pytest.approx(0.1)
    assert m.stiffness == ACTUATOR


@pytest.mark.parametrize("change, words", [
    ({"leg": LEG}, "leave leg_diameter_mm out"),
    ({"leg": dict(LEG, housing_inner_diameter_mm=99.5), "drop": True}, "thinner than 1 mm"),
    ({"leg": dict(LEG, housing_length_mm=190.0), "drop": True}, "shortest leg leaves a rod"),
    ({"leg": {"rod_outer_diameter_mm": 60.0}}, "needs the housing's length"),
    ({"stiffness": {"platform_joint_rotational_nm_per_urad": 2.0}}, "constrains no rotation"),
    ({"stiffness": {"actuator_axial_n_per_um": 1e-6}}, "at least 0.001 N/um"),
    ({"stiffness": {"actuator_axial_n_per_um": -1.0}}, "must be >= 0"),
])
def test_an_impossible_leg_or_spring_is_refused_in_one_line(paper, change, words):
    change = dict(change)
    drop = change.pop("drop", False)
    raw = _scene(paper, **change)
    if drop:
        del raw["manipulator"]["leg_diameter_mm"]
    with pytest.raises(InputError) as info:
        parse_scene(raw)
    assert words in str(info.value) and "\n" not in str(info.value)
