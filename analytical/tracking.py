"""Following modes from pose to pose by their shapes (MAC), not by their sorted order.

A family is one mode followed through neighbouring poses. Between two poses the modes are
matched by the modal assurance criterion of comparable physical shapes (batch_model.probe_shapes),
with (near-)repeated modes compared as subspaces: inside a cluster any basis is an equally
valid set of modes, so a cluster is matched as a whole and its members keep ascending order.
Two families cross where their order swaps between neighbours.

Shapes cost an eigenvector solve; frequencies alone tell where they are not needed. If two
families swap inside a step, the sorted gap between them is at most 2 D at both ends, D being
the most any family moves in that step (a crossing family travels the whole gap). Sorting
never moves a frequency more than the families do, so D is estimated from the sorted
frequencies of the step and its neighbours, with a safety factor; a step whose gaps all
exceed 2 D at one end is matched in sorted order. `steps_needing_shapes` says which are not.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg
from scipy.optimize import linear_sum_assignment

from common.modes import clusters

REPEATED = 1e-7  # relative frequency gap below which modes form one (repeated) cluster
RATE_SAFETY = 1.5  # family speed over a step vs the largest sorted change nearby


def _orthonormal(vectors: np.ndarray) -> np.ndarray:
    return scipy.linalg.orth(vectors) if vectors.shape[1] > 1 else (
        vectors / np.linalg.norm(vectors))


def match_modes(source_shapes: np.ndarray, source_hz: np.ndarray, target_shapes: np.ndarray,
                target_hz: np.ndarray, repeated: float = REPEATED
                ) -> tuple[np.ndarray, np.ndarray]:
    """Where every source mode went: (target index per source mode, MAC of the match).

    Shapes are (d, w) physical vectors, frequencies ascending. The score of a source and a
    target mode is the overlap of their clusters' subspaces, sum of cos^2 of the principal
    angles divided by the smaller cluster size (the MAC for two single modes); the matching
    maximises the total score (Hungarian). Members of one cluster keep ascending order on
    both sides.
    """
    groups_s, groups_t = clusters(source_hz, repeated), clusters(target_hz, repeated)
    bases_s = [_orthonormal(source_shapes[:, g]) for g in groups_s]
    bases_t = [_orthonormal(target_shapes[:, g]) for g in groups_t]
    overlap = np.array([[np.sum((a.T @ b) ** 2) / min(a.shape[1], b.shape[1])
                         for b in bases_t] for a in bases_s])
    of_s = np.concatenate([[a] * len(g) for a, g in enumerate(groups_s)])
    of_t = np.concatenate([[b] * len(g) for b, g in enumerate(groups_t)])
    score = overlap[np.ix_(of_s, of_t)]
    _, target = linear_sum_assignment(score, maximize=True)
    for g in groups_s:  # a source cluster's members go to its targets in ascending order
        target[g] = np.sort(target[g])
    for g in groups_t:  # and a target cluster receives its sources in ascending order
        into = np.flatnonzero(np.isin(target, g))
        target[into] = np.sort(target[into])
    return target, score[np.arange(len(target)), target]


def match_steps(source_shapes: np.ndarray, source_hz: np.ndarray, target_shapes: np.ndarray,
                target_hz: np.ndarray, repeated: float = REPEATED
                ) -> tuple[np.ndarray, np.ndarray]:
    """`match_modes` for a batch of steps: shapes (S, d, w), frequencies (S, w).

    Where neither end has repeated modes and every source mode's best MAC is a different
    target mode, that is the matching of largest total MAC, read off directly; the other
    steps go through `match_modes`.
    """
    def unit(x):
        return x / np.linalg.norm(x, axis=1, keepdims=True)

    mac = np.einsum("sda,sdb->sab", unit(source_shapes), unit(target_shapes)) ** 2
    best = np.argmax(mac, axis=2)
    distinct = np.all(np.diff(np.sort(best, axis=1), axis=1) > 0, axis=1)
    single = np.all(np.diff(source_hz, axis=1) > repeated * source_hz[:, 1:], axis=1) & np.all(
        np.diff(target_hz, axis=1) > repeated * target_hz[:, 1:], axis=1)
    target = best.copy()
    for k in np.flatnonzero(~(distinct & single)):
        target[k] = match_modes(source_shapes[k], source_hz[k], target_shapes[k],
                                target_hz[k], repeated)[0]
    quality = np.take_along_axis(mac, target[:, :, None], axis=2)[:, :, 0]
    for k in np.flatnonzero(~single):  # cluster matches are scored on their subspaces
        quality[k] = match_modes(source_shapes[k], source_hz[k], target_shapes[k],
                                 target_hz[k], repeated)[1]
    return target, quality


def steps_needing_shapes(frequencies: np.ndarray, closed: bool = False,
                         safety: float = RATE_SAFETY) -> np.ndarray:
    """Which steps of a path may hide a crossing: (n - 1,) bool, or (n,) for a closed path
    (the last step returns to the first pose).

    `frequencies` is (n, w + 1), ascending per pose: w tracked modes and the next one, so a
    family leaving the window is seen too. Neighbours k, k + 1 can swap inside a step only if
    their gap is at most 2 D at both ends, D = `safety` times the largest change of either
    over the step and the steps next to it.
    """
    f = np.asarray(frequencies, float)
    if closed:
        f = np.concatenate([f, f[:1]])
    if len(f) < 2:
        return np.zeros(0, bool)
    change = np.abs(np.diff(f, axis=0))  # (steps, w + 1) sorted change per mode
    before = np.roll(change, 1, axis=0) if closed else np.concatenate([change[:1], change[:-1]])
    after = np.roll(change, -1, axis=0) if closed else np.concatenate([change[1:], change[-1:]])
    nearby = np.maximum(change, np.maximum(before, after))
    reach = 2.0 * safety * np.maximum(nearby[:, :-1], nearby[:, 1:])  # 2 D per pair (k, k+1)
    gaps = np.diff(f, axis=1)  # (n(+1), w)
    clear = (gaps[:-1] > reach) | (gaps[1:] > reach)
    return ~np.all(clear, axis=1)


def follow(order: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Family -> sorted index after a step, given family -> sorted index before it and where
    each sorted mode went."""
    return target[order]


def track_path(frequencies: np.ndarray, shapes: np.ndarray,
               repeated: float = REPEATED) -> tuple[np.ndarray, np.ndarray]:
    """Follow the modes of a path of poses: (n, w) sorted index of every family at every pose
    (families named by their order at the first pose) and (n, w) MAC of the step into it.

    `frequencies` (n, w) ascending, `shapes` (n, d, w) probe shapes.
    """
    n, w = frequencies.shape
    order = np.empty((n, w), int)
    quality = np.ones((n, w))
    order[0] = np.arange(w)
    for k in range(1, n):
        target, mac = match_modes(shapes[k - 1], frequencies[k - 1], shapes[k],
                                  frequencies[k], repeated)
        order[k] = follow(order[k - 1], target)
        quality[k] = mac[order[k - 1]]
    return order, quality


def family_values(sorted_values: np.ndarray, order: np.ndarray) -> np.ndarray:
    """Per-family values from per-sorted-mode values: out[..., j] = sorted[..., order[..., j]]."""
    return np.take_along_axis(sorted_values, order, axis=-1)
