"""Study: the first frequencies over the regular workspace, sorted and followed per family
(the paper's Fig. 6; results.studies.workspace)."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from typing_extensions import TypedDict

import results
from analytical.reach import layer_heights
from common.errors import ComputeError
from scene import Scene

from .registry import OWN_TEMPLATE, Context, Section, Study, own


def workspace_heights(scene: Scene, layers: int) -> np.ndarray:
    """Heights (m) of the map's layers, evenly over the reachable layer band
    (`analytical.reach.layer_band`)."""
    return layer_heights(scene.manipulator, layers)


MAP_LAYERS = 8  # height layers of the workspace map


def workspace_map(scene: Scene, layers: int = MAP_LAYERS, rings: int = 6, azimuths: int = 36,
                  modes: int = 3) -> results.Workspace:
    """The first `modes` frequencies over the regular workspace (the paper's Fig. 6), sorted
    and per family: each mode followed by its shape from pose to pose (MAC), so where two
    families cross the map shows it; the crossings are listed."""
    from analytical.workspace import frequency_map

    fmap = frequency_map(scene.manipulator, replace(scene.analytical, modes=modes),
                         workspace_heights(scene, layers), rings, azimuths)
    tracking = fmap.tracking
    if tracking is None:  # frequency_map always follows the families
        raise ComputeError("the workspace map was drawn without following its families")

    def listed(values):
        return np.where(np.isnan(values), None, values).tolist()

    per_leg = pose_values(scene.manipulator, fmap)

    return results.Workspace(
        heights_mm=(fmap.heights * 1e3).tolist(),
        regular_tilt_deg=np.degrees(fmap.radii).tolist(),
        tilts_deg=np.degrees(fmap.tilts).tolist(),
        azimuths_deg=np.degrees(fmap.azimuths).tolist(),
        frequencies_hz=listed(fmap.frequencies_hz),
        tracked_frequencies_hz=listed(fmap.tracked_hz),
        **per_leg,
        crossings=[results.Crossing(
            families=[a + 1, b + 1], height_mm=c.height * 1e3, tilt_deg=math.degrees(c.tilt),
            azimuth_deg=math.degrees(c.azimuth), frequency_hz=c.frequency_hz, along=c.along)
            for c in fmap.crossings for a, b in [c.families]],
        tracking=results.Tracking(
            families="f_k of family k at the level pose of the layer at "
                     f"{tracking.root_height * 1e3:.1f} mm, followed by MAC of leg and "
                     "platform shapes",
            root_height_mm=tracking.root_height * 1e3,
            modes_followed=tracking.window,
            steps=tracking.steps,
            steps_matched_by_shape=tracking.steps_with_shapes,
            poses_with_shapes=tracking.poses_with_shapes,
            min_mac=None if math.isnan(tracking.min_mac) else tracking.min_mac,
            open_rings=tracking.open_rings,
            lost_families=[j + 1 for j in tracking.lost]),
        settings=scene.analytical.describe())


class PerLeg(TypedDict):
    """Per map pose and leg: the fields of results.Workspace the report's hover shows."""
    actuation_mm: list
    s_joint_angles_deg: list
    r_joint_angles_deg: list


def pose_values(manipulator, fmap) -> PerLeg:
    """Per map pose and leg ([z][tilt][azimuth][leg], None where the map has no frequency):
    the locked actuator (mm) and the S- and R-joint angles (deg), for the report's hover."""
    from analytical.pose_batch import pose_batch

    z = np.broadcast_to(fmap.heights[:, None, None], fmap.frequencies_hz.shape[:3])
    tilt = np.broadcast_to(fmap.tilts[:, :, None], z.shape)
    phi = np.broadcast_to(fmap.azimuths[None, None, :], z.shape)
    batch = pose_batch(manipulator, z.ravel(), phi.ravel(), tilt.ravel())
    reached = np.isfinite(fmap.frequencies_hz[..., 0])

    def per_pose(values, scale):
        grid = (scale * values).reshape(z.shape + (values.shape[-1],)).tolist()
        return [[[leg if ok else None for leg, ok in zip(ring, ring_ok)]
                 for ring, ring_ok in zip(layer, layer_ok)]
                for layer, layer_ok in zip(grid, reached.tolist())]

    return PerLeg(actuation_mm=per_pose(batch.actuation, 1e3),
                  s_joint_angles_deg=per_pose(batch.s_joint_angles, 180 / math.pi),
                  r_joint_angles_deg=per_pose(batch.r_joint_angles, 180 / math.pi))


def run(ctx: Context) -> results.Workspace:
    return workspace_map(ctx.scene)


STUDY = Study(own("workspace", "scene", section=Section(
    "workspace", "Workspace maps", "workspace maps", OWN_TEMPLATE)), "scene", run)
