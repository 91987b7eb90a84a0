"""The lowest natural frequency over the whole reachable workspace, found adaptively.

A designer asks for the least f_k over every pose the machine reaches, not at a pose. The
reachable workspace is `reach`'s (one definition): heights in the level band, and at every
(height z, tilt azimuth phi) the tilts from the level platform out to the largest reachable one,
theta_max(z, phi) (`reach.max_tilts`; a tilt of -theta at phi is the tilt theta at phi + 180
degrees, so theta >= 0 covers every orientation of zero torsion). A pose is written
(z, phi, u) with theta = u theta_max(z, phi), u in [0, 1]: a box, whose face u = 1 is the
workspace's boundary.

1. Coarse: f_k on a grid of the box (heights x azimuths x tilt fractions, u = 1 included),
   batched (`batch_model`: assembled and solved together).
2. Local: from the `starts` lowest grid points (distinct cells), Nelder-Mead in the box (bounded;
   robust where two modes cross and f_k has a kink), each step the pose's f_k with theta_max
   found to 1e-10 rad. The least value found is the answer, with its pose and whether it lies
   on the boundary (u = 1) or at an end of the level band.

tests/test_minimum.py proves it against dense maps on every shipped scene (and machines of
both architectures drawn at random): never above the dense map's least value by more than
0.05 %.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import minimize

from common.errors import RpsError

from .batch_model import CHUNK, assemble_batch, assembly_plan, batch_layout
from .batch_solve import frequencies
from .model import natural_frequencies
from .params import Manipulator, ModelOptions, Pose
from .pose_batch import pose_batch
from .reach import LevelBand, level_band, max_tilt, max_tilts

TILT_TOLERANCE = 1e-10  # rad: theta_max of the local search's poses
COARSE = (9, 24, 5)  # heights x azimuths x tilt fractions of the coarse grid
STARTS = 3  # local searches, from the lowest grid points of distinct basins
RELATIVE_TOLERANCE = 1e-6  # Nelder-Mead stops when its simplex's values agree to this
MAX_STEPS = 120  # poses solved by one local search at most


@dataclass(frozen=True)
class WorkspaceMinimum:
    """The least f_k (Hz) over the reachable workspace, where, and how it was found."""

    frequency_hz: float
    mode: int  # k, 1-based
    pose: Pose
    boundary: bool  # theta at theta_max(z, phi): on the workspace's boundary
    band_end: bool  # z at an end of the level band
    coarse_hz: float  # the least value on the coarse grid
    evaluations: int  # poses solved, coarse and local
    band: LevelBand  # the heights searched: the level band (`reach.level_band`)


def grid_frequencies(manipulator: Manipulator, options: ModelOptions, heights, azimuths,
                     tilts) -> np.ndarray:
    """f_1..f_modes (Hz) of the poses (heights, azimuths, tilts) (equal shapes), batched;
    NaN where a pose is unreachable."""
    z, phi, theta = (np.ravel(a) for a in np.broadcast_arrays(heights, azimuths, tilts))
    out = np.full((len(z), options.modes), np.nan)
    m = manipulator
    plan = assembly_plan(batch_layout(m, options, m.base_joint, m.platform_joint))  # once
    for start in range(0, len(z), CHUNK):
        part = slice(start, start + CHUNK)
        poses = pose_batch(manipulator, z[part], phi[part], theta[part])
        ok = np.flatnonzero(poses.feasible)
        if len(ok):
            model = assemble_batch(manipulator, poses.take(ok), options, plan)
            out[start + ok] = frequencies(model, options.modes)
    return out.reshape(np.shape(np.broadcast_arrays(heights, azimuths, tilts)[0])
                       + (options.modes,))


def workspace_minimum(manipulator: Manipulator, options: ModelOptions, mode: int = 1,
                      coarse: tuple[int, int, int] = COARSE,
                      starts: int = STARTS) -> WorkspaceMinimum:
    """The least f_mode over the reachable workspace (the module doc)."""
    m = manipulator
    opts = replace(options, modes=max(mode, 1))
    band = level_band(m)  # WorkspaceError when no level pose is reachable
    scale = band.high - band.low
    nz, nphi, nu = coarse
    # the box's interior on a coarse grid, its face u = 1 (the boundary) four times finer in z:
    # near the band's ends theta_max changes fast, and f_k is often least on the boundary
    grids = []
    for heights, fractions in ((np.linspace(0.0, 1.0, nz), np.linspace(0.0, 1.0, nu)),
                               (np.linspace(0.0, 1.0, 4 * (nz - 1) + 1), np.array([1.0]))):
        phis = np.linspace(0.0, 2 * math.pi, nphi, endpoint=False)
        top = max_tilts(m, band.low + heights * scale, phis, 1e-9)
        x, p, u = np.meshgrid(heights, phis, fractions, indexing="ij")
        theta = u * top[:, :, None]
        hz = grid_frequencies(m, opts, band.low + x * scale, p, theta)[..., mode - 1]
        grids.append((x, p, u, theta, hz))
    evaluations = sum(int(np.isfinite(g[-1]).sum()) for g in grids)
    spacing = np.array([1.0 / (4 * max(nz - 1, 1)), math.pi / nphi, 0.5 / max(nu - 1, 1)])

    def pose_of(x) -> Pose:
        zz = band.low + float(np.clip(x[0], 0.0, 1.0)) * scale
        phi = float(x[1]) % (2 * math.pi)
        theta = float(np.clip(x[2], 0.0, 1.0)) * max_tilt(m, zz, phi, TILT_TOLERANCE)
        return Pose(zz, phi, theta)

    def value(x) -> float:
        nonlocal evaluations
        evaluations += 1
        try:  # a pose the tilt ray's bisection stepped over, or a model that cannot solve
            return float(natural_frequencies(m, pose_of(x), opts)[mode - 1])
        except RpsError:
            return math.inf

    candidates = sorted(
        (float(hz.flat[n]), float(x.flat[n]), float(p.flat[n]), float(u.flat[n]),
         float(theta.flat[n]))
        for x, p, u, theta, hz in grids for n in np.flatnonzero(np.isfinite(hz)))
    best_f, best_x = candidates[0][0], np.array(candidates[0][1:4])
    chosen: list[np.ndarray] = []
    for f0, x0, p0, u0, theta0 in candidates:
        if len(chosen) >= starts:
            break
        where = np.array([x0 * scale, theta0 * math.cos(p0), theta0 * math.sin(p0)])
        if any(np.all(np.abs(where - c) <= [2.5 * spacing[0] * scale, 0.05, 0.05])
               for c in chosen):
            continue  # the same basin as a search already started (or the same pose)
        chosen.append(where)
        on_face = u0 >= 1.0
        if on_face:  # along the boundary: (z, phi) at u = 1
            fun = lambda y: value([y[0], y[1], 1.0])  # noqa: E731
            y0, bounds = np.array([x0, p0]), [(0.0, 1.0), (None, None)]
        else:
            fun, y0, bounds = value, np.array([x0, p0, u0]), [(0.0, 1.0), (None, None),
                                                              (0.0, 1.0)]
        step = spacing[:len(y0)]
        simplex = np.vstack([y0] + [y0 + np.eye(len(y0))[d] * step[d]
                                    * (1 if y0[d] < 0.5 or d == 1 else -1)
                                    for d in range(len(y0))])
        res = minimize(fun, y0, method="Nelder-Mead", bounds=bounds,
                       options={"initial_simplex": simplex, "xatol": 1e-7,
                                "fatol": RELATIVE_TOLERANCE * f0, "maxfev": MAX_STEPS})
        if res.fun < best_f:
            best_f = float(res.fun)
            best_x = np.array([res.x[0], res.x[1], 1.0 if on_face else res.x[2]])
    pose = pose_of(best_x)  # its tilt to TILT_TOLERANCE: the value is the model's there
    best_f = float(natural_frequencies(m, pose, opts)[mode - 1])
    return WorkspaceMinimum(best_f, mode, pose, boundary=bool(best_x[2] >= 1.0 - 1e-9),
                            band_end=bool(best_x[0] <= 1e-9 or best_x[0] >= 1.0 - 1e-9),
                            coarse_hz=candidates[0][0], evaluations=evaluations, band=band)

