"""Modal solve of the reduced model, Eqs. (23)-(24), and expansion of the mode shapes."""
from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
import scipy.linalg

from .substructure import SubstructureModel


class ModalError(RuntimeError):
    """The eigenproblem has no physical answer (not positive definite, non-finite)."""


@dataclass(frozen=True)
class ModalResult:
    frequencies_hz: np.ndarray  # (n,), ascending
    shapes: np.ndarray  # (18s, n) mass-normalised eigenvectors in independent coordinates


def solve_modes(model: SubstructureModel, count: int) -> ModalResult:
    """Lowest `count` modes of (K - omega^2 M) Phi = 0, Eq. (23); f = omega / 2 pi, Eq. (24)."""
    n = model.stiffness.shape[0]
    if count > n:
        raise ModalError(f"modes = {count}: the model has only {n} coordinates")
    if not (np.all(np.isfinite(model.stiffness)) and np.all(np.isfinite(model.mass))):
        raise ModalError("the reduced matrices hold non-finite entries (singular joint map?)")
    try:
        eigval, eigvec = scipy.linalg.eigh(model.stiffness, model.mass)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise ModalError(f"eigen solve failed: {exc}") from exc
    eigval, eigvec = eigval[:count], eigvec[:, :count]
    if eigval[0] <= 0.0:
        raise ModalError(f"lowest eigenvalue {eigval[0]:.3e} rad^2/s^2 is not positive: "
                         "the structure is a mechanism")
    return ModalResult(np.sqrt(eigval) / (2.0 * math.pi), eigvec)


def leg_displacements(model: SubstructureModel, shapes: np.ndarray) -> np.ndarray:
    """Nodal displacements and rotations of every leg for each mode.

    Returns (3, s+1, 6, n): leg, node, (u_x, u_y, u_z, theta_x, theta_y, theta_z), mode.
    """
    s = model.elements
    out = np.stack([t @ shapes for t in model.leg_maps])
    return out.reshape(3, s + 1, 6, shapes.shape[1])


def platform_motion(model: SubstructureModel, shapes: np.ndarray) -> np.ndarray:
    """(6, n): (Delta_p, Phi_p) of the platform centre for each mode."""
    return shapes[model.platform_slice]
