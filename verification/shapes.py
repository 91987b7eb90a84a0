"""Which computed mode is which reference mode: pairing BY SHAPE, not by index.

Published mode lists skip or interleave modes of other families (bending and in-plane modes of
a plate, circumferential harmonics of a cylinder), so every reference mode is declared as the
k-th elastic mode of a kind ("bending", "in-plane", "axisymmetric", ...) and found among the
computed modes by the kind of each computed mode: its kinetic-energy fractions by displacement
component (v_c^T M_cc v_c / v^T M v, M the consistent mass) or, on a 3D body of revolution, the
fraction of its displacement in each circumferential harmonic (`harmonic_content`). Rigid-body
modes are those far below the lowest elastic frequency (`RIGID_RATIO`).
"""
from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

# |f| below RIGID_RATIO times the lowest elastic frequency: a rigid-body mode. A zero eigenvalue
# comes out of the shifted solve as round-off, |lambda| ~ 1e-16 |K| / |M|, i.e. |f| of order
# 1e-5-1e-4 of the elastic ones on these meshes (measured); an elastic mode is never that low.
RIGID_RATIO = 1e-3


def component_fractions(vectors: np.ndarray, mass: sp.spmatrix) -> np.ndarray:
    """(3, n_modes) kinetic-energy fraction of each displacement component c of every mode
    (dofs 3 s + c; `mass` the consistent mass, block-diagonal by component)."""
    total = np.einsum("im,im->m", vectors, mass @ vectors)
    parts = []
    for c in range(3):
        v = vectors[c::3]
        parts.append(np.einsum("im,im->m", v, mass[c::3][:, c::3] @ v))
    return np.array(parts) / np.where(total > 0, total, 1.0)


def rigid_count(hz: np.ndarray) -> tuple[int, float, float]:
    """(number of rigid-body modes, largest rigid |f|, the limit RIGID_RATIO f_elastic) of an
    ascending spectrum: the modes below RIGID_RATIO times the first frequency above it."""
    hz = np.abs(np.asarray(hz, float))
    order = np.sort(hz)
    elastic = order[order > RIGID_RATIO * order.max()]
    limit = RIGID_RATIO * float(elastic.min())
    rigid = order[order < limit]
    return len(rigid), float(rigid.max()) if len(rigid) else 0.0, limit


def kth_of_kind(hz: np.ndarray, kinds, kind: str, k: int) -> int:
    """Index of the k-th (1-based) elastic mode whose kind is `kind` (rigid modes skipped).
    Raises LookupError if the spectrum holds fewer."""
    _, _, limit = rigid_count(hz)
    found = [i for i in range(len(hz)) if abs(hz[i]) >= limit and kinds[i] == kind]
    if len(found) < k:
        raise LookupError(f"only {len(found)} elastic modes of kind {kind!r} among {len(hz)}")
    return found[k - 1]


def pair_split(f_a: float, f_b: float) -> float:
    """|f_a - f_b| / mean: the relative split of a (near-)repeated pair."""
    return abs(f_a - f_b) / (0.5 * (abs(f_a) + abs(f_b)))


def cylindrical(xyz: np.ndarray, vectors: np.ndarray):
    """(theta, u_r, u_t, u_z) per node of every mode (z the axis): theta (n_nodes,), the
    components (n_nodes, n_modes)."""
    x, y = xyz[:, 0], xyz[:, 1]
    theta = np.arctan2(y, x)
    c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
    ux, uy, uz = vectors[0::3], vectors[1::3], vectors[2::3]
    return theta, c * ux + s * uy, -s * ux + c * uy, uz


