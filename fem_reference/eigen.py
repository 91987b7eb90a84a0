"""Lowest natural modes of K x = lambda M x (sparse, symmetric): ARPACK in shift-invert mode.

- shift sigma = -(2 pi f_shift)^2 with f_shift = 10 Hz: small and negative, so K - sigma M is
  positive definite even with rigid-body modes (free-free bodies) and the lowest modes come first;
- the factorisation of K - sigma M is done once; backend "splu" is SuperLU with the symmetric
  ordering MMD_AT_PLUS_A and diagonal pivoting preferred (less fill and faster solves than the
  default COLAMD at equal factorisation time; CHOLMOD and MKL Pardiso measured no clear gain on
  2 cores, see fem_reference/README.md);
- v0 is a fixed pseudo-random vector (seeded), so ARPACK's iteration and hence the frequencies are
  bit-for-bit reproducible run to run;
- a few more modes are computed than reported (`extra`), so a repeated pair at the end of the
  reported range is complete; clusters (relative gap below `cluster_tol`) are reported, and if the
  last reported mode's cluster reaches the last computed mode, more modes are computed;
- every returned pair is checked: relative residual |K x - lambda M x| / |K x|, M-orthonormality,
  and exactly the asked number of modes;
- a failed attempt (ARPACK not converging, a singular factorisation, a failed check) is retried
  once with another shift and starting vector; the failures are reported in `Modes.retries`, and
  if the retry fails too, EigenError names both: never fewer modes than asked.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from common.errors import ComputeError, InputError

SHIFT_HZ = 10.0
V0_SEED = 20230723
RETRY = (40.0, V0_SEED + 1)  # the second attempt's shift (Hz) and starting-vector seed
ARPACK_TOL = 1e-10  # relative Ritz-value accuracy; frequencies to ~1e-10


BACKENDS = ("splu", "splu-colamd")


class EigenError(ComputeError):
    """The eigensolver did not converge or returned inaccurate pairs."""


@dataclass(frozen=True)
class Modes:
    eigenvalues: np.ndarray  # (n,) lambda = omega^2, ascending
    vectors: np.ndarray  # (n_dofs, n), M-orthonormal
    clusters: list[list[int]]  # groups of (near-)repeated modes among the returned ones
    residuals: np.ndarray  # (n,) relative residuals
    backend: str
    retries: tuple[str, ...] = ()  # failed attempts before this answer, one line each
    shift_hz: float = SHIFT_HZ  # the shift of the attempt that gave it

    @property
    def frequencies_hz(self) -> np.ndarray:
        return np.sign(self.eigenvalues) * np.sqrt(np.abs(self.eigenvalues)) / (2 * math.pi)


def factorize(a: sp.spmatrix, backend: str = "splu"):
    """A solve function for the symmetric positive definite matrix `a`."""
    if backend == "splu":
        lu = sla.splu(sp.csc_matrix(a), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                      options={"SymmetricMode": True})
        return lu.solve
    if backend == "splu-colamd":
        return sla.splu(sp.csc_matrix(a)).solve
    raise InputError(f"eigen backend = {backend!r}: expected splu or splu-colamd")


def clusters_of(eigenvalues: np.ndarray, tol: float) -> list[list[int]]:
    """Group consecutive eigenvalues whose frequencies differ by less than `tol` (relative)."""
    f = np.sqrt(np.abs(eigenvalues))
    groups, current = [], [0]
    for k in range(1, len(f)):
        if f[k] - f[k - 1] <= tol * max(abs(f[k]), 1e-300):
            current.append(k)
        else:
            groups.append(current)
            current = [k]
    groups.append(current)
    return groups


def lowest_modes(k: sp.spmatrix, m: sp.spmatrix, n_modes: int, extra: int = 2,
                 backend: str = "splu", cluster_tol: float = 1e-3,
                 residual_tol: float = 1e-6) -> Modes:
    """The `n_modes` lowest eigenpairs of (K, M), checked; retried once with another shift.

    Raises EigenError if both attempts fail (the message names each failure).
    """
    n = k.shape[0]
    if n_modes + extra >= n - 1:
        raise EigenError(f"{n_modes} modes asked of a model with only {n} dofs")
    failures = []
    for shift_hz, seed in ((SHIFT_HZ, V0_SEED), RETRY):
        try:
            modes = _attempt(k, m, n_modes, extra, backend, cluster_tol, residual_tol,
                             shift_hz, seed)
        except EigenError as exc:
            failures.append(f"shift -({shift_hz:g} Hz)^2: {exc}")
            continue
        return replace(modes, retries=tuple(failures))
    raise EigenError("; ".join(failures))


def _attempt(k, m, n_modes: int, extra: int, backend: str, cluster_tol: float,
             residual_tol: float, shift_hz: float, seed: int) -> Modes:
    """One shift-invert Lanczos solve at sigma = -(2 pi shift_hz)^2, checked."""
    n = k.shape[0]
    sigma = -(2 * math.pi * shift_hz) ** 2
    try:
        solve = factorize((k - sigma * m).tocsc(), backend)
    except RuntimeError as exc:  # SuperLU: singular factor
        raise EigenError(f"factorisation of K - sigma M failed ({exc})") from None
    op = sla.LinearOperator((n, n), matvec=solve, dtype=float)
    v0 = np.random.default_rng(seed).standard_normal(n)
    n_ask = n_modes + extra
    while True:
        try:
            w, v = sla.eigsh(k, k=n_ask, M=m, sigma=sigma, which="LM", OPinv=op, v0=v0,
                             tol=ARPACK_TOL, maxiter=max(1000, 20 * n_ask))
        except sla.ArpackNoConvergence as exc:
            raise EigenError(f"ARPACK did not converge: {len(exc.eigenvalues)} of {n_ask} "
                             "eigenpairs found") from None
        except sla.ArpackError as exc:
            raise EigenError(f"ARPACK failed ({' '.join(str(exc).split())})") from None
        if len(w) != n_ask:
            raise EigenError(f"ARPACK returned {len(w)} of {n_ask} eigenpairs")
        order = np.argsort(w)
        w, v = w[order], v[:, order]
        groups = clusters_of(w, cluster_tol)
        last = next(g for g in groups if n_modes - 1 in g)
        if last[-1] < n_ask - 1 or n_ask >= min(n - 2, n_modes + 24):
            break
        n_ask = min(n - 2, n_ask + 4)
    w, v = w[:n_modes], v[:, :n_modes]
    kv = k @ v
    res = np.linalg.norm(kv - (m @ v) * w, axis=0) / np.maximum(
        np.linalg.norm(kv, axis=0), np.abs(sigma) * np.linalg.norm(m @ v, axis=0))
    if not np.all(np.isfinite(res)) or res.max() > residual_tol:
        raise EigenError(f"eigenpair residual {np.nanmax(res):.3g} exceeds {residual_tol:g}")
    gram = v.T @ (m @ v)
    if np.abs(gram - np.eye(n_modes)).max() > 1e-6:
        raise EigenError("eigenvectors are not M-orthonormal (lost multiplicity?)")
    return Modes(w, v, [g for g in clusters_of(w, cluster_tol)], res, backend, (), shift_hz)
