"""Modal solve of the reduced model, Eqs. (23)-(24), and expansion of the mode shapes."""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg
from scipy.linalg.lapack import _compute_lwork

from common.errors import ComputeError, InputError

from .substructure import SubstructureModel


class ModalError(ComputeError):
    """The eigenproblem has no physical answer (not positive definite, non-finite)."""


RESIDUAL_LIMIT = 1e-6  # a solve whose pairs are worse than this is refused (see solve_modes)


@dataclass(frozen=True)
class ModalResult:
    frequencies_hz: np.ndarray  # (n,), ascending
    shapes: np.ndarray  # (18s, n) mass-normalised eigenvectors in independent coordinates
    residuals: np.ndarray | None = None  # (n,) |K x - omega^2 M x| / |K x| of every pair
    orthonormality: float | None = None  # max |X^T M X - I|


def solve_modes(model: SubstructureModel, count: int) -> ModalResult:
    """Lowest `count` modes of (K - omega^2 M) Phi = 0, Eq. (23); f = omega / 2 pi, Eq. (24).

    Solved as M Phi = mu K Phi for the largest mu = 1 / omega^2 (LAPACK reduces with the
    Cholesky factor of K): the structure's lowest modes are then the end of the spectrum that
    the reduction resolves best. Reducing with the Cholesky factor of M instead loses them as
    the elements shrink (the Euler-Bernoulli mass has nearly massless rotations): measured on
    the paper's Case 2, relative residuals 9e-10 at s = 10 and 1e-4 at s = 200 that way,
    8e-12 and 3e-7 this way. Every pair is checked, not trusted: its residual and the
    M-orthonormality are returned, and a solve worse than RESIDUAL_LIMIT is refused.
    """
    n = model.stiffness.shape[0]
    if count > n:
        raise ModalError(f"modes = {count}: the model has only {n} coordinates")
    if not (np.all(np.isfinite(model.stiffness)) and np.all(np.isfinite(model.mass))):
        raise ModalError("the reduced matrices hold non-finite entries (singular joint map?)")
    sygvx, lwork = _generalized_solver(n)
    mu, vectors, found, _, info = sygvx(model.mass, model.stiffness, itype=1, jobz="V",
                                        range="I", uplo="L", il=n - count + 1, iu=n,
                                        lwork=lwork)
    if info > n:
        raise ModalError(f"the stiffness matrix is not positive definite: the structure is a "
                         f"mechanism (its leading minor of order {info - n} is not)")
    if info != 0 or found != count:
        raise ModalError(f"eigen solve failed (LAPACK ?sygvx info = {info}, {found} of "
                         f"{count} eigenvalues)")
    mu, vectors = mu[:count][::-1], vectors[:, :count][:, ::-1]
    if not mu[-1] > 0.0:
        raise ModalError(f"eigenvalue 1/omega^2 = {mu[-1]:.3e} s^2/rad^2 is not positive: the "
                         "structure is a mechanism")
    eigval = 1.0 / mu
    shapes = vectors / np.sqrt(mu)  # K-normalised -> M-normalised
    k_x = model.stiffness @ shapes
    m_x = model.mass @ shapes
    residuals = np.linalg.norm(k_x - m_x * eigval, axis=0) / np.linalg.norm(k_x, axis=0)
    orthonormality = float(np.abs(shapes.T @ m_x - np.eye(count)).max())
    if not (residuals.max() <= RESIDUAL_LIMIT and orthonormality <= RESIDUAL_LIMIT):
        raise ModalError(f"eigen solve inaccurate: residual {residuals.max():.2e}, "
                         f"M-orthonormality {orthonormality:.2e} (limit {RESIDUAL_LIMIT:g})")
    return ModalResult(np.sqrt(eigval) / (2.0 * math.pi), shapes, residuals, orthonormality)


@functools.lru_cache(maxsize=None)
def _generalized_solver(n: int):
    """LAPACK ?sygvx and its workspace for n x n (looked up once per size): the driver and the
    workspace scipy.linalg.eigh(a, b, subset_by_index=...) picks, called without its per-call
    checks (bit-identical results; the wrapper cost as much as the 54 x 54 solve itself)."""
    sygvx, query = scipy.linalg.get_lapack_funcs(("sygvx", "sygvx_lwork"), (np.zeros(1),))
    return sygvx, _compute_lwork(query, n, uplo="L")


def leg_displacements(model: SubstructureModel, shapes: np.ndarray) -> np.ndarray:
    """Nodal displacements and rotations of every leg for each mode.

    Returns (3, s+1, 6, n): leg, node, (u_x, u_y, u_z, theta_x, theta_y, theta_z), mode.
    """
    s = model.elements
    out = np.stack([t @ shapes for t in model.leg_maps])
    return out.reshape(len(model.leg_maps), s + 1, 6, shapes.shape[1])


def platform_motion(model: SubstructureModel, shapes: np.ndarray) -> np.ndarray:
    """(6, n): (Delta_p, Phi_p) of the platform centre for each mode."""
    return shapes[model.platform_slice]


