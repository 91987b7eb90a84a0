"""Study: the cut's stability over the workspace map (results.studies.stability_map), in the
scenes that declare a [cutting] table.

On a grid of the workspace map's layers (MAP_LAYERS heights, RINGS rings of tilt up to the
regular workspace's radius, AZIMUTHS azimuths: the dynamic-stiffness map's grid, thinned), every
reachable pose's tool modes by the batched analytical model at the run's fidelity (the compared
modes and two more), turned into the cut's plane at that pose (the feed follows the platform),
and its lobes over MAP_SPEEDS speeds of the [cutting] range (or its exact list) by the scene's
method: per pose the least critical depth over the speeds, where it falls, the best speed and
its depth. The least over the map is the depth a programmer can cut at any pose and speed of
the range. The time is estimated from the first pose and said before the map starts.
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np

from common.errors import ComputeError
from results import Record, Section, StabilityLeast, StabilityMap, Table

from .dynamic_stiffness import map_grid
from .registry import Context, Study

MAP_LAYERS, RINGS, AZIMUTHS = 4, 4, 12  # the map's grid: 4 heights, 4 tilts, 12 azimuths
MAP_SPEEDS = 60  # speeds of a pose's lobes over the [cutting] range (its list: all of it)
SAY_ABOVE = 10.0  # s: a longer estimate is said on stderr before the map


def map_speeds(cutting) -> np.ndarray:
    """The speeds (rev/s) of every pose's lobes."""
    if cutting.spindle_list:
        return cutting.speeds_hz()
    return np.linspace(cutting.spindle[0], cutting.spindle[1], min(MAP_SPEEDS, cutting.speeds))


def stability_map(scene, layers: int = MAP_LAYERS, rings: int = RINGS,
                  azimuths: int = AZIMUTHS, say: bool = True) -> StabilityMap:
    from analytical.pose_batch import pose_batch
    from analytical.tool_response import summed_count, tool_modes_chunks
    from chatter.lobes import diagram, plan
    from chatter.tool_input import from_base

    start = time.perf_counter()
    cutting = scene.cutting
    speeds = map_speeds(cutting)
    heights, tilts, phis = map_grid(scene, layers, rings, azimuths)
    shape = (len(heights), tilts.shape[1], len(phis))
    z = np.broadcast_to(heights[:, None, None], shape).ravel()
    tilt = np.broadcast_to(tilts[:, :, None], shape).ravel()
    phi = np.broadcast_to(phis[None, None, :], shape).ravel()
    poses = pose_batch(scene.manipulator, z, phi, tilt)
    reached = np.flatnonzero(poses.feasible)
    if not len(reached):
        raise ComputeError("the stability map: no pose of its grid is reachable")
    batch = poses.take(reached)
    count = summed_count(scene.manipulator, scene.analytical, scene.fidelity.modes)
    n = len(reached)
    out = {key: np.full(n, np.nan) for key in ("least", "least_rpm", "best_rpm", "best",
                                                "chatter", "error")}
    kinds = np.full(n, "", object)
    estimate = None
    from dataclasses import replace
    sized = replace(cutting, spindle=(), spindle_list=tuple(speeds))
    for s, modes in tool_modes_chunks(scene.manipulator, scene.analytical, batch,
                                      scene.tool.point, count):
        rotations = batch.rotation[s]
        for k in range(modes.omega.shape[0]):
            tool = from_base(modes.omega[k], scene.damping.ratios(modes.omega[k]),
                             modes.phi[k], rotations[k], cutting.feed_direction)
            if estimate is None:
                estimate = plan(tool, sized).seconds * n
                if say and estimate > SAY_ABOVE:
                    print(f"stability map: {n} poses x {len(speeds)} speeds by "
                          f"{cutting.method}, about {estimate:.0f} s", file=sys.stderr)
            d = diagram(tool, cutting, speeds, estimate=False)
            i = s.start + k
            least, best = d.least, d.best
            out["best_rpm"][i] = d.speeds_hz[best] * 60
            out["best"][i] = d.depth[best] * 1e3
            if d.error_percent is not None:
                out["error"][i] = float(d.error_percent.max(initial=0.0))
            if least is not None:
                out["least"][i] = d.depth[least] * 1e3
                out["least_rpm"][i] = d.speeds_hz[least] * 60
                out["chatter"][i] = d.frequency_hz[least]
                kinds[i] = d.kind[least]

    def grid(values) -> list:
        full = np.full(z.size, None, object)
        full[reached] = [float(v) if np.isfinite(v) else None for v in values]
        return full.reshape(shape).tolist()

    rows = []
    if np.isfinite(out["least"]).any():
        k = int(np.nanargmin(out["least"]))
        pose = reached[k]
        rows.append(StabilityLeast(
            depth_mm=float(out["least"][k]), spindle_rpm=float(out["least_rpm"][k]),
            chatter_frequency_hz=float(out["chatter"][k]), kind=str(kinds[k]),
            height_mm=float(z[pose]) * 1e3, tilt_deg=math.degrees(float(tilt[pose])),
            azimuth_deg=math.degrees(float(phi[pose]))))
    errors = out["error"][np.isfinite(out["error"])]
    return StabilityMap(
        point_mm=[1e3 * v for v in scene.tool.point], method=cutting.method,
        analytical=scene.analytical.describe(), damping=scene.damping.describe(),
        speeds=len(speeds), spindle_rpm_range=[float(speeds.min()) * 60,
                                               float(speeds.max()) * 60],
        heights_mm=(heights * 1e3).tolist(), tilts_deg=np.degrees(tilts).tolist(),
        azimuths_deg=np.degrees(phis).tolist(),
        least_depth_mm=grid(out["least"]), least_rpm=grid(out["least_rpm"]),
        best_rpm=grid(out["best_rpm"]), best_depth_mm=grid(out["best"]),
        chatter_frequency_hz=grid(out["chatter"]),
        max_error_percent=float(errors.max()) if errors.size else None,
        least=rows, poses=int(n), estimated_seconds=float(estimate or 0.0),
        seconds=time.perf_counter() - start)


def run(ctx: Context) -> StabilityMap | None:
    if ctx.scene.cutting is None:  # the scene asks no cut: nothing computed
        return None
    return stability_map(ctx.scene)


STUDY = Study(Record(
    "stability_map", "scene", StabilityMap | None, None,
    Section("stability-map", "Stable cutting over the workspace: the least critical depth",
            None, asks="[cutting]", nothing="the cut is stable at every pose of the map and "
            "every speed, up to the search's ceiling"),
    (Table("least", ("depth_mm", "spindle_rpm", "chatter_frequency_hz", "kind", "height_mm",
                     "tilt_deg", "azimuth_deg"), each="least"),)),
    "scene", run)
