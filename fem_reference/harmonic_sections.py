"""The section harmonics n >= 2 of the legs: never coupled to a joint, checked to lie above.

Harmonic n >= 2 of a leg is a set of modes of that leg alone (faces held for a rigid coupling,
free for a distributing one; `harmonic.py`'s docstring). The solver leaves harmonic n out when
none of its modes lies below the range solved for: counted by the inertia of K - mu M (a few
ms a leg), or by its lowest mode where that count is not available.
"""
from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from .eigen import lowest_modes
from .meridian import leg_data


def section_blocks(manipulator, geometry, size: float, coupling: str, n: int):
    """(K, M) of harmonic n >= 2 of each leg alone, faces held (rigid coupling) or free
    (distributing), the axis regular; both families share them. Rigid: the longest leg only
    (faces held, a longer leg's admissible fields hold a shorter one's: its modes are lower,
    min-max)."""
    legs = leg_data(manipulator, geometry, size, (n,),
                    longest_only=coupling == "rigid")
    for leg, _ in legs:
        k, m = leg.stiffness[n], leg.mass
        fixed = [3 * leg.axis_nodes[:, None] + np.arange(3)]
        if coupling == "rigid":
            fixed += [3 * f[:, None] + np.arange(3) for f in leg.face_nodes]
        free = np.setdiff1d(np.arange(k.shape[0]), np.concatenate(fixed).ravel())
        yield k[free][:, free], m[free][:, free]


def lowest_leg_harmonic(manipulator, geometry, size: float, coupling: str, n: int) -> float:
    """Lowest frequency (Hz) of harmonic n >= 2 over the legs (`section_blocks`)."""
    lowest = math.inf
    for k, m in section_blocks(manipulator, geometry, size, coupling, n):
        w = lowest_modes(k, m, 1, extra=1).eigenvalues
        lowest = min(lowest, math.sqrt(max(float(w[0]), 0.0)) / (2 * math.pi))
    return lowest


def modes_below(k: sp.spmatrix, m: sp.spmatrix, frequency_hz: float) -> int | None:
    """How many eigenvalues of (K, M) lie below (2 pi f)^2, by Sylvester's law of inertia: the
    negative pivots of K - mu M factorised with symmetric (diagonal) pivots, LDL^T. None when
    SuperLU had to pivot off the diagonal (then the count is not the inertia)."""
    mu = (2 * math.pi * frequency_hz) ** 2
    lu = sla.splu(sp.csc_matrix(k - mu * m), permc_spec="MMD_AT_PLUS_A",
                  diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    if not np.array_equal(lu.perm_r, lu.perm_c):
        return None
    return int(np.count_nonzero(lu.U.diagonal() < 0))


def section_modes_above(manipulator, geometry, size: float, coupling: str, n: int,
                        frequency_hz: float) -> bool:
    """Does harmonic n >= 2 of every leg have no mode below `frequency_hz`? Counted by
    inertia (a few ms a leg; ARPACK crawls in the dense band of section modes of a long leg),
    or by its lowest mode where the inertia count is not available."""
    for k, m in section_blocks(manipulator, geometry, size, coupling, n):
        count = modes_below(k, m, frequency_hz)
        if count is None:
            w = lowest_modes(k, m, 1, extra=1).eigenvalues[0]
            count = int(w < (2 * math.pi * frequency_hz) ** 2)
        if count:
            return False
    return True
