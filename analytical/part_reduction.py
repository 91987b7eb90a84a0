"""A solid leg part's interior stations reduced to a few of its own modes (Craig-Bampton).

A condensed part (`solid_legs`) has s + 1 station nodes; only its two end nodes meet the rest
of the machine (the joints, the drive, the other part), its s - 1 interior stations are its
own. For a map over many poses they need not be kept: the part is reduced to its two end
nodes and a few fixed-interface modes (Craig & Bampton, AIAA J. 6:1313, 1968): the interior is
u_I = Psi u_B + Phi eta, Psi = -K_II^-1 K_IB the static (constraint) modes, exact at every
length, so the part stays a free body with its six rigid motions and its static stiffness
between its ends, and Phi the lowest modes of the part held at both ends.

Phi is taken at one length and carried to the others (`stretched_modes`), so that the reduced
K and M stay smooth in the length and are interpolated like the unreduced ones; the basis is
that of a sub-piece's middle (a piece of the stroke cut in SUB_PIECES, geometric), because a
basis carried further drifts: measured on random real legs, one basis per piece missed the
unreduced machine by up to 2.4e-3 (4.9e-4 with the slopes scaled) whatever the count, a
quarter piece matched the modes of each length. The part is a solid of revolution: its
axial-torsion modes (t_x, r_x) and its bending modes in the two planes (t_y, r_z) and
(t_z, -r_y) are found apart, and each bending mode is kept with its twin in the other plane,
so the basis is one of the part's symmetry, not an arbitrary turn of a degenerate pair.

How many modes a machine needs depends on how close its parts' own modes come to its modes
(18 a part on the actuator-legs scene, 30 on a slender rod): the batched model
chooses the count per machine against the unreduced one (`batch_model.leg_reduction`). The
modal coordinates sit where the chain expects nodes, `count / 6` "nodes" of six coordinates
between the two end nodes (`reduced_segments`); the per-pose model keeps every station.
"""
from __future__ import annotations

import numpy as np

SUB_PIECES = 4  # reduction bases a piece of the stroke (`joint_ends.leg_part.PIECE_RATIO`)

# per node (t_x, t_y, t_z, r_x, r_y, r_z) in the part's frame (x along the axis)
_AXIAL_TORSION = (0, 3)
_PLANE_Y = (1, 5)  # bending in x-y: t_y, r_z
_PLANE_Z = (2, 4)  # its twin in x-z: t_z = t_y, r_y = -r_z
_TWIN_SIGN = np.array([1.0, -1.0])


def reduced_segments(stations: int, modes: int) -> int:
    """Chain segments of a part of `stations` segments reduced to `modes` modal coordinates
    (0: not reduced)."""
    return modes // 6 + 1 if modes else stations


def sub_piece(lengths, lo: float, hi: float):
    """(index, lo, hi) of the geometric sub-piece of [lo, hi] holding each length."""
    lengths = np.asarray(lengths, float)
    ratio = hi / lo
    index = np.clip(np.floor(np.log(lengths / lo) / np.log(ratio) * SUB_PIECES), 0,
                    SUB_PIECES - 1).astype(int)
    return index, lo * ratio ** (index / SUB_PIECES), lo * ratio ** ((index + 1) / SUB_PIECES)


