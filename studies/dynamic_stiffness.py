"""Study: the least dynamic stiffness at the tool over the workspace map (results.studies.
dynamic_stiffness), in the scenes that ask for it ([damping] or [tool]).

On the workspace map's grid (its layers, rings of tilt up to the regular workspace's radius,
azimuths), every reachable pose's tool receptance by the analytical model at the run's
fidelity (`analytical.tool_response.least_stiffness_map`: the compared modes and two more
summed, the rest by their residual flexibility, LINES lines from 0 Hz to the band's top), and
per direction 1 / max |H_dd|, the frequency of that peak and the mode that dominates it; the
least of each direction over the map and the pose where it occurs.
"""
from __future__ import annotations

import math
import time

import numpy as np

import results
from common.errors import ComputeError
from common.frf import DIRECTIONS, LINES
from results import Section, Table

from .registry import Context, Study, own
from .workspace_map import MAP_LAYERS, workspace_heights

RINGS, AZIMUTHS = 6, 36  # the workspace map's


def map_grid(scene, layers: int = MAP_LAYERS, rings: int = RINGS, azimuths: int = AZIMUTHS):
    """(heights (L,), tilts (L, R), azimuths (A,)) of the workspace map's grid, rad and m."""
    from analytical.reach import regular_radii

    heights = workspace_heights(scene, layers)
    radii = regular_radii(scene.manipulator, heights)
    return (heights, radii[:, None] * np.linspace(0.0, 1.0, rings)[None, :],
            np.linspace(0.0, 2 * math.pi, azimuths, endpoint=False))


def dynamic_stiffness_map(scene, layers: int = MAP_LAYERS, rings: int = RINGS,
                          azimuths: int = AZIMUTHS, lines: int = LINES
                          ) -> results.DynamicStiffnessMap:
    from analytical.batch_model import batch_coordinates
    from analytical.pose_batch import pose_batch
    from analytical.tool_response import SUPERPOSED_EXTRA, least_stiffness_map

    start = time.perf_counter()
    heights, tilts, phis = map_grid(scene, layers, rings, azimuths)
    shape = (len(heights), tilts.shape[1], len(phis))
    z = np.broadcast_to(heights[:, None, None], shape)
    tilt = np.broadcast_to(tilts[:, :, None], shape)
    phi = np.broadcast_to(phis[None, None, :], shape)
    poses = pose_batch(scene.manipulator, z.ravel(), phi.ravel(), tilt.ravel())
    reached = np.flatnonzero(poses.feasible)
    compared = scene.fidelity.modes
    least = least_stiffness_map(scene.manipulator, scene.analytical, poses.take(reached),
                                   scene.damping, scene.tool.point, compared, lines)

    def grid(values, cast=float) -> list:
        full = np.full(z.size, None, object)
        full[reached] = [cast(v) if np.isfinite(v) else None for v in values]
        return full.reshape(shape).tolist()

    if not len(reached):
        raise ComputeError("the dynamic stiffness map: no pose of its grid is reachable")
    rows = []
    for d, name in enumerate(DIRECTIONS):
        k = int(np.argmin(least.stiffness_n_per_m[:, d]))
        if not np.isfinite(least.stiffness_n_per_m[k, d]):
            continue  # the tool never moves along d (rows are for finite stiffness only)
        pose = reached[k]
        rows.append(results.LeastPose(direction=name,
                              stiffness_n_per_m=float(least.stiffness_n_per_m[k, d]),
                              frequency_hz=float(least.peak_hz[k, d]),
                              mode=int(least.mode[k, d]) + 1,
                              height_mm=float(z.ravel()[pose]) * 1e3,
                              tilt_deg=math.degrees(float(tilt.ravel()[pose])),
                              azimuth_deg=math.degrees(float(phi.ravel()[pose]))))
    summed = min(compared + SUPERPOSED_EXTRA,
                 batch_coordinates(scene.manipulator, scene.analytical))
    return results.DynamicStiffnessMap(
        point_mm=[1e3 * v for v in scene.tool.point], damping=scene.damping.describe(),
        analytical=scene.analytical.describe(), lines=lines, modes_summed=summed,
        heights_mm=(heights * 1e3).tolist(), tilts_deg=np.degrees(tilts).tolist(),
        azimuths_deg=np.degrees(phis).tolist(),
        stiffness_n_per_m={n: grid(least.stiffness_n_per_m[:, d])
                           for d, n in enumerate(DIRECTIONS)},
        peak_hz={n: grid(least.peak_hz[:, d]) for d, n in enumerate(DIRECTIONS)},
        mode={n: grid(least.mode[:, d] + 1, int) for d, n in enumerate(DIRECTIONS)},
        least=rows, poses=int(len(reached)), seconds=time.perf_counter() - start)


def run(ctx: Context) -> results.DynamicStiffnessMap | None:
    if not ctx.scene.dynamics_given:  # the scene does not ask: nothing computed
        return None
    return dynamic_stiffness_map(ctx.scene)


STUDY = Study(own(
    "dynamic_stiffness", "scene",
    section=Section("dynamic-stiffness", "Least dynamic stiffness at the tool over the "
                    "workspace", None,
                    asks="[damping] or [tool], a rigid platform"),
    tables=(Table("least", ("direction", "stiffness_n_per_m", "frequency_hz", "mode",
                            "height_mm", "tilt_deg", "azimuth_deg"), each="least"),)),
    "scene", run)
