"""Hard cases: the workspace boundary and the joint limits."""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from analytical.architectures import actuation, height_reach
from analytical.kinematics import PoseError
from analytical.model import analyse, natural_frequencies
from analytical.params import Manipulator, Pose
from analytical.pose_batch import pose_batch
from analytical.reach import layer_heights, max_tilts, regular_radius
from common.errors import InputError
from scene import Scene

from .base import Row, checked_residuals

# --- workspace boundary and joint limits ----------------------------------------------------

def boundary_ring(scene: Scene, layers: int = 5, azimuths: int = 72) -> Row:
    """On the regular workspace's boundary (tilt theta_r(z) at every azimuth theta_r was
    found on) every pose is reachable and solves with residual below 1e-8; 1e-5 rad further
    out, the azimuth that bounds theta_r is unreachable. Measured: the worst residual, or 1
    for a pose on the wrong side."""
    m, opts = scene.manipulator, scene.analytical
    phis = np.linspace(0, 2 * math.pi, azimuths, endpoint=False)
    worst = 0.0
    for z in layer_heights(m, layers):
        radius = regular_radius(m, float(z), azimuths)
        bounding = phis[np.argmin(max_tilts(m, float(z), phis))]
        for phi in phis:
            try:
                modal = analyse(m, Pose(float(z), float(phi), radius), opts).modal
            except PoseError:
                return Row("workspace boundary", "a boundary pose is unreachable", 0.0, 1.0)
            worst = max(worst, float(checked_residuals(modal).max()))
        if pose_batch(m, z, bounding, radius + 1e-5).feasible[0]:
            return Row("workspace boundary", "the boundary is not where theta_r says", 0.0, 1.0)
    return Row("workspace boundary", "residual at every boundary pose (5 layers x 72 "
               "azimuths); beyond it unreachable", 1e-8, worst, "relative")


# limit -> (the phrase PoseError uses, a change that makes it bind somewhere);
LIMITS: dict[str, tuple[str, dict[str, Any]]] = {
    # the actuator's: a 3-RPS's leg lengths, a 3-PRS's slider travels (analytical.architecture)
    "actuator_min": ("outside the (actuator range|slider stroke)", {}),
    "actuator_max": ("outside the (actuator range|slider stroke)", {}),
    "s_joint_max": ("S-joint", {}),
    "r_joint_max": ("R-joint", {"r_joint_max": math.radians(15.0)}),
}


def limit_pose(m: Manipulator, limit: str) -> Pose:
    """A pose where `limit` of Eq. (25) binds: the largest tilt reachable at some (height,
    azimuth), found to 1e-12 rad, with `limit` the constraint closest to violation there."""
    act = actuation(m)
    for z in np.linspace(0.0, 1.0, 41)[1:] * (height_reach(m) + m.base_radius):
        phis = np.linspace(0, 2 * math.pi, 24, endpoint=False)
        tilts = max_tilts(m, float(z), phis, 1e-12)
        poses = pose_batch(m, z, phis, tilts)
        for k in np.flatnonzero(poses.feasible & (tilts > 0)):
            margins = {
                "actuator_min": (poses.actuation[k] - act.low).min(),
                "actuator_max": (act.high - poses.actuation[k]).min(),
                "s_joint_max": (m.s_joint_max - np.abs(poses.s_joint_angles[k])).min(),
                "r_joint_max": (m.r_joint_max - np.abs(poses.r_joint_angles[k])).min(),
            }
            if min(margins, key=lambda k: margins[k]) == limit:
                return Pose(float(z), float(phis[k]), float(tilts[k]))
    raise InputError(f"no pose of this machine has {limit} binding")


def joint_limit(scene: Scene, limit: str) -> Row:
    """At a pose where one limit of Eq. (25) binds, the model solves as anywhere else: the
    frequencies 1e-6 rad inside the limit differ from those at the limit by less than 1e-4
    (relative), i.e. nothing jumps at the edge (the test also checks that 1e-6 rad beyond the
    pose is refused, naming the limit)."""
    m = replace(scene.manipulator, **LIMITS[limit][1])
    act = actuation(m)
    shown = {"actuator_min": act.low_key[:-3], "actuator_max": act.high_key[:-3]}.get(limit, limit)
    case = (f"joint limit {shown} ({scene.manipulator.base_joint}-"
            f"{scene.manipulator.platform_joint})")
    try:
        pose = limit_pose(m, limit)
    except ValueError as exc:
        return Row(case, "nothing to test", 1e-4, 0.0, note=str(exc))
    inside = replace(pose, tilt=pose.tilt - 1e-6)
    f_edge = natural_frequencies(m, pose, scene.analytical)
    f_in = natural_frequencies(m, inside, scene.analytical)
    return Row(case, "relative change of every frequency over the last 1e-6 rad before the "
               "limit", 1e-4,
               float(np.abs(f_edge / f_in - 1).max()), "relative")
