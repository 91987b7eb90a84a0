"""Evaluate the P2 displacement field at points inside one body (e.g. along a leg axis).

The containing element is searched among the body's elements only (bodies may overlap in space:
the plate and the leg tops), first by the affine barycentric test on candidates near the point,
then the isoparametric map is inverted by Newton iterations.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from common.errors import InputError

from .discretisation import Discretisation


def tet10_shape(x: np.ndarray):
    """P2 tetrahedron shape functions (meshio/skfem order) at reference points x (n, 3), and
    their derivatives: (n, 10), (n, 10, 3)."""
    xi, eta, zeta = x[:, 0], x[:, 1], x[:, 2]
    l = np.stack([1 - xi - eta - zeta, xi, eta, zeta], axis=1)  # barycentric (n, 4)
    dl = np.array([[-1, -1, -1], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)  # d L_a / d x
    edges = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)]
    n = np.empty((len(x), 10))
    dn = np.empty((len(x), 10, 3))
    for a in range(4):
        n[:, a] = l[:, a] * (2 * l[:, a] - 1)
        dn[:, a] = (4 * l[:, a] - 1)[:, None] * dl[a]
    for k, (a, b) in enumerate(edges):
        n[:, 4 + k] = 4 * l[:, a] * l[:, b]
        dn[:, 4 + k] = 4 * (l[:, b][:, None] * dl[a] + l[:, a][:, None] * dl[b])
    return n, dn


def locate(disc: Discretisation, body: str, points: np.ndarray, candidates: int = 48):
    """(cells, reference coordinates) of points (n, 3) inside `body`."""
    points = np.atleast_2d(np.asarray(points, float))
    elems = np.flatnonzero(disc.tet_body == disc.bodies.index(body))
    edofs = disc.basis.element_dofs[:, elems].T  # (ne_b, 10)
    verts = disc.node_xyz[edofs[:, :4]]  # (ne_b, 4, 3)
    tree = cKDTree(verts.mean(axis=1))
    cells = np.empty(len(points), np.int64)
    ref = np.empty((len(points), 3))
    for p, x in enumerate(points):  # few points: loop over points is cheap
        # nearest centroids first; widen the search where small elements crowd a large one
        # (the rim refinement next to a joint face)
        k = min(candidates, len(elems))
        while True:
            _, cs = tree.query(x, k=k)
            cs = np.atleast_1d(cs)
            v = verts[cs]
            jac = (v[:, 1:] - v[:, :1]).transpose(0, 2, 1)  # (k, 3, 3)
            lam = np.linalg.solve(jac, (x - v[:, 0])[:, :, None])[:, :, 0]
            bary = np.column_stack([1 - lam.sum(1), lam])
            best = int(np.argmax(bary.min(axis=1)))
            if bary[best].min() >= -1e-2 or k == len(elems):
                break
            k = min(4 * k, len(elems))
        if bary[best].min() < -1e-2:
            raise InputError(f"point {np.round(x, 6).tolist()} is not inside {body}")
        cells[p], ref[p] = cs[best], lam[best]
    # Newton on the isoparametric map x(X) = sum N_a(X) x_a
    nodes = disc.node_xyz[edofs[cells]]  # (n, 10, 3)
    for _ in range(8):
        n, dn = tet10_shape(ref)
        x = np.einsum("pa,pac->pc", n, nodes)
        jac = np.einsum("pac,pad->pcd", nodes, dn)
        step = np.linalg.solve(jac, (points - x)[:, :, None])[:, :, 0]
        ref += step
        if np.abs(step).max() < 1e-13:
            break
    return elems[cells], ref


def evaluate(disc: Discretisation, body: str, points: np.ndarray, fields: np.ndarray):
    """Displacements at points: fields (n_raw, m) with dofs 3 s + c -> (n_points, 3, m)."""
    cells, ref = locate(disc, body, points)
    n, _ = tet10_shape(ref)
    nodes = disc.basis.element_dofs[:, cells].T  # (n_points, 10)
    u = fields.reshape(disc.n_nodes, 3, -1)[nodes]  # (n_points, 10, 3, m)
    return np.einsum("pa,pacm->pcm", n, u)
