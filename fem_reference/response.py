"""The solid's direct frequency response at the tool point: the damped system
(K_q - w^2 M_q + i w C) x = A^T F solved at each frequency (sparse LU, no modal truncation),
C = alpha M_q + beta K_q (Rayleigh: the one damping a direct solve and a modal sum share
exactly), the tool point's rows A on the rigid platform's six coordinates (`common.frf`); and
its static compliance A K_q^-1 A^T. What the models' modal superposition is checked against.
"""
from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg

from common.frf import tool_rows

from .options import FemError


def tool_operator(result, point) -> sp.csr_matrix:
    """A (3, n_q): the tool point's displacement from a solve's coordinates (base frame)."""
    columns = getattr(result, "columns", None)
    if columns is None:
        constraints = getattr(result, "constraints", None)
        columns = getattr(constraints, "columns", {})
    platform = columns.get("platform") if isinstance(columns, dict) else None
    if platform is None:
        raise FemError("the tool point's response needs the rigid platform's coordinates "
                       "(platform = 'rigid')")
    if result.system is None:
        raise FemError("the tool point's response needs the solve's K_q and M_q: solve the "
                       "pose with keep_system=True")
    rows = tool_rows(point, np.asarray(result.geometry.rotation, float))
    n = result.system[0].shape[0]
    a = sp.lil_matrix((3, n))
    a[:, np.asarray(platform, int)] = rows
    return a.tocsr()


def static_compliance(result, a: sp.csr_matrix) -> tuple[np.ndarray, int]:
    """(3, 3) m/N: A K_q^-1 A^T by one sparse factorisation, and the factor's entries (what
    `check_direct_memory` reads)."""
    lu = scipy.sparse.linalg.splu(result.system[0].tocsc(), permc_spec="MMD_AT_PLUS_A")
    g = a @ lu.solve(a.T.toarray())
    return 0.5 * (g + g.T), int(lu.L.nnz + lu.U.nnz)


def check_direct_memory(result, factor_entries: int) -> None:
    """Before any complex factorisation: one of the same pattern as the real factor of K_q
    (`factor_entries`) holds twice its bytes, and pivoting adds fill (taken as three times
    in all); MemoryLimitError naming it if that exceeds the share a solve may take
    (resources.MEMORY_FRACTION of the memory available now)."""
    from .resources import MEMORY_FRACTION, MemoryLimitError, available_bytes

    need = 3.0 * 16.0 * factor_entries
    free = available_bytes()
    if free is not None and need > MEMORY_FRACTION * free:
        raise MemoryLimitError(f"the direct frequency response at {result.dofs} dofs needs "
                               f"about {need / 1e9:.3g} GB for its complex factor, above "
                               f"{MEMORY_FRACTION:g} of the {free / 1e9:.3g} GB available")


def direct_receptance(result, a: sp.csr_matrix, lines_hz, alpha: float, beta: float
                      ) -> np.ndarray:
    """(nf, 3, 3) complex m/N at each line: one complex factorisation of the damped dynamic
    stiffness a line, three right-hand sides."""
    k, m = (mat.tocsc() for mat in result.system)
    rhs = a.T.toarray().astype(complex)
    out = np.empty((len(np.atleast_1d(lines_hz)), 3, 3), complex)
    for i, f in enumerate(np.atleast_1d(np.asarray(lines_hz, float))):
        w = 2.0 * math.pi * f
        dynamic = (k * (1.0 + 1j * w * beta) + m * (1j * w * alpha - w * w)).tocsc()
        try:
            x = scipy.sparse.linalg.splu(dynamic, permc_spec="MMD_AT_PLUS_A").solve(rhs)
        except RuntimeError as exc:  # exactly at an undamped resonance
            raise FemError(f"direct response at {f:g} Hz: singular system ({exc})") from None
        out[i] = a @ x
    return out
