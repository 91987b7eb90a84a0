"""Mode pairing by shape: MAC properties, repeated pairs as subspaces, order independence."""
from __future__ import annotations

import numpy as np

from solvers.pairing import clusters, mac_matrix, pair_modes


def test_mac_is_one_for_scaled_shapes_and_zero_for_orthogonal():
    rng = np.random.default_rng(0)
    a = np.linalg.qr(rng.normal(size=(30, 4)))[0]
    mac = mac_matrix(a, -3.0 * a)
    assert np.allclose(np.diag(mac), 1.0)
    assert np.allclose(mac - np.diag(np.diag(mac)), 0.0, atol=1e-20)


def test_pairs_by_shape_not_by_sorted_order():
    rng = np.random.default_rng(1)
    shapes = np.linalg.qr(rng.normal(size=(40, 4)))[0]
    ref_hz = np.array([100.0, 200.0, 300.0, 400.0])
    # the model under test swaps modes 2 and 3 in frequency order
    model = shapes[:, [0, 2, 1, 3]]
    model_hz = np.array([101.0, 290.0, 305.0, 402.0])
    pairs = pair_modes(model, model_hz, shapes, ref_hz, count=4)
    assert [(p.reference_mode, p.model_mode) for p in pairs] == [(0, 0), (1, 2), (2, 1), (3, 3)]
    assert all(p.mac > 0.999 for p in pairs)


def test_repeated_pair_is_compared_as_a_subspace():
    rng = np.random.default_rng(2)
    basis = np.linalg.qr(rng.normal(size=(40, 3)))[0]
    ref = basis.copy()
    c, s = np.cos(0.7), np.sin(0.7)
    model = basis.copy()
    model[:, :2] = basis[:, :2] @ np.array([[c, -s], [s, c]])  # any basis of the pair
    pairs = pair_modes(model, np.array([100.0, 100.0, 150.0]), ref,
                       np.array([99.0, 99.5, 149.0]), count=3)
    assert [p.repeated for p in pairs] == [True, True, False]
    assert all(p.mac > 0.999999 for p in pairs)
    # mode by mode, MAC would have called them different
    assert mac_matrix(model[:, :1], ref[:, :1])[0, 0] < 0.7


def test_clusters_group_near_repeated_frequencies():
    assert clusters(np.array([115.0, 115.1, 196.0, 650.0, 724.0, 724.5]), 0.01) == [
        [0, 1], [2], [3], [4, 5]]


def test_a_pair_split_by_the_cut_is_still_compared_whole():
    rng = np.random.default_rng(3)
    basis = np.linalg.qr(rng.normal(size=(40, 4)))[0]
    c, s = np.cos(0.9), np.sin(0.9)
    model = basis.copy()
    model[:, 2:] = basis[:, 2:] @ np.array([[c, -s], [s, c]])  # the pair in another basis
    ref_hz = np.array([50.0, 80.0, 120.0, 120.5])
    pairs = pair_modes(model, np.array([51.0, 81.0, 121.0, 121.0]), basis, ref_hz, count=3)
    assert [p.reference_mode for p in pairs] == [0, 1, 2]
    assert pairs[2].repeated and pairs[2].mac > 0.999999


def test_a_rotated_repeated_pair_keeps_its_members_against_a_decoy():
    """The solver may return a repeated pair in any basis. Turned by 45 degrees, each member
    has MAC 0.5 with both model members, while a third model mode (a different family that
    shares 75 % of one member's sampled shape) has MAC 0.75 with it: mode by mode, the decoy
    would take a member's place. The pair is taken by subspace, whatever its basis."""
    e = np.eye(8)
    pair = np.column_stack([e[:, 0] + e[:, 1], e[:, 0] - e[:, 1]]) / np.sqrt(2)
    reference = np.column_stack([pair, e[:, 2]])
    ref_hz = np.array([300.0, 300.0, 500.0])
    decoy = np.sqrt(0.75) * pair[:, 0] + np.sqrt(0.25) * e[:, 3]
    model = np.column_stack([e[:, 0], e[:, 1], e[:, 2], decoy])
    model_hz = np.array([301.0, 301.0, 498.0, 320.0])
    assert mac_matrix(model, reference)[3, 0] > mac_matrix(model, reference)[0, 0]
    for turn in np.linspace(0.0, np.pi, 7):  # any basis of the pair
        c, s = np.cos(turn), np.sin(turn)
        turned = reference.copy()
        turned[:, :2] = pair @ np.array([[c, -s], [s, c]])
        pairs = pair_modes(model, model_hz, turned, ref_hz, count=3)
        assert [(p.reference_mode, p.model_mode) for p in pairs] == [(0, 0), (1, 1), (2, 2)]
        assert all(p.mac > 0.999 for p in pairs)