def leg_axis_displacements(model: SubstructureModel, leg_frames: np.ndarray,
                           shapes: np.ndarray, fractions) -> np.ndarray:
    """Translations of the leg axis at fractions t of B_i -> A_i, for each mode.

    The beam field is interpolated inside each segment as a frame element assumes it: linear
    axial displacement, cubic Hermite transverse displacement from end translations and
    rotations (theta_z = +dv/dx, theta_y = -dw/dx in the limb frame); a solid end zone is read
    the same way between its joint and interface nodes. Returns
    (3, len(fractions), 3, n) in base coordinates.
    """
    s = model.elements
    t = np.asarray(fractions, float)
    if np.any((t < 0) | (t > 1)):
        raise InputError(f"fractions {t.tolist()}: must lie in [0, 1]")
    nodal = leg_displacements(model, shapes)  # (3, s+1, 6, n)
    legs = len(model.leg_maps)
    out = np.empty((legs, len(t), 3, shapes.shape[1]))
    for i in range(legs):
        frame = leg_frames[i]
        along = np.linalg.norm(model.leg_nodes[i] - model.leg_nodes[i, 0], axis=1)
        stations = along / along[-1]  # node positions as fractions of the leg
        element = np.clip(np.searchsorted(stations, t, side="right") - 1, 0, s - 1)
        length = along[element + 1] - along[element]
        xi = (t - stations[element]) * along[-1] / length
        h1, h2 = 1 - 3 * xi**2 + 2 * xi**3, xi - 2 * xi**2 + xi**3
        h3, h4 = 3 * xi**2 - 2 * xi**3, -xi**2 + xi**3
        local_u = np.einsum("ba,kbn->kan", frame, nodal[i, :, :3, :])  # R_i^T u
        local_r = np.einsum("ba,kbn->kan", frame, nodal[i, :, 3:, :])
        a, b = element, element + 1
        lk = length[:, None]
        ax = (1 - xi)[:, None] * local_u[a, 0] + xi[:, None] * local_u[b, 0]
        v = (h1[:, None] * local_u[a, 1] + h2[:, None] * lk * local_r[a, 2]
             + h3[:, None] * local_u[b, 1] + h4[:, None] * lk * local_r[b, 2])
        w = (h1[:, None] * local_u[a, 2] - h2[:, None] * lk * local_r[a, 1]
             + h3[:, None] * local_u[b, 2] - h4[:, None] * lk * local_r[b, 1])
        local = np.stack([ax, v, w], axis=1)  # (nt, 3, n)
        out[i] = np.einsum("ab,kbn->kan", frame, local)
    return out


def leg_axis_twists(model: SubstructureModel, leg_frames: np.ndarray, shapes: np.ndarray,
                    fractions) -> np.ndarray:
    """Rotation of each leg's sections about its own axis (twist, rad) at fractions t of
    B_i -> A_i, for each mode: the torsion rotation interpolated linearly inside each element
    (as a frame element assumes it). Returns (3, len(fractions), n). A leg's torsion modes move
    no point of its axis: the pairing by shape needs this to see them."""
    s = model.elements
    t = np.asarray(fractions, float)
    if np.any((t < 0) | (t > 1)):
        raise InputError(f"fractions {t.tolist()}: must lie in [0, 1]")
    nodal = leg_displacements(model, shapes)  # (3, s+1, 6, n)
    out = np.empty((len(model.leg_maps), len(t), shapes.shape[1]))
    for i in range(len(model.leg_maps)):
        along = np.linalg.norm(model.leg_nodes[i] - model.leg_nodes[i, 0], axis=1)
        stations = along / along[-1]
        element = np.clip(np.searchsorted(stations, t, side="right") - 1, 0, s - 1)
        xi = (t - stations[element]) * along[-1] / (along[element + 1] - along[element])
        twist = np.einsum("b,kbn->kn", leg_frames[i][:, 0], nodal[i, :, 3:, :])
        out[i] = (1 - xi)[:, None] * twist[element] + xi[:, None] * twist[element + 1]
    return out


ENERGY_PARTS = ("legs", "joints", "drive", "platform")


def strain_energy_shares(model: SubstructureModel, shapes: np.ndarray) -> dict[str, np.ndarray]:
    """The share of each mode's strain energy x^T K x in each part of the machine: the joints'
    springs, the drive's, and the legs (the rest: every leg segment's elastic energy). The
    platform is rigid in this model, so its share is 0 by construction. Returns part ->
    (n,) fractions summing to 1 per mode."""
    total = np.einsum("qn,qp,pn->n", shapes, model.stiffness, shapes)
    out = {part: np.zeros(shapes.shape[1]) for part in ENERGY_PARTS}
    for part, block in (model.springs or {}).items():
        out[part] = np.einsum("qn,qp,pn->n", shapes, block, shapes) / total
    out["legs"] = 1.0 - out["joints"] - out["drive"]
    return out
