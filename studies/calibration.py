"""Study: the paper's height calibration, recomputed from the code so the scene's calibrated
height can be checked (results.studies.height_calibration)."""
from __future__ import annotations

from dataclasses import replace

import results
from analytical.calibration import calibrate_height
from scene import Case, Scene

from .registry import PAPER_READING, Context, Study, floats, own


def calibration_case(scene: Scene) -> Case | None:
    """The case the scene's calibrated height is checked on: the first case at the calibrated
    height that carries the paper's theoretical row (None when there is none)."""
    return next((c for c in scene.cases.values()
                 if c.height_origin == "calibrated" and c.paper_theory_hz), None)


def height_calibration(scene: Scene, case: Case) -> results.HeightCalibration:
    """Recompute the height calibration on `case`'s theoretical row and say how the scene's
    value compares: a results.HeightCalibration."""
    opts = replace(scene.analytical, elements=3, beam="euler-bernoulli", platform_inertia="plate")
    cal = calibrate_height(scene.manipulator, case.pose, case.paper_theory_hz, opts)
    return results.HeightCalibration(
        case=case.name,
        computed_height_mm=cal.height * 1e3,
        scene_height_mm=(None if scene.calibrated_height is None
                         else scene.calibrated_height * 1e3),
        worst_deviation_percent=100 * cal.worst_deviation,
        deviation_percent=floats(100 * cal.deviations),
        settings=f"Euler-Bernoulli, s = 3, {scene.manipulator.platform_shape} plate inertia")


def run(ctx: Context) -> results.HeightCalibration | None:
    case = calibration_case(ctx.scene)
    return None if case is None else height_calibration(ctx.scene, case)


STUDY = Study(own("height_calibration", "scene", section=PAPER_READING), "scene", run,
              profiles=("full", "ci"))
