"""The batched eigenvalues on a compiled kernel with the poses in its vector lanes (issue 40).

LAPACK solves one small matrix a call; for the standard forms of a batch (`batch_model`), the
tridiagonal reduction of ?syevd runs column by column through BLAS 2 calls on one matrix at a
time (measured: 4.2 GFLOP/s at n = 126 on one core whose peak is 39). `analytical.lane_kernels`
runs the same reduction on LANES matrices at once, one per vector lane, and finds only the
eigenvalues asked for, by bisection. It needs numba (the `fast` extra); without it,
`lane_eigenvalues` says so once, in one line, and returns None: the caller solves with LAPACK,
which gives the same frequencies (tests/test_lanes.py: 1e-9 on every shipped scene and on
random machines).
"""
from __future__ import annotations

import warnings

import numpy as np

LANES = 64  # matrices a kernel call (n = 126, one core: 3.5, 4.0, 4.4, 8.4, 10.2, 10.5, 6.5
# GFLOP/s with 4, 8, 16, 32, 64, 128, 256; 64 is also batch_model.CHUNK)


class KernelFallback(UserWarning):
    """The compiled kernel cannot run here; LAPACK solves instead."""


def kernels():
    """The compiled kernels, or None where numba is not installed (said once, one line)."""
    try:
        from . import lane_kernels
    except ImportError as exc:
        warnings.warn(f"the compiled eigenvalue kernel needs numba ({exc.name or exc} is not "
                      "installed; pip install rps-elastodynamics[fast]): LAPACK solves instead",
                      KernelFallback, stacklevel=3)
        return None
    return lane_kernels


def _groups(stack: np.ndarray):
    """(start, stop, LANES matrices) of N stacked ones (N, n, n), a short last group padded
    with copies of its last matrix (the spare lanes' results are dropped)."""
    for start in range(0, len(stack), LANES):
        group = stack[start:start + LANES]
        if len(group) < LANES:
            group = np.concatenate([group, np.repeat(group[-1:], LANES - len(group), axis=0)])
        yield start, min(start + LANES, len(stack)), np.ascontiguousarray(group)


def lane_eigenvalues(matrices: list[np.ndarray], count: int) -> np.ndarray | None:
    """(N, count): the `count` largest eigenvalues, descending, of the symmetric matrices (their
    upper triangles, as LAPACK's ?sygst leaves them), or None where the kernel cannot run."""
    compiled = kernels()
    if compiled is None:
        return None
    n = len(matrices[0])
    out = np.empty((len(matrices), count))
    a, d, e = np.empty((n, n, LANES)), np.empty((n, LANES)), np.empty((n - 1, LANES))
    found = np.empty((count, LANES))
    # the lower triangle of each lane's matrix is the upper of the given one: a[i, j, b] =
    # matrix_b[j, i] (the transposes of ?sygst's Fortran-ordered results are C-ordered: stacked
    # as they lie, then gathered into lanes, 23 against 49 us a pose for np.stack along the last
    # axis)
    for start, stop, group in _groups(np.stack([matrix.T for matrix in matrices])):
        compiled.gather_lower(group, a)
        compiled.tridiagonal(a, d, e)
        compiled.largest(d, e, count, found)
        out[start:stop] = found.T[:stop - start]
    return out


def lane_model_eigenvalues(stiffness: np.ndarray, mass: np.ndarray, count: int
                           ) -> tuple[np.ndarray, np.ndarray] | None:
    """The `count` largest mu of M x = mu K x, descending, for each pose of K and M (N, n, n)
    (lower triangles read, neither changed), all on the kernel: Cholesky of K, the standard
    form, the tridiagonal and the bisection; and per pose 0, or j + 1 where K's j-th pivot is not
    positive (not positive definite: a mechanism). None where the kernel cannot run."""
    compiled = kernels()
    if compiled is None:
        return None
    total, n = len(stiffness), stiffness.shape[1]
    out, info = np.empty((total, count)), np.zeros(total + LANES, np.int64)
    factor, a = np.empty((n, n, LANES)), np.empty((n, n, LANES))
    d, e, found = np.empty((n, LANES)), np.empty((n - 1, LANES)), np.empty((count, LANES))
    for (start, stop, k_group), (_, _, m_group) in zip(_groups(stiffness), _groups(mass)):
        compiled.gather_lower(k_group, factor)
        compiled.gather_lower(m_group, a)
        compiled.cholesky(factor, info[start:start + LANES])
        compiled.reduce_standard(a, factor)
        compiled.tridiagonal(a, d, e)
        compiled.largest(d, e, count, found)
        out[start:stop] = found.T[:stop - start]
    return out, info[:total]
