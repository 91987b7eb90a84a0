"""Scene study: where the input uncertainty bites over the workspace: the 95 % band of f1 and
of the least dynamic stiffness at the tool (the least over x, y and z, where the scene has
[tool] or [damping]) along the workspace map's worst path, the pose of least nominal f1 on
each layer of the map's grid (studies.dynamic_stiffness.map_grid: 8 layers, 6 rings, 36
azimuths), lowest layer first (results.studies.uncertainty_path).

At each pose of the path the inputs are drawn PATH_SAMPLES times (a scrambled Sobol'
sequence) through the run's analytical model (solvers.uncertainty.band).
"""
from __future__ import annotations

import math
import time

import numpy as np

import results
from analytical.params import Pose
from results import Section, Table

from .dynamic_stiffness import map_grid
from .registry import Context, Study, own
from .uncertainty import BUDGET_SECONDS

CHUNK = 256


def worst_path(scene) -> list[tuple[int, Pose, float]]:
    """(layer, pose, nominal f1 in Hz) of the least f1 of each layer of the map's grid."""
    from analytical.batch_model import assemble_batch
    from analytical.batch_solve import frequencies
    from analytical.pose_batch import pose_batch

    heights, tilts, phis = map_grid(scene)
    shape = (len(heights), tilts.shape[1], len(phis))
    z = np.broadcast_to(heights[:, None, None], shape).ravel()
    tilt = np.broadcast_to(tilts[:, :, None], shape).ravel()
    phi = np.broadcast_to(phis[None, None, :], shape).ravel()
    poses = pose_batch(scene.manipulator, z, phi, tilt)
    f1 = np.full(len(z), np.inf)
    reached = np.flatnonzero(poses.feasible)
    for first in range(0, len(reached), CHUNK):
        index = reached[first:first + CHUNK]
        model = assemble_batch(scene.manipulator, poses.take(index), scene.analytical)
        f1[index] = frequencies(model, 1)[:, 0]
    per_layer = f1.reshape(len(heights), -1)
    out = []
    for layer, row in enumerate(per_layer):
        k = int(np.argmin(row))
        if math.isfinite(row[k]):
            flat = layer * per_layer.shape[1] + k
            out.append((layer + 1, Pose(height=float(z[flat]), azimuth=float(phi[flat]),
                                        tilt=float(tilt[flat])), float(row[k])))
    return out


def run(ctx: Context) -> results.UncertaintyPath | None:
    from solvers.uncertainty import PATH_SAMPLES, OverBudget, band, nominal, run_model

    scene = ctx.scene
    if scene.uncertainty is None:
        return None
    start = time.perf_counter()
    how = ("per layer of the workspace map's grid, the pose of least nominal f1; "
           f"{PATH_SAMPLES} scrambled Sobol' draws of the inputs at each")
    options = run_model(scene, scene.analytical)
    why = None
    path = worst_path(scene)
    rows: list[results.PathPose] = []
    skipped: list[str] = []
    try:
        bands = band(scene, options, [p for _, p, _ in path], scene.fidelity.modes,
                     budget_seconds=BUDGET_SECONDS) if path else []
    except OverBudget as exc:
        why, bands = str(exc), []
    tool = bool(scene.dynamics_given)
    for (layer, pose, _), found in zip(path, bands):
        if "refused" in found:  # a sample out of reach at this pose: no band drawn there
            skipped.append(f"layer {layer}: {found['refused']}")
            continue
        at_scene = nominal(scene, options, pose, scene.fidelity.modes, tool)  # the band's model
        f1 = float(at_scene.frequencies_hz[0, 0])
        least = None if at_scene.least_n_per_m is None else float(np.min(at_scene.least_n_per_m))
        q = found.get("least_n_per_m")
        rows.append(results.PathPose(
            layer=layer, height_mm=pose.height * 1e3, tilt_deg=math.degrees(pose.tilt),
            azimuth_deg=math.degrees(pose.azimuth), f1_nominal_hz=f1,
            f1_q025_hz=found["f1_hz"][0], f1_median_hz=found["f1_hz"][1],
            f1_q975_hz=found["f1_hz"][2],
            least_nominal_n_per_m=None if least is None else float(least),
            least_q025_n_per_m=None if q is None else q[0],
            least_median_n_per_m=None if q is None else q[1],
            least_q975_n_per_m=None if q is None else q[2]))
    return results.UncertaintyPath(path=how, samples=PATH_SAMPLES,
                                   model=options.describe(), refused=why, poses=rows,
                                   skipped=skipped, seconds=time.perf_counter() - start)


STUDY = Study(own(
    "uncertainty_path", "scene",
    section=Section("uncertainty-path", "Input uncertainty over the workspace", None,
                    asks="[uncertainty]"),
    tables=(Table("path", ("layer", "height_mm", "tilt_deg", "azimuth_deg", "f1_nominal_hz",
                           "f1_q025_hz", "f1_median_hz", "f1_q975_hz", "least_nominal_n_per_m",
                           "least_q025_n_per_m", "least_q975_n_per_m"), each="poses"),)),
    "scene", run)
