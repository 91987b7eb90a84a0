"""Comparing mode shapes: the modal assurance criterion and groups of repeated frequencies.

Shared by everything that pairs or tracks modes (analytical vs FEM pairing, mode tracking over
the workspace), so both speak of the same MAC and the same clusters.
"""
from __future__ import annotations

import numpy as np


def mac_matrix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Modal assurance criterion |a_i . b_j|^2 / (|a_i|^2 |b_j|^2), shape (n_a, n_b); 0 against
    a shape that is zero at every station (a mode that leaves the stations still correlates
    with nothing there)."""
    num = np.abs(a.T @ b) ** 2
    den = np.outer(np.sum(a * a, axis=0), np.sum(b * b, axis=0))
    return np.divide(num, den, out=np.zeros(np.broadcast_shapes(num.shape, den.shape)),
                     where=den > 0.0)


def clusters(frequencies: np.ndarray, tolerance: float) -> list[list[int]]:
    """Groups of consecutive modes whose relative frequency gap is below `tolerance`."""
    groups = [[0]]
    for k in range(1, len(frequencies)):
        if frequencies[k] / frequencies[k - 1] - 1 < tolerance:
            groups[-1].append(k)
        else:
            groups.append([k])
    return groups
