"""The reachable workspace of a scene's machine, checked before any expensive work.

`check(scene, profile)` runs in about a second: every case of the scene (whatever the profile)
must be reachable, the machine must have a band of heights whose level pose is reachable
(`analytical.reach.level_band`; the studies' layers, maps and samplers live in it) at least
MIN_BAND wide, and it computes the poses the workspace studies will use. It raises ValueError
(one line, naming the case or the binding limit and its value) or returns the
`results.ReachableWorkspace` record: the band, what bounds it, and every way a study adapted to
the machine (a narrow band, layers that cannot tilt, designed poses left out).
"""
from __future__ import annotations

import math

import numpy as np

import results as schema
from analytical.architectures import height_reach
from analytical.kinematics import PoseError, pose_geometry
from analytical.reach import (
    LAYER_INSET,
    LAYER_INSET_SHARE,
    WorkspaceError,
    layer_band,
    level_band,
    regular_radii,
)
from scene import Scene
from studies.workspace_map import MAP_LAYERS, workspace_heights
from studies.workspace_validation import FULL, SMALL, design_with_dropped

from .registry import OWN_TEMPLATE, Section, Study, own

MIN_BAND = 1e-3  # m: a level band narrower than this leaves the layered studies nothing to map
FLAT_TILT = math.radians(0.01)  # a layer whose theta_r is below this cannot tilt every way


def case_keys(name: str, case) -> str:
    """A case's pose as the scene file gives it: `cases.NAME.height_mm = 490 (azimuth_deg =
    10, tilt_deg = -12)`, the calibrated height shown as such."""
    p = case.pose
    angles = f"azimuth_deg = {math.degrees(p.azimuth):g}, tilt_deg = {math.degrees(p.tilt):g}"
    if case.height_origin == "calibrated":
        return (f"calibration.height.value_mm = {p.height * 1e3:g} (the height of "
                f"cases.{name}, {angles})")
    return f"cases.{name}.height_mm = {p.height * 1e3:g} ({angles})"


def check(scene: Scene, profile: str = "full") -> schema.ReachableWorkspace:
    """The scene's reachable workspace (see the module docstring); ValueError if a case is
    unreachable or the workspace is empty or too thin for the studies."""
    m = scene.manipulator
    for name, case in scene.cases.items():  # every case, whatever the profile
        try:
            pose_geometry(m, case.pose)
        except PoseError as exc:
            raise PoseError(f"{case_keys(name, case)}: {exc}") from None
    band = level_band(m)  # WorkspaceError (a ValueError) names the binding limit
    if band.width < MIN_BAND:
        raise WorkspaceError(
            f"the level pose of this machine is reachable only between z = {band.low * 1e3:.3f} "
            f"and {band.high * 1e3:.3f} mm (bounded by {band.bounding_text()}): narrower than "
            f"{MIN_BAND * 1e3:g} mm, too thin for the workspace studies")
    low, high = layer_band(m)
    heights = workspace_heights(scene, MAP_LAYERS)
    radii = regular_radii(m, heights)
    poses, dropped = design_with_dropped(m, FULL if profile == "full" else SMALL)
    adaptations = []
    if LAYER_INSET * height_reach(m) > LAYER_INSET_SHARE * band.width:
        adaptations.append(
            f"the level band is {band.width * 1e3:.1f} mm wide: the study layers keep a quarter "
            f"of it ({LAYER_INSET_SHARE * band.width * 1e3:.1f} mm) from each end instead of "
            f"{LAYER_INSET:.0%} of the height reach ({height_reach(m) * 1e3:.1f} mm)")
    flat = heights[radii < FLAT_TILT]
    if len(flat):
        adaptations.append(
            f"{len(flat)} of {len(heights)} layers (z = "
            f"{', '.join(f'{z * 1e3:.1f}' for z in flat)} mm) cannot tilt in every direction "
            "(theta_r = 0): their rings are level poses")
    if dropped:
        adaptations.append(f"workspace validation: {dropped} of {len(poses) + dropped} designed "
                           "poses are unreachable and were left out")
    return schema.ReachableWorkspace(
        level_band_mm=[band.low * 1e3, band.high * 1e3],
        bounded_by=[band.binding_low, band.binding_high],
        layer_band_mm=[low * 1e3, high * 1e3],
        regular_tilt_deg=np.degrees(radii).tolist(),
        validation_poses=len(poses), validation_poses_dropped=dropped,
        adaptations=adaptations)


STUDY = Study(own("reachable_workspace", "scene", section=Section(
    "scene", "Scene and set-up", "the scene", OWN_TEMPLATE)), "check", None,
    profiles=("full", "ci"))
