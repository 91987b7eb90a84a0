"""The batched model's eigen solves (Eqs. 23-24) over many poses, and its shapes for tracking.

Frequencies come from the compiled kernel (`analytical.lanes`) or LAPACK's ?sygvd path without
vectors (`frequencies`, `batch_frequencies`); where shapes are needed, ?syevr gives the lowest
modes with vectors (`batch_modes`), as modal.solve_modes does. Shapes are compared between
poses as `probe_shapes`: the translations of every leg node, their rotations times the leg
radius (so leg torsion counts) and the platform's translation and rotation times r2, in base
coordinates. The matrices come from `batch_model.assemble_batch`.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace

import numpy as np
import scipy.linalg

from .lanes import LANES, lane_eigenvalues, lane_model_eigenvalues
from .modal import ModalError

# The whole solve on the kernel pays while its two lanes' matrices (K's factor, M's standard
# form) stay in cache; LAPACK's blocked standard form is faster beyond (measured on one core,
# us a pose, whole kernel against LAPACK's standard form + the kernel's eigenvalues: n = 54
# 72 against 96 (3.0 MB); n = 72 284 against 204 (5.3 MB); n = 126 850 against 630).
FULL_LANE_BYTES = 4 * 2 ** 20


@dataclass(frozen=True)
class BatchModel:
    """Reduced stiffness and mass of N poses, and how to read physical shapes from q."""

    stiffness: np.ndarray  # (N, 18s, 18s)
    mass: np.ndarray  # (N, 18s, 18s)
    leg_maps: tuple  # per leg: (columns (c,), T_i restricted (N, 6(s+1), c)), base coordinates
    platform_slice: slice
    leg_radius: float
    platform_radius: float


@dataclass(frozen=True)
class StandardForm:
    """M x = mu K x of every pose (mu = 1 / omega^2, as modal.solve_modes solves it) turned
    standard: K = U^T U (Cholesky), A = U^-T M U^-1, A y = mu y, x = U^-1 y (LAPACK ?potrf,
    ?sygst; upper triangles, Fortran order). The lowest modes are the largest mu."""

    matrices: list  # A per pose
    factors: list  # U per pose


def standard_form(model: BatchModel, index=None) -> StandardForm:
    """Reduce every pose once (or the poses `index`, in its order); their K and M are
    overwritten (they are not needed afterwards).

    The transposed views of the C-ordered K and M are Fortran-ordered, so LAPACK works in
    place; their upper triangle is the lower one of K and M, which solve_modes reads.
    """
    potrf, sygst = (_lapack(name) for name in ("potrf", "sygst"))
    matrices, factors = [], []
    for k in (range(len(model.stiffness)) if index is None else np.asarray(index, int)):
        factor, info = potrf(model.stiffness[k].T, lower=0, clean=1, overwrite_a=1)
        if info != 0:
            raise _mechanism(int(k), info)
        matrix, info = sygst(model.mass[k].T, factor, itype=1, lower=0, overwrite_a=1)
        matrices.append(matrix)
        factors.append(factor)
    return StandardForm(matrices, factors)


def _mechanism(pose: int, info: int) -> ModalError:
    return ModalError(f"pose {pose}: the stiffness matrix is not positive definite: the "
                      f"structure is a mechanism (LAPACK info = {info})")


def frequencies(model: BatchModel, count: int, keep: bool = False) -> np.ndarray:
    """(N, count): the lowest `count` natural frequencies (Hz) of every pose, Eqs. (23)-(24).

    Small models wholly on the compiled kernel from K and M (`analytical.lanes`: Cholesky,
    standard form, tridiagonal, bisection), while both lanes' matrices fit in FULL_LANE_BYTES;
    larger ones through LAPACK's blocked standard form and the kernel's eigenvalues
    (`batch_frequencies`); LAPACK alone where the kernel cannot run. The LAPACK paths overwrite
    K and M unless `keep`."""
    n = model.stiffness.shape[1]
    if count > n:
        raise ModalError(f"modes = {count}: the model has only {n} coordinates")
    whole = 2 * n * n * LANES * 8 <= FULL_LANE_BYTES and len(model.stiffness) > 0
    found = lane_model_eigenvalues(model.stiffness, model.mass, count) if whole else None
    if found is None:
        if keep:
            model = replace(model, stiffness=model.stiffness.copy(), mass=model.mass.copy())
        return batch_frequencies(standard_form(model), count)
    largest, info = found
    for k in np.flatnonzero(info)[:1]:  # the first, as LAPACK's pose by pose would
        raise _mechanism(int(k), int(info[k]))
    return _hertz(largest)


def _hertz(largest: np.ndarray) -> np.ndarray:
    """Frequencies (Hz) from the kernel's largest mu = 1 / omega^2 of every pose, the first pose
    whose last mu is not positive refused as `_eigenvalues` refuses it."""
    for k in np.flatnonzero(~(largest[:, -1] > 0.0))[:1]:
        _eigenvalues(int(k), 0, largest[k])
    return np.sqrt(1.0 / largest) / (2.0 * math.pi)


def batch_frequencies(form: StandardForm, count: int, kernel: str = "lanes") -> np.ndarray:
    """(N, count): the lowest `count` natural frequencies (Hz) of every pose, eigenvalues only,
    Eqs. (23)-(24): with `kernel` "lanes" the compiled kernel with the poses in its vector lanes
    (`analytical.lanes`; LAPACK where it cannot run), with "lapack" LAPACK's ?syevd without
    vectors (tridiagonal reduction and QR) one pose a call."""
    if not form.matrices:
        return np.empty((0, count))
    if count > len(form.matrices[0]):
        raise ModalError(f"modes = {count}: the model has only {len(form.matrices[0])} "
                         "coordinates")
    largest = lane_eigenvalues(form.matrices, count) if kernel == "lanes" else None
    if largest is not None:
        return _hertz(largest)
    values = np.empty((len(form.matrices), count))
    syevd = _lapack("syevd")
    for k, matrix in enumerate(form.matrices):
        mu, _, info = syevd(matrix, compute_v=0, lower=0)
        values[k] = _eigenvalues(k, info, mu[::-1][:count])
    return np.sqrt(values) / (2.0 * math.pi)


def standard_modes(form: StandardForm, k: int, count: int) -> tuple[np.ndarray, np.ndarray]:
    """mu (count,) descending and the standard form's orthonormal eigenvectors y (18s, count)
    of pose `k`, the largest mu only (LAPACK ?syevr), checked."""
    matrix = form.matrices[k]
    n = len(matrix)
    if count > n:
        raise ModalError(f"modes = {count}: the model has only {n} coordinates")
    mu, y, found, _, info = _lapack("syevr")(matrix, compute_v=1, range="I", il=n - count + 1,
                                             iu=n, lower=0)
    mu, y = mu[:count][::-1], y[:, :count][:, ::-1]
    _eigenvalues(int(k), info if found == count else -1, mu)
    return mu, y


def batch_modes(form: StandardForm, index, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies (n, count) and mass-normalised shapes (n, 18s, count) of the poses `index`
    (the largest mu only: `standard_modes`, then x = U^-1 y / sqrt(mu))."""
    trtrs = _lapack("trtrs")
    index = np.asarray(index, int)
    values, vectors = [], []
    for k in index:
        mu, y = standard_modes(form, int(k), count)
        x, info = trtrs(form.factors[k], y, lower=0)
        values.append(1.0 / mu)
        vectors.append(x / np.sqrt(mu))
    n_q = len(form.matrices[0]) if form.matrices else 0
    return (np.sqrt(np.reshape(values, (len(index), count))) / (2.0 * math.pi),
            np.reshape(vectors, (len(index), n_q, count)))


