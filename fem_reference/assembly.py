"""Linear-elastic stiffness and consistent mass of the solid bodies (vector P2 tetrahedra).

K = int sigma(u) : eps(v) dV with the isotropic Hooke law (Lame parameters from E and
nu = E / 2G - 1), M = int rho u . v dV, assembled once per mesh over all bodies (which share no
node: the matrices are block diagonal by body until the joint constraints couple them).

scikit-fem supplies the isoparametric P2 element on the curved mesh: shape-function gradients and
the weights |det J| w_q at the quadrature points (`Basis`). The 30 x 30 element matrices are then
contracted in one vectorised einsum over all elements instead of scikit-fem's loop over the 900
basis-function pairs of `asm` (same integrals, ~20x faster here), and summed into CSR.
"""
from __future__ import annotations

from typing import Protocol

import numpy as np
import scipy.sparse as sp

from .discretisation import Discretisation


class Material(Protocol):
    """What the solid needs of an isotropic material (any record with these fields, e.g.
    `analytical.params.Material`, the one declaration of the scene's material): E, G, rho in
    SI. The FEM reads the values only (read-only members: a frozen dataclass or a NamedTuple
    such as `joint_ends.zone.Solid` qualifies); nu = E / 2G - 1."""

    @property
    def youngs_modulus(self) -> float: ...  # Pa

    @property
    def shear_modulus(self) -> float: ...  # Pa

    @property
    def density(self) -> float: ...  # kg/m^3


def lame(material: Material) -> tuple[float, float]:
    """(lambda, mu) from E and nu = E / 2G - 1."""
    e = material.youngs_modulus
    nu = e / (2.0 * material.shear_modulus) - 1.0
    return e * nu / ((1 + nu) * (1 - 2 * nu)), e / (2 * (1 + nu))


def _element_arrays(disc: Discretisation):
    b = disc.basis
    grads = np.stack([phi[0].grad for phi in b.basis], axis=0)  # (10, 3, ne, nq)
    values = np.stack([np.asarray(phi[0]) for phi in b.basis], axis=0)  # (10, ne, nq)
    return grads, values, b.dx, b.element_dofs  # dx: (ne, nq) = |det J| w_q


def _scalar_pattern(element_dofs: np.ndarray, n: int):
    """CSR pattern of the scalar P2 matrices and, for every element entry (e, a, b), the
    position of its (row, column) in that pattern."""
    ed = element_dofs.T.astype(np.int64)  # (ne, 10)
    keys = (ed[:, :, None] * n + ed[:, None, :]).ravel()
    unique, position = np.unique(keys, return_inverse=True)
    rows, cols = np.divmod(unique, n)
    indptr = np.searchsorted(rows, np.arange(n + 1))
    return indptr, cols, position


def stiffness_and_mass(disc: Discretisation, material: Material) -> tuple[sp.csr_matrix,
                                                                           sp.csr_matrix]:
    """(K, M) on dofs 3 s + c (node-major), CSR, symmetric.

    Both matrices share the scalar P2 pattern with a 3 x 3 block per node pair, so they are
    built as block sparse (BSR) from per-component scalar sums and converted to CSR.
    """
    lam, mu = lame(material)
    grads, values, dx, edofs = _element_arrays(disc)
    ne, nq = dx.shape
    n = disc.n_nodes
    g = np.ascontiguousarray(grads.transpose(2, 3, 0, 1)).reshape(ne, nq, 30)  # (e, q, a i)
    # p[e, a i, b j] = int d_i N_a d_j N_b dV
    p = np.matmul((g * dx[:, :, None]).transpose(0, 2, 1), g).reshape(ne, 10, 3, 10, 3)
    lap = np.einsum("eakbk->eab", p)
    indptr, indices, position = _scalar_pattern(edofs, n)
    nnz = len(indices)
    blocks = np.empty((nnz, 3, 3))
    for i in range(3):
        for j in range(3):
            kij = lam * p[:, :, i, :, j] + mu * p[:, :, j, :, i]
            if i == j:
                kij = kij + mu * lap
            blocks[:, i, j] = np.bincount(position, kij.ravel(), minlength=nnz)
    k = sp.bsr_matrix((blocks, indices, indptr), shape=(3 * n, 3 * n)).tocsr()
    v = values.transpose(1, 2, 0)  # (e, q, a)
    ms = material.density * np.matmul((v * dx[:, :, None]).transpose(0, 2, 1), v)
    mdata = np.bincount(position, ms.ravel(), minlength=nnz)
    m = sp.bsr_matrix((mdata[:, None, None] * np.eye(3)[None], indices, indptr),
                      shape=(3 * n, 3 * n)).tocsr()
    return k, m
