"""fem_reference.constraints: the joint map u = T q (paper Eqs. 10, 14-17) on a coarse mesh."""
from __future__ import annotations

import numpy as np
import pytest

from analytical.kinematics import pose_geometry
from common.rigid_body import skew
from fem_reference.constraints import build_constraints
from fem_reference.discretisation import discretise
from meshing import MeshSettings, build_mesh, pose_assembly

SIZE = 0.045


@pytest.fixture(scope="module", params=["case1", "case2"])
def pose(request, scene):
    geom = pose_geometry(scene.manipulator, scene.case(request.param).pose)
    disc = discretise(build_mesh(pose_assembly(scene.manipulator, geom), MeshSettings(SIZE)))
    return geom, disc


def rigid_fit(x, u, ref):
    """Least-squares rigid motion (t, theta) about ref of displacements u at points x."""
    r = x - ref
    a = np.zeros((len(x), 3, 6))
    a[:, :, :3] = np.eye(3)
    a[:, :, 3:] = -skew(r)
    sol, *_ = np.linalg.lstsq(a.reshape(-1, 6), u.ravel(), rcond=None)
    return sol[:3], sol[3:], np.abs(a.reshape(-1, 6) @ sol - u.ravel()).max()


def test_rigid_coupling_moves_every_joint_face_rigidly_with_its_joint(pose):
    geom, disc = pose
    cmap = build_constraints(disc, geom, "rigid", "rigid")
    q = np.random.default_rng(3).standard_normal(cmap.n_free)
    u = (cmap.T @ q).reshape(-1, 3)
    plat = q[cmap.columns["platform"]]
    for i in range(3):
        nodes = disc.face_nodes[f"leg{i + 1}_base"]
        t, theta, resid = rigid_fit(disc.node_xyz[nodes], u[nodes], geom.base_points[i])
        phi = q[cmap.columns["phi"][i]]
        assert resid < 1e-12  # face nodes follow the reference point rigidly (RBE2)
        np.testing.assert_allclose(t, 0.0, atol=1e-12)  # Eq. (16): Delta_B = 0
        np.testing.assert_allclose(theta, phi * geom.joint_axes[i], atol=1e-12)  # Eq. (17)
        nodes = disc.face_nodes[f"leg{i + 1}_top"]
        t, theta, resid = rigid_fit(disc.node_xyz[nodes], u[nodes], geom.platform_points[i])
        arm = geom.platform_points[i] - geom.platform_centre
        assert resid < 1e-12
        np.testing.assert_allclose(t, plat[:3] + np.cross(plat[3:], arm), atol=1e-12)  # Eq. (10)
        np.testing.assert_allclose(theta, q[cmap.columns["psi"][3 * i:3 * i + 3]], atol=1e-12)
    # every other node is its own coordinate
    free = np.setdiff1d(np.arange(disc.n_nodes), np.concatenate(list(disc.face_nodes.values())))
    np.testing.assert_array_equal(u.ravel()[3 * free], q[:len(cmap.retained)][
        np.searchsorted(cmap.retained, 3 * free)])


def test_distributing_coupling_constrains_the_face_average(pose):
    geom, disc = pose
    cmap = build_constraints(disc, geom, "distributing", "rigid")
    q = np.random.default_rng(4).standard_normal(cmap.n_free)
    u = cmap.T @ q
    plat = q[cmap.columns["platform"]]
    warped = 0.0
    for i in range(3):
        a = cmap.reference_motion(f"leg{i + 1}_base", u)
        np.testing.assert_allclose(a[:3], 0.0, atol=1e-10)
        axis = geom.joint_axes[i]
        np.testing.assert_allclose(a[3:] - axis * (axis @ a[3:]), 0.0, atol=1e-10)
        a = cmap.reference_motion(f"leg{i + 1}_top", u)
        arm = geom.platform_points[i] - geom.platform_centre
        np.testing.assert_allclose(a[:3], plat[:3] + np.cross(plat[3:], arm), atol=1e-10)
        nodes = disc.face_nodes[f"leg{i + 1}_top"]
        warped = max(warped, rigid_fit(disc.node_xyz[nodes], u.reshape(-1, 3)[nodes],
                                       geom.platform_points[i])[2])
    assert warped > 1e-3  # the face itself is free to deform (RBE3, not RBE2)
    n_face = sum(len(v) for v in disc.face_nodes.values())
    assert cmap.n_free == disc.n_dofs - 3 * (5 + 3) + 6  # 5 + 3 equations eliminated per leg
    assert n_face > 0


def test_projection_reproduces_rigid_motions_exactly(pose):
    geom, disc = pose
    cmap = build_constraints(disc, geom, "rigid", "rigid")
    rng = np.random.default_rng(5)
    for face, ref in cmap.references.items():
        t, theta = rng.standard_normal(3), rng.standard_normal(3)
        u = np.tile(t, (disc.n_nodes, 1)) + np.cross(theta, disc.node_xyz - ref)
        a = cmap.reference_motion(face, u.ravel())
        np.testing.assert_allclose(a, np.concatenate([t, theta]), atol=1e-10)


def test_rigid_coupling_coordinate_count(pose):
    geom, disc = pose
    cmap = build_constraints(disc, geom, "rigid", "rigid")
    n_face = sum(len(v) for v in disc.face_nodes.values())
    assert cmap.n_free == disc.n_dofs - 3 * n_face + 3 * 1 + 3 * 3 + 6
    assert cmap.T.shape == (disc.n_dofs, cmap.n_free)
