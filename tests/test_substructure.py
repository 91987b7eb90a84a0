"""Substructure synthesis and modal solve: invariances, symmetry, scaling, regularity."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from analytical.kinematics import pose_geometry
from analytical.modal import ModalError, leg_displacements, platform_motion
from analytical.model import analyse, natural_frequencies
from analytical.params import Material, ModelOptions, Pose
from analytical.substructure import SingularJointMap, assemble

CASE2 = Pose(0.5436, math.radians(10), math.radians(-12))
THEORIES = ["euler-bernoulli", "timoshenko"]


def test_reduced_model_has_18s_coordinates_and_is_positive_definite(manipulator):
    for s in (1, 3, 6):
        model = assemble(manipulator, pose_geometry(manipulator, CASE2), ModelOptions(elements=s))
        assert model.stiffness.shape == (18 * s, 18 * s)  # Eq. (19)
        for mat in (model.stiffness, model.mass):
            assert np.abs(mat - mat.T).max() <= 1e-13 * np.abs(mat).max()
        assert np.linalg.eigvalsh(model.stiffness).min() > 0  # no mechanism left
        assert np.linalg.eigvalsh(model.mass).min() > 0


@pytest.mark.parametrize("beam", THEORIES)
def test_symmetric_pose_has_repeated_pairs(manipulator, beam):
    f = natural_frequencies(manipulator, Pose(0.5436), ModelOptions(beam=beam, modes=6))
    assert f[1] / f[0] - 1 < 1e-6
    assert f[5] / f[4] - 1 < 1e-6
    assert f[2] / f[1] - 1 > 0.1 and f[3] / f[2] - 1 > 0.1 and f[4] / f[3] - 1 > 0.01
    assert np.all(np.diff(f) >= 0)


@pytest.mark.parametrize("beam", THEORIES)
def test_rigid_rotation_of_the_whole_manipulator_leaves_frequencies_unchanged(manipulator, beam):
    opts = ModelOptions(beam=beam, elements=4, modes=10)
    geom = pose_geometry(manipulator, CASE2)
    reference = analyse(manipulator, CASE2, opts).frequencies_hz
    for seed in range(3):
        turn = Rotation.random(random_state=seed).as_matrix()
        moved = geom.transformed(turn, translation=[0.3, -1.0, 2.0])
        f = analyse(manipulator, CASE2, opts, geometry=moved).frequencies_hz
        assert f == pytest.approx(reference, rel=1e-9)


def test_turning_the_leg_layout_about_z_leaves_frequencies_unchanged(manipulator):
    """The same mechanism turned by gamma is posed at azimuth phi + gamma (Eqs. 1-2)."""
    reference = natural_frequencies(manipulator, CASE2)
    for gamma in (0.3, 1.0, math.pi / 2, 2.5):
        turned = replace(manipulator,
                         leg_angles=tuple(gamma + k * 2 * math.pi / 3 for k in range(3)))
        pose = replace(CASE2, azimuth=CASE2.azimuth + gamma)
        assert natural_frequencies(turned, pose) == pytest.approx(reference, rel=1e-9)


def test_paper_eq18_coordinate_diverges_where_the_axis_coordinate_stays_regular(manipulator):
    """Eq. (18)'s ratio R_i(1,2)/R_i(2,2) is singular when an R-joint axis lies along x."""
    paper = ModelOptions(r_joint_coordinate="paper-eq18")
    ours = ModelOptions(r_joint_coordinate="axis")
    reference = natural_frequencies(manipulator, CASE2, ours)
    # Elsewhere both forms span the same motions: identical frequencies.
    assert natural_frequencies(manipulator, CASE2, paper) == pytest.approx(reference, rel=1e-9)
    # Leg 1 at 90 degrees puts its joint axis on -x: Eq. (18) divides by zero.
    conditions = []
    for eps in (1e-2, 1e-4, 1e-6):
        gamma = math.pi / 2 + eps
        turned = replace(manipulator,
                         leg_angles=tuple(gamma + k * 2 * math.pi / 3 for k in range(3)))
        pose = replace(CASE2, azimuth=CASE2.azimuth + gamma)
        geom = pose_geometry(turned, pose)
        f_ours = natural_frequencies(turned, pose, ours)
        assert f_ours == pytest.approx(reference, rel=1e-9)
        conditions.append(np.linalg.cond(assemble(turned, geom, paper).mass))
        assert np.linalg.cond(assemble(turned, geom, ours).mass) < 1e8
    assert conditions[1] > 1e3 * conditions[0] and conditions[2] > 1e3 * conditions[1]
    # Exactly on the singular layout (an exact quarter turn, so axis_y is exactly 0):
    quarter = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    geom = pose_geometry(manipulator, CASE2).transformed(quarter)
    assert geom.joint_axes[0] @ [0.0, 1.0, 0.0] == 0.0
    with pytest.raises(SingularJointMap, match=r"R_i\(2,2\) = 0"):
        analyse(manipulator, CASE2, paper, geometry=geom)
    assert analyse(manipulator, CASE2, ours, geometry=geom).frequencies_hz == pytest.approx(
        reference, rel=1e-9)


