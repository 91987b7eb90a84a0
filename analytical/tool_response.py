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

from common.frf import tidy_groups, tool_rows

from .batch_solve import BatchModel, StandardForm, standard_modes
from .modal import solve_modes
from .substructure import SubstructureModel

SUPERPOSED_EXTRA = 2  # modes summed beyond the compared ones (the rest: residual flexibility)


@dataclass(frozen=True)
class ToolModes:
    """Modes at the tool of one pose (or a batch: a leading axis on every array)."""

    omega: np.ndarray  # (m,) rad/s, ascending
    phi: np.ndarray  # (3, m) tool displacement of each mass-normalised mode, base frame
    static: np.ndarray  # (3, 3) m/N, the static compliance at the tool, A K^-1 A^T
    next_omega: np.ndarray | float = np.inf  # the first mode left out of the sum (inf: none)

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
    count = min(count, n_q)
    modal = solve_modes(model, min(count + 1, n_q))  # one more: where the band must stop
    rows = _platform_rows(n_q, model.platform_slice, tool_rows(point, rotation))
    static = rows @ scipy.linalg.solve(model.stiffness, rows.T, assume_a="pos")
    omega = 2.0 * math.pi * modal.frequencies_hz
    phi, after = tidy_groups(omega[:count], rows @ modal.shapes[:, :count],
                             omega[count] if count < n_q else np.inf)
    return ToolModes(omega[:count], phi, 0.5 * (static + static.T), after)


def batch_tool_modes(model: BatchModel, form: StandardForm, rotations, point, count: int,
                     index=None) -> ToolModes:
    """The same for the poses `index` of a batch (default all), from its standard form
    (`batch_model.standard_form`, which has overwritten K and M). With K = U^T U and
    Y = U^-T A^T (one triangular solve of three right-hand sides): G0 = Y^T Y, and a mode
    x = U^-1 y / sqrt(mu) moves the tool by A x = Y^T y / sqrt(mu), so the modes' full
    shapes are never formed."""
    index = np.arange(len(form.matrices)) if index is None else np.asarray(index, int)
    n_q = len(form.matrices[0])
    count = min(count, n_q)
    rows = _platform_rows(n_q, model.platform_slice,
                          tool_rows(point, np.asarray(rotations, float)[index]))  # (n, 3, n_q)
    omega, phi, static = (np.empty((len(index), count)), np.empty((len(index), 3, count)),
                          np.empty((len(index), 3, 3)))
    after = np.full(len(index), np.inf)  # the first mode left out of the sum
    for k, pose in enumerate(index):
        mu, y = standard_modes(form, int(pose), min(count + 1, n_q))
        w = scipy.linalg.solve_triangular(form.factors[pose], rows[k].T, trans="T",
                                          check_finite=False)  # (n_q, 3)
        static[k] = w.T @ w
        omega[k] = 1.0 / np.sqrt(mu[:count])
        phi[k], after[k] = tidy_groups(omega[k], (w.T @ y[:, :count]) / np.sqrt(mu[:count]),
                                       1.0 / math.sqrt(mu[count]) if count < n_q else np.inf)
    return ToolModes(omega, phi, static, after)


MAP_CHUNK = 500  # poses assembled at once: K and M of 500 poses of 126 coordinates, 127 MB


def summed_count(manipulator, options, compared: int) -> int:
    """Modes a map sums at the tool: the compared ones and SUPERPOSED_EXTRA more (at most
    every coordinate's)."""
    from .batch_model import batch_coordinates

    return min(compared + SUPERPOSED_EXTRA, batch_coordinates(manipulator, options))


def tool_modes_chunks(manipulator, options, poses, point, count: int):
    """(slice, ToolModes) of the batch `poses` (feasible poses: `PoseBatch.take`), MAP_CHUNK
    poses at a time through the batched model: `count` modes at the tool point."""
    from .batch_model import assemble_batch, assembly_plan, batch_layout
    from .batch_solve import standard_form

    n = len(poses)
    plan = assembly_plan(batch_layout(manipulator, options, poses.base_joint,
                                      poses.platform_joint))
    for start in range(0, n, MAP_CHUNK):
        chunk = poses.take(np.arange(start, min(n, start + MAP_CHUNK)))
        model = assemble_batch(manipulator, chunk, options, plan)
        yield (slice(start, start + len(chunk)),
               batch_tool_modes(model, standard_form(model), chunk.rotation, point, count))


def least_stiffness_map(manipulator, options, poses, damping, point, compared: int,
                        lines: int):
    """The least dynamic stiffness at the tool along x, y, z of every pose of the batch
    `poses` (feasible poses: `PoseBatch.take`), each pose's band from 0 to
    common.frf.BAND_ABOVE times its highest compared mode on `lines` lines: the compared modes
    and SUPERPOSED_EXTRA more summed, the rest by their residual flexibility
    (common.frf.LeastStiffness (N, 3))."""
    from common.frf import (
        LeastStiffness,
        band_lines,
        least_dynamic_stiffness,
        residual_flexibility,
        summed_band_top,
    )

    n = len(poses)
    count = summed_count(manipulator, options, compared)
    stiffness, peak, mode = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3), int)
    for s, modes in tool_modes_chunks(manipulator, options, poses, point, count):
        residual = residual_flexibility(modes.static, modes.omega, modes.phi)
        band = band_lines(summed_band_top(modes.omega, compared, modes.next_omega, damping),
                          lines)
        least = least_dynamic_stiffness(band, modes.omega, damping.ratios(modes.omega),
                                        modes.phi, np.diagonal(residual, axis1=1, axis2=2))
        stiffness[s], peak[s], mode[s] = least.stiffness_n_per_m, least.peak_hz, least.mode
    return LeastStiffness(stiffness, peak, mode)