def _eigenvalues(pose: int, info: int, mu: np.ndarray) -> np.ndarray:
    """omega^2 = 1 / mu, ascending, after checking the solve."""
    if info != 0:
        raise ModalError(f"pose {pose}: eigen solve failed (LAPACK info = {info})")
    if not mu[-1] > 0.0:
        raise ModalError(f"pose {pose}: eigenvalue 1/omega^2 = {mu[-1]:.3e} s^2/rad^2 is not "
                         "positive: the structure is a mechanism")
    return 1.0 / mu


@functools.lru_cache(maxsize=None)
def _lapack(name: str):
    """The double-precision LAPACK routine (looked up once: a lookup costs as much as a small
    pose's triangular solve)."""
    return scipy.linalg.get_lapack_funcs((name,), (np.zeros(1),))[0]


def probe_shapes(model: BatchModel, shapes: np.ndarray, index=None) -> np.ndarray:
    """(n, 6 * 3(s+1) + 6, modes): physical shapes comparable between neighbouring poses, for
    the poses `index` (default: all) whose shapes (n, 18s, modes) are given.

    Per leg and node the translation and the rotation times the leg radius, then the
    platform's translation and rotation times r2, all in base coordinates.
    """
    index = slice(None) if index is None else np.asarray(index, int)
    parts = []
    for columns, t in model.leg_maps:
        nodal = t[index] @ shapes[:, columns, :]  # (N, 6(s+1), modes)
        nodal = nodal.reshape(nodal.shape[0], -1, 2, 3, nodal.shape[2])
        parts.append(nodal[:, :, 0].reshape(nodal.shape[0], -1, nodal.shape[-1]))
        parts.append(model.leg_radius
                     * nodal[:, :, 1].reshape(nodal.shape[0], -1, nodal.shape[-1]))
    platform = shapes[:, model.platform_slice, :]
    parts.append(platform[:, :3])
    parts.append(model.platform_radius * platform[:, 3:])
    return np.concatenate(parts, axis=1)
