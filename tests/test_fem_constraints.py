"""fem_reference.constraints: the joint map u = T q (paper Eqs. 10, 14-17) on a coarse mesh,
for both joint orders (R at the base and S at the platform as the paper's equations; S at the
base and R at the platform as its Section 2 text)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from analytical.kinematics import pose_geometry
from common.rigid_body import rigid_fit as fit_motion
from fem_reference.constraints import build_constraints
from fem_reference.discretisation import discretise
from meshing import MeshSettings, build_mesh, pose_assembly

SIZE = 0.045
RIM_ZONE = 0.015  # the paper machine's: 0.15 of its 100 mm legs
ORDERS = {"RPS": ("R", "S"), "SPR": ("S", "R")}


@pytest.fixture(scope="module", params=[("case1", "RPS"), ("case2", "RPS"), ("case2", "SPR")],
                ids=lambda p: "-".join(p))
def pose(request, scene):
    case, order = request.param
    base, top = ORDERS[order]
    m = replace(scene.manipulator, base_joint=base, platform_joint=top)
    geom = pose_geometry(m, scene.case(case).pose)
    assembly = pose_assembly(m, geom)
    disc = discretise(build_mesh(assembly, MeshSettings(SIZE, rim_zone=RIM_ZONE)))
    return geom, assembly, disc


def rigid_fit(x, u, ref):
    """Least-squares rigid motion (t, theta) about ref of displacements u at points x, and the
    largest residual."""
    sol = fit_motion(x, u, ref)
    r = x - ref
    resid = np.abs(sol[:3] + np.cross(sol[3:], r) - u).max()
    return sol[:3], sol[3:], resid


def expected_motion(geom, joint, q, cmap, leg):
    """(translation, rotation) the joint rules of Eqs. (10), (16)-(17) give its reference."""
    plat = q[cmap.columns["platform"]]
    if joint.body == "base":
        t, body_rotation = np.zeros(3), np.zeros(3)
    else:
        t = plat[:3] + np.cross(plat[3:], joint.centre - geom.platform_centre)
        body_rotation = plat[3:]
    if joint.type == "S":
        return t, q[cmap.columns["psi"][3 * leg:3 * leg + 3]]
    return t, body_rotation + q[cmap.columns["phi"][leg]] * joint.axis


def test_rigid_coupling_moves_every_joint_face_rigidly_with_its_joint(pose):
    geom, assembly, disc = pose
    cmap = build_constraints(disc, geom, assembly, "rigid", "rigid")
    q = np.random.default_rng(3).standard_normal(cmap.n_free)
    u = (cmap.T @ q).reshape(-1, 3)
    for i, leg in enumerate(assembly.cylinders):
        for face, joint in zip((leg.start_face, leg.end_face), geom.leg_joints(i)):
            nodes = disc.face_nodes[face]
            t, theta, resid = rigid_fit(disc.node_xyz[nodes], u[nodes], joint.centre)
            t_exp, theta_exp = expected_motion(geom, joint, q, cmap, i)
            assert resid < 1e-12  # face nodes follow the reference point rigidly (RBE2)
            np.testing.assert_allclose(t, t_exp, atol=1e-12)  # Eqs. (10), (16)
            np.testing.assert_allclose(theta, theta_exp, atol=1e-12)  # Eq. (17), free for S
    # every other node is its own coordinate
    free = np.setdiff1d(np.arange(disc.n_nodes), np.concatenate(list(disc.face_nodes.values())))
    np.testing.assert_array_equal(u.ravel()[3 * free], q[:len(cmap.retained)][
        np.searchsorted(cmap.retained, 3 * free)])


def test_distributing_coupling_constrains_the_face_average(pose):
    geom, assembly, disc = pose
    cmap = build_constraints(disc, geom, assembly, "distributing", "rigid")
    q = np.random.default_rng(4).standard_normal(cmap.n_free)
    u = cmap.T @ q
    plat = q[cmap.columns["platform"]]
    warped = 0.0
    for i, leg in enumerate(assembly.cylinders):
        for face, joint in zip((leg.start_face, leg.end_face), geom.leg_joints(i)):
            a = cmap.reference_motion(face, u)
            body_t, body_r = np.zeros(3), np.zeros(3)
            if joint.body == "platform":
                body_t = plat[:3] + np.cross(plat[3:], joint.centre - geom.platform_centre)
                body_r = plat[3:]
            np.testing.assert_allclose(a[:3], body_t, atol=1e-10)
            if joint.type == "R":  # only the rotation about the axis is free
                rel = a[3:] - body_r
                np.testing.assert_allclose(rel - joint.axis * (joint.axis @ rel), 0.0,
                                           atol=1e-10)
            nodes = disc.face_nodes[face]
            warped = max(warped, rigid_fit(disc.node_xyz[nodes], u.reshape(-1, 3)[nodes],
                                           joint.centre)[2])
    assert warped > 1e-3  # the faces themselves are free to deform (RBE3, not RBE2)
    assert cmap.n_free == disc.n_dofs - 3 * (5 + 3) + 6  # 5 + 3 equations eliminated per leg


def test_projection_reproduces_rigid_motions_exactly(pose):
    geom, assembly, disc = pose
    cmap = build_constraints(disc, geom, assembly, "rigid", "rigid")
    rng = np.random.default_rng(5)
    for face, ref in cmap.references.items():
        t, theta = rng.standard_normal(3), rng.standard_normal(3)
        u = np.tile(t, (disc.n_nodes, 1)) + np.cross(theta, disc.node_xyz - ref)
        a = cmap.reference_motion(face, u.ravel())
        np.testing.assert_allclose(a, np.concatenate([t, theta]), atol=1e-10)


def test_rigid_coupling_coordinate_count(pose):
    geom, assembly, disc = pose
    cmap = build_constraints(disc, geom, assembly, "rigid", "rigid")
    n_face = sum(len(v) for v in disc.face_nodes.values())
    assert cmap.n_free == disc.n_dofs - 3 * n_face + 3 * 1 + 3 * 3 + 6
    assert cmap.T.shape == (disc.n_dofs, cmap.n_free)
