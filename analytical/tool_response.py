"""The analytical model's modes at the tool point, and its static compliance there: what
`common.frf` turns into the tool's receptance, its modal table and its least dynamic stiffness.

One pose (`tool_modes`) from the assembled K and M, or a batch of poses (`batch_tool_modes`)
from the batched standard form: the static compliance G0 = A K^-1 A^T from the Cholesky factor
the eigen solve already made (K = U^T U: G0 = Y^T Y with U^T Y = A^T, one triangular solve of
three right-hand sides a pose), so a map of the dynamic stiffness costs the eigenvectors of the
modes it sums and little else.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from common.frf import tool_rows

from .batch_model import BatchModel, StandardForm, batch_modes
from .modal import solve_modes
from .substructure import SubstructureModel

SUPERPOSED_EXTRA = 6  # modes summed beyond the compared ones (the rest: residual flexibility)


@dataclass(frozen=True)
class ToolModes:
    """Modes at the tool of one pose (or a batch: a leading axis on every array)."""

    omega: np.ndarray  # (m,) rad/s, ascending
    phi: np.ndarray  # (3, m) tool displacement of each mass-normalised mode, base frame
    static: np.ndarray  # (3, 3) m/N, the static compliance at the tool, A K^-1 A^T

    @property
    def frequencies_hz(self) -> np.ndarray:
        return self.omega / (2.0 * math.pi)


def _platform_rows(n_q: int, platform: slice, rows: np.ndarray) -> np.ndarray:
    """A (..., 3, n_q): the tool's rows on the platform's six coordinates, zero elsewhere."""
    full = np.zeros(rows.shape[:-1] + (n_q,))
    full[..., platform] = rows
    return full


def tool_modes(model: SubstructureModel, rotation, point, count: int) -> ToolModes:
    """The lowest `count` modes (at most every coordinate's) of one assembled pose at the
    tool point `point` (platform frame, m), the platform turned by `rotation`."""
    n_q = model.stiffness.shape[0]
    modal = solve_modes(model, min(count, n_q))
    rows = _platform_rows(n_q, model.platform_slice, tool_rows(point, rotation))
    static = rows @ scipy.linalg.solve(model.stiffness, rows.T, assume_a="pos")
    omega = 2.0 * math.pi * modal.frequencies_hz
    return ToolModes(omega, rows @ modal.shapes, 0.5 * (static + static.T))


def batch_tool_modes(model: BatchModel, form: StandardForm, rotations, point, count: int,
                     index=None) -> ToolModes:
    """The same for the poses `index` of a batch (default all), from its standard form
    (`batch_model.standard_form`, which has overwritten K and M)."""
    index = np.arange(len(form.matrices)) if index is None else np.asarray(index, int)
    n_q = len(form.matrices[0])
    hz, shapes = batch_modes(form, index, min(count, n_q))
    rows = _platform_rows(n_q, model.platform_slice,
                          tool_rows(point, np.asarray(rotations, float)[index]))  # (n, 3, n_q)
    static = np.empty((len(index), 3, 3))
    for k, pose in enumerate(index):  # U^T Y = A^T, G0 = Y^T Y
        y = scipy.linalg.solve_triangular(form.factors[pose], rows[k].T, trans="T",
                                          check_finite=False)
        static[k] = y.T @ y
    return ToolModes(2.0 * math.pi * hz, rows @ shapes, static)
