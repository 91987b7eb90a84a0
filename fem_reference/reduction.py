"""The joints' elimination applied: K_q = T^T K T, M_q = T^T M T, plus the rigid platform.

Shared by both leg discretisations (`tetrahedra.py`, `harmonic.py`), below them.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from common.payload import payload_mass_matrix
from meshing.geometry import GmshFailure

from .options import FemError, FemOptions
from .rigid_platform import meshed_plate_mass


def reduced_matrices(k, m, t, platform_cols, plate, manipulator, geometry,
                     options: FemOptions, springs: sp.spmatrix | None = None
                     ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """K_q = T^T K T and M_q = T^T M T (paper Eqs. 20-22), plus the rigid platform's 6x6 mass
    at o on its coordinates `platform_cols` (Eqs. 7-9, integrated over its own meshed plate,
    rigid_platform.py; None: an elastic plate, already in K and M) and the payload fixed to it
    (`common.payload`, the idealisation both models share), symmetric to round-off.
    T^T (K T) with T^T in CSR: both products row-major, half the time of (T^T K) T (which
    converts T^T from CSC on the way; measured 0.016 s against 0.035 s at 17k dofs).
    `springs`: the joint and drive springs' stiffness on q (`leg_points`), added to K_q; they
    have no mass."""
    t_rows = t.T.tocsr()
    kq = (t_rows @ (k @ t)).tocsr()
    if springs is not None:
        kq = kq + springs
    mq = (t_rows @ (m @ t)).tocsr()
    if platform_cols is not None:
        try:
            mp = sp.coo_matrix(meshed_plate_mass(
                plate, np.asarray(geometry.rotation), manipulator.material.density,
                options.platform_mesh * plate.radius))
        except GmshFailure as exc:
            raise FemError(f"platform_mesh = {options.platform_mesh:g}: gmsh failed on the "
                           f"platform plate ({exc})") from None
        mp = sp.coo_matrix(mp.toarray() + payload_mass_matrix(manipulator.payload,
                                                              geometry.rotation))
        mq = mq + sp.csr_matrix((mp.data, (platform_cols[mp.row], platform_cols[mp.col])),
                                shape=mq.shape)

    return 0.5 * (kq + kq.T), 0.5 * (mq + mq.T)