def interior_modes(stiffness: np.ndarray, mass: np.ndarray, count: int) -> np.ndarray:
    """(6 (s - 1), count) fixed-interface modes of one part (both end nodes held), the lowest
    `count` with bending modes in twin pairs (module doc), each scaled to a unit largest
    station translation, that component positive (`_signed`)."""
    d = stiffness.shape[-1]
    interior = np.arange(6, d - 6)
    nodes = len(interior) // 6

    def family(dofs):
        index = (6 + 6 * np.arange(nodes)[:, None] + np.asarray(dofs)[None, :]).ravel()
        from scipy.linalg import eigh

        values, vectors = eigh(stiffness[np.ix_(index, index)], mass[np.ix_(index, index)])
        return index, values, vectors

    axial_index, axial_values, axial_vectors = family(_AXIAL_TORSION)
    y_index, y_values, y_vectors = family(_PLANE_Y)
    z_index = (6 + 6 * np.arange(nodes)[:, None] + np.asarray(_PLANE_Z)[None, :]).ravel()
    twin = np.tile(_TWIN_SIGN, nodes)
    candidates = sorted([(v, "axial", j) for j, v in enumerate(axial_values)]
                        + [(v, "bending", j) for j, v in enumerate(y_values)])
    columns: list[np.ndarray] = []
    taken: set[tuple[str, int]] = set()
    for value, kind, j in candidates:
        size = 1 if kind == "axial" else 2
        if len(columns) + size > count:
            continue
        vector = np.zeros(d)
        if kind == "axial":
            vector[axial_index] = axial_vectors[:, j]
            columns.append(_signed(vector))
        else:
            vector[y_index] = y_vectors[:, j]
            vector = _signed(vector)
            mirror = np.zeros(d)
            mirror[z_index] = twin * vector[y_index]
            columns.extend([vector, mirror])
        taken.add((kind, j))
        if len(columns) == count:
            break
    if len(columns) != count:  # only twin pairs left for one place: the next axial mode
        rest = [j for j in range(len(axial_values)) if ("axial", j) not in taken]
        vector = np.zeros(d)
        vector[axial_index] = axial_vectors[:, rest[0]]
        columns.append(_signed(vector))
    return np.stack(columns, axis=1)[interior]


def stretched_modes(modes: np.ndarray, ratio) -> np.ndarray:
    """(*ratio.shape, 6 (s - 1), count): the modes of a part of length L0 carried to the part
    stretched to L = L0 / ratio: a shape over the stations' fractions of the part keeps its
    translations and its twist, and its bending rotations (slopes, r_y and r_z) scale as
    1 / L. The same Ritz vectors as far as the part's shape goes, so a piece keeps the
    lowest modes of every length it holds, not only of its middle."""
    ratio = np.asarray(ratio, float)
    scale = np.tile([1.0, 1.0, 1.0, 1.0, 0.0, 0.0], len(modes) // 6)
    per_dof = scale + (1.0 - scale) * ratio[..., None]  # (..., 6 (s - 1))
    return per_dof[..., :, None] * modes


def _signed(vector: np.ndarray) -> np.ndarray:
    """The mode scaled to a unit largest station translation (its twist's largest rotation
    for a torsion mode), that component positive: a modal coordinate is then about the
    station motion it stands for, as the batch's shapes compare it (`probe_shapes`)."""
    translations = vector.reshape(-1, 6)[:, :3]
    pool = translations if np.abs(translations).max() > 1e-9 * np.abs(vector).max() else \
        vector.reshape(-1, 6)[:, 3:]
    peak = pool.ravel()[np.argmax(np.abs(pool))]
    return vector / peak


def reduce_part(stiffness: np.ndarray, mass: np.ndarray, modes: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """K and M (..., 12 + count, 12 + count) of parts (..., d, d) on [end node 0, the modal
    coordinates, end node s]: the Craig-Bampton basis with the static modes of each part's
    own K and the fixed-interface `modes` (d - 12, count) given."""
    d = stiffness.shape[-1]
    interior, ends = np.arange(6, d - 6), np.r_[0:6, d - 6:d]
    k_ii = stiffness[..., interior[:, None], interior]
    k_ib = stiffness[..., interior[:, None], ends]
    psi = -np.linalg.solve(k_ii, k_ib)  # (..., d - 12, 12)
    count = modes.shape[-1]
    shape = stiffness.shape[:-2]
    basis = np.zeros(shape + (d, 12 + count))
    basis[..., :6, :6] = np.eye(6)
    basis[..., d - 6:, 6 + count:] = np.eye(6)
    basis[..., 6:d - 6, :6] = psi[..., :6]
    basis[..., 6:d - 6, 6 + count:] = psi[..., 6:]
    basis[..., 6:d - 6, 6:6 + count] = modes
    turned = np.swapaxes(basis, -1, -2)
    k_r, m_r = turned @ stiffness @ basis, turned @ mass @ basis
    return (0.5 * (k_r + np.swapaxes(k_r, -1, -2)), 0.5 * (m_r + np.swapaxes(m_r, -1, -2)))
