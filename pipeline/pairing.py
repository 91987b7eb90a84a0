"""Pairing modes of two models by shape (MAC), with repeated modes compared as subspaces.

Shapes are sampled on shared points (stations along every leg axis, joint centres included):
each model supplies a matrix of (n_points * 3, n_modes) translations in base coordinates.
Within a cluster of (near-)repeated frequencies any rotation of the basis is an equally valid
set of modes, so such a cluster is paired as a whole: its quality is cos^2 of the largest
principal angle between the two subspaces (1 = identical subspaces), and its members are
paired in ascending order of frequency.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
from scipy.optimize import linear_sum_assignment


def mac_matrix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Modal assurance criterion |a_i . b_j|^2 / (|a_i|^2 |b_j|^2), shape (n_a, n_b)."""
    num = np.abs(a.T @ b) ** 2
    den = np.outer(np.sum(a * a, axis=0), np.sum(b * b, axis=0))
    return num / den


def clusters(frequencies: np.ndarray, tolerance: float) -> list[list[int]]:
    """Groups of consecutive modes whose relative frequency gap is below `tolerance`."""
    groups = [[0]]
    for k in range(1, len(frequencies)):
        if frequencies[k] / frequencies[k - 1] - 1 < tolerance:
            groups[-1].append(k)
        else:
            groups.append([k])
    return groups


@dataclass(frozen=True)
class Pair:
    reference_mode: int  # 0-based index in the reference (FEM) model
    model_mode: int  # 0-based index in the model under test (analytical)
    mac: float  # MAC, or cos^2 of the largest principal angle for a repeated group
    group: int  # index of the repeated-mode group (singletons have their own)
    repeated: bool

    def error_percent(self, f_model: np.ndarray, f_reference: np.ndarray) -> float:
        return 100.0 * (f_model[self.model_mode] / f_reference[self.reference_mode] - 1.0)


def pair_modes(model_shapes: np.ndarray, model_hz: np.ndarray, reference_shapes: np.ndarray,
               reference_hz: np.ndarray, count: int, repeat_tolerance: float = 0.02
               ) -> list[Pair]:
    """Pair the first `count` reference modes with modes of the model under test.

    The reference may carry more modes than `count` (so a pair split across the cut is still
    found); the model must carry at least `count`. Groups of near-repeated reference modes
    (relative gap < repeat_tolerance) are matched as subspaces to the model modes that the
    assignment gives them.
    """
    mac = mac_matrix(model_shapes, reference_shapes)
    n_ref = min(count, reference_shapes.shape[1])
    rows, cols = linear_sum_assignment(-mac[:, :n_ref])
    assigned = dict(zip(cols, rows))
    pairs: list[Pair] = []
    for g, group in enumerate(clusters(np.asarray(reference_hz[:n_ref]), repeat_tolerance)):
        if len(group) == 1:
            k = group[0]
            pairs.append(Pair(k, int(assigned[k]), float(mac[assigned[k], k]), g, False))
            continue
        model_modes = sorted(int(assigned[k]) for k in group)
        angles = scipy.linalg.subspace_angles(model_shapes[:, model_modes],
                                              reference_shapes[:, group])
        quality = float(np.cos(angles.max()) ** 2)
        for k, j in zip(group, model_modes):
            pairs.append(Pair(k, j, quality, g, True))
    return pairs