@pytest.mark.parametrize("beam", THEORIES)
def test_scaling_laws(manipulator, beam):
    opts = ModelOptions(beam=beam)
    f0 = natural_frequencies(manipulator, CASE2, opts)
    k = 1.7
    scaled = manipulator.scaled(k)
    f_len = natural_frequencies(scaled, replace(CASE2, height=CASE2.height * k), opts)
    assert f_len == pytest.approx(f0 / k, rel=1e-9)
    mat = manipulator.material
    stiff = replace(manipulator, material=Material(mat.youngs_modulus * k,
                                                   mat.shear_modulus * k, mat.density))
    assert natural_frequencies(stiff, CASE2, opts) == pytest.approx(f0 * math.sqrt(k), rel=1e-9)
    heavy = replace(manipulator, material=replace(mat, density=mat.density * k))
    assert natural_frequencies(heavy, CASE2, opts) == pytest.approx(f0 / math.sqrt(k), rel=1e-9)


def test_convergence_in_elements_is_monotone_from_above(manipulator):
    """Consistent-mass Hermite beams converge from above as s grows (the paper's Fig. 3)."""
    freqs = np.array([natural_frequencies(manipulator, CASE2, ModelOptions(elements=s))
                      for s in range(1, 11)])
    assert np.all(np.diff(freqs, axis=0) <= 1e-9 * freqs[1:])
    assert np.abs(freqs[-2] / freqs[-1] - 1).max() < 1e-4


def test_timoshenko_is_softer_than_euler_bernoulli(manipulator):
    eb = natural_frequencies(manipulator, CASE2, ModelOptions(beam="euler-bernoulli"))
    ti = natural_frequencies(manipulator, CASE2, ModelOptions(beam="timoshenko"))
    assert np.all(ti < eb)


def test_mode_shapes_expand_consistently_with_the_joints(manipulator):
    res = analyse(manipulator, CASE2, ModelOptions(elements=3, modes=6))
    legs = leg_displacements(res.model, res.modal.shapes)
    plat = platform_motion(res.model, res.modal.shapes)
    g = res.geometry
    assert np.allclose(legs[:, 0, :3, :], 0)  # R joint: B_i does not move
    for i in range(3):  # R joint: base rotation only about the joint axis
        rot = legs[i, 0, 3:, :]
        assert np.allclose(rot - np.outer(g.joint_axes[i], g.joint_axes[i] @ rot), 0,
                           atol=1e-12)
        arm = g.platform_points[i] - g.platform_centre
        expected = plat[:3] + np.cross(plat[3:].T, arm).T  # S joint, Eq. (10)
        assert np.allclose(legs[i, -1, :3, :], expected)
    # mass normalisation: Phi^T M Phi = I
    assert np.allclose(res.modal.shapes.T @ res.model.mass @ res.modal.shapes, np.eye(6))


