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

from common.errors import InputError
from common.modes import clusters, mac_matrix  # noqa: F401  (re-exported)


@dataclass(frozen=True)
class Pair:
    reference_mode: int  # 0-based index in the reference (FEM) model
    model_mode: int  # 0-based index in the model under test (analytical)
    mac: float  # MAC, or cos^2 of the largest principal angle for a repeated group
    group: int  # index of the repeated-mode group (singletons have their own)
    repeated: bool

    def error_percent(self, f_model: np.ndarray, f_reference: np.ndarray) -> float:
        return 100.0 * (f_model[self.model_mode] / f_reference[self.reference_mode] - 1.0)


def group_scores(model_shapes: np.ndarray, reference_shapes: np.ndarray, mac: np.ndarray,
                  groups: list[list[int]]) -> np.ndarray:
    """MAC, except against a repeated group: there every member's column holds the share of
    each model shape lying in the group's subspace, ||P x||^2 / ||x||^2, which does not depend
    on the arbitrary basis the eigen solver returned for the group (single-mode MACs do: a pair
    rotated by 45 degrees gives 0.5 against both members, and a third mode of middling MAC could
    then win a member's place)."""
    scores = mac.copy()
    norms = np.einsum("ij,ij->j", model_shapes.conj(), model_shapes).real
    for group in groups:
        if len(group) > 1:
            basis = scipy.linalg.orth(reference_shapes[:, group])
            share = np.linalg.norm(basis.conj().T @ model_shapes, axis=0) ** 2
            scores[:, group] = (share / np.where(norms > 0, norms, 1.0))[:, None]
    return scores


def pair_modes(model_shapes: np.ndarray, model_hz: np.ndarray, reference_shapes: np.ndarray,
               reference_hz: np.ndarray, count: int, repeat_tolerance: float = 0.02
               ) -> list[Pair]:
    """Pair the first `count` reference modes with modes of the model under test.

    Groups of near-repeated reference modes (relative gap < repeat_tolerance) are found over
    every reference mode given, so a pair split by the cut at `count` is still taken whole:
    it is matched as a subspace, and its members below the cut are reported. The model must
    carry at least as many modes as the groups reaching below the cut hold.
    """
    reference_hz = np.asarray(reference_hz)
    n_ref = min(count, reference_shapes.shape[1])
    groups = [g for g in clusters(reference_hz, repeat_tolerance) if g[0] < n_ref]
    columns = [k for g in groups for k in g]
    if len(columns) > model_shapes.shape[1]:
        raise InputError(f"pairing needs {len(columns)} model modes, got "
                         f"{model_shapes.shape[1]}")
    mac = mac_matrix(model_shapes, reference_shapes)
    rows, cols = linear_sum_assignment(-group_scores(model_shapes, reference_shapes, mac,
                                                      groups)[:, columns])
    assigned = {columns[c]: int(r) for r, c in zip(rows, cols)}
    pairs: list[Pair] = []
    for g, group in enumerate(groups):
        if len(group) == 1:
            k = group[0]
            pairs.append(Pair(k, assigned[k], float(mac[assigned[k], k]), g, False))
            continue
        model_modes = sorted(assigned[k] for k in group)
        angles = scipy.linalg.subspace_angles(model_shapes[:, model_modes],
                                              reference_shapes[:, group])
        quality = float(np.cos(angles.max()) ** 2)
        for k, j in zip(group, model_modes):
            if k < n_ref:
                pairs.append(Pair(k, j, quality, g, True))
    return pairs