def harmonic_content(xyz: np.ndarray, vectors: np.ndarray, n_max: int = 4,
                     bins: tuple[int, int] = (2, 24)) -> np.ndarray:
    """(n_max + 1, n_modes) fraction of every mode's displacement (squared, all three
    cylindrical components) in circumferential harmonics 0..n_max of a body of revolution about
    z: the nodes are binned in (r, z) (`bins`), and in every bin each component is fitted by
    least squares with cos(n theta), sin(n theta), n <= n_max (harmonics above n_max count in
    the last row's complement: the rows need not sum to one)."""
    theta, ur, ut, uz = cylindrical(xyz, vectors)
    r = np.hypot(xyz[:, 0], xyz[:, 1])
    z = xyz[:, 2]
    ri = np.minimum((bins[0] * (r - r.min()) / (np.ptp(r) or 1.0)).astype(int), bins[0] - 1)
    zi = np.minimum((bins[1] * (z - z.min()) / (np.ptp(z) or 1.0)).astype(int), bins[1] - 1)
    cell = ri * bins[1] + zi
    columns = [np.ones_like(theta)] + [f(n * theta) for n in range(1, n_max + 1)
                                       for f in (np.cos, np.sin)]
    basis = np.column_stack(columns)
    harmonic_of_column = [0] + [n for n in range(1, n_max + 1) for _ in (0, 1)]
    energy = np.zeros((n_max + 1, vectors.shape[1]))
    total = np.zeros(vectors.shape[1])
    for b in np.unique(cell):
        rows = np.flatnonzero(cell == b)
        if len(rows) < 3 * len(columns):
            continue
        a = basis[rows]
        for comp in (ur, ut, uz):
            values = comp[rows]
            coef, *_ = np.linalg.lstsq(a, values, rcond=None)
            fitted = a[:, :, None] * coef[None, :, :]  # (rows, columns, modes)
            for j, n in enumerate(harmonic_of_column):
                energy[n] += (fitted[:, j] ** 2).sum(axis=0)
            total += (values ** 2).sum(axis=0)
    return energy / np.where(total > 0, total, 1.0)


def dominant_harmonic(content: np.ndarray) -> list[int]:
    """The harmonic holding the largest share of each mode (`harmonic_content`'s columns)."""
    return [int(i) for i in np.argmax(content, axis=0)]


def torsion_share(xyz: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """(n_modes,) the share of u_t in the squared displacement of every mode (nodal sums):
    close to 1 for a torsional mode of a tube."""
    _, ur, ut, uz = cylindrical(xyz, vectors)
    total = (ur**2 + ut**2 + uz**2).sum(axis=0)
    return (ut**2).sum(axis=0) / np.where(total > 0, total, 1.0)


def closed_form_torsion_hz(m: int, length: float, shear_modulus: float, density: float) -> float:
    """The m-th free-free torsional frequency of a circular shaft or tube: m / (2 L)
    sqrt(G / rho) (Saint-Venant torsion is exact for circular sections)."""
    return m / (2.0 * length) * math.sqrt(shear_modulus / density)


def radial_uniformity(rz: np.ndarray, vectors: np.ndarray, mass: sp.spmatrix) -> np.ndarray:
    """Per mode of a body of revolution about a centre (harmonic 0, meridian nodes `rz`, dofs
    3 s + c): the share of its kinetic energy in a uniform radial motion U(rho) e_rho, i.e. in
    the mean over each sphere rho = const (nodes grouped by rho to 1e-9) of the radial
    displacement; 1 for the breathing modes of a sphere, ~0 for every other mode."""
    rho = np.hypot(rz[:, 0], rz[:, 1])
    e_rho = rz / rho[:, None]
    weights = np.abs(np.asarray(mass.diagonal())[0::3])
    levels = np.unique(np.round(rho, 9), return_inverse=True)[1]
    out = []
    for v in vectors.T:
        u = np.stack([v[0::3], v[2::3]], axis=1)
        radial = (u * e_rho).sum(axis=1)
        mean = (np.bincount(levels, weights * radial) / np.bincount(levels, weights))[levels]
        total = np.sum(weights * (u**2).sum(axis=1))
        out.append(float(np.sum(weights * mean**2) / total) if total > 0 else 0.0)
    return np.asarray(out)