def test_too_many_modes_is_refused(manipulator):
    with pytest.raises(ModalError, match="modes = 19"):
        natural_frequencies(manipulator, CASE2, ModelOptions(elements=1, modes=19))


@pytest.mark.parametrize("field, value", [("elements", 0), ("beam", "bernoulli"),
                                          ("modes", 0), ("platform_inertia", "cube")])
def test_invalid_model_options_name_the_value(field, value):
    with pytest.raises(ValueError, match=repr(value)):
        ModelOptions(**{field: value})


def test_axis_interpolation_hits_the_nodes_and_is_smooth(manipulator):
    from analytical.modal import leg_axis_displacements
    res = analyse(manipulator, CASE2, ModelOptions(elements=3, modes=6))
    nodal = leg_displacements(res.model, res.modal.shapes)[:, :, :3, :]
    at_nodes = leg_axis_displacements(res.model, res.geometry.leg_frames, res.modal.shapes,
                                      np.linspace(0, 1, 4))
    assert np.allclose(at_nodes, nodal, atol=1e-12)
    # a finer model's nodes lie on the coarse model's interpolated field, to discretisation error
    fine = analyse(manipulator, CASE2, ModelOptions(elements=12, modes=1))
    t = np.linspace(0, 1, 13)
    coarse_f = leg_axis_displacements(res.model, res.geometry.leg_frames,
                                      res.modal.shapes[:, :1], t)
    fine_f = leg_axis_displacements(fine.model, fine.geometry.leg_frames, fine.modal.shapes, t)
    sign = np.sign(np.sum(coarse_f * fine_f))
    assert np.abs(coarse_f - sign * fine_f).max() < 0.02 * np.abs(fine_f).max()


@pytest.mark.parametrize("beam", THEORIES)
def test_section2_joint_order_keeps_symmetry_invariance_and_18s_coordinates(manipulator, beam):
    """S at the base, R at the platform: the same coordinate count (Eq. 19), repeated pairs at
    the symmetric pose, frequencies unchanged by a rigid motion of the whole manipulator."""
    m = replace(manipulator, base_joint="S", platform_joint="R")
    f = natural_frequencies(m, Pose(0.5436), ModelOptions(beam=beam, modes=6))
    assert f[1] / f[0] - 1 < 1e-6 and f[5] / f[4] - 1 < 1e-6
    opts = ModelOptions(beam=beam, elements=4, modes=10)
    geom = pose_geometry(m, CASE2)
    model = assemble(m, geom, opts)
    assert model.stiffness.shape == (72, 72)
    assert np.linalg.eigvalsh(model.stiffness).min() > 0
    reference = analyse(m, CASE2, opts).frequencies_hz
    turn = Rotation.from_rotvec([0.3, -1.1, 0.4]).as_matrix()
    moved = analyse(m, CASE2, opts, geometry=geom.transformed(turn, (0.2, -0.1, 0.3)))
    np.testing.assert_allclose(moved.frequencies_hz, reference, rtol=1e-9)


def test_section2_r_joint_turns_with_the_platform(manipulator):
    """The leg top at an R joint on the platform rotates as the platform plus phi about the
    platform-fixed axis; the leg bottom at an S joint stays in place and rotates freely."""
    m = replace(manipulator, base_joint="S", platform_joint="R")
    geom = pose_geometry(m, CASE2)
    res = analyse(m, CASE2, ModelOptions(elements=3, modes=6))
    nodal = leg_displacements(res.model, res.modal.shapes)  # (3, s+1, 6, n)
    plat = platform_motion(res.model, res.modal.shapes)
    for i in range(3):
        np.testing.assert_allclose(nodal[i, 0, :3], 0.0, atol=1e-12)
        arm = geom.platform_points[i] - geom.platform_centre
        np.testing.assert_allclose(nodal[i, -1, :3], plat[:3] + np.cross(plat[3:].T, arm).T,
                                   atol=1e-12)
        relative = nodal[i, -1, 3:] - plat[3:]
        axis = geom.joint_axes[i]
        np.testing.assert_allclose(relative - np.outer(axis, axis @ relative), 0.0,
                                   atol=1e-12)
