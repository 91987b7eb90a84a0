"""The scene's model against the test, stated as V&V 20 states a validation (solvers/vv20.py):
per fitted test mode, E the scene's model (its values as given) against the measured frequency,
u_num the beam model's discretisation (its change when its elements are doubled, as a bound),
u_input the scene's [uncertainty] propagated at the pose (solvers/uncertainty.py), u_D the
identification's frequency noise (stated, or from the fit's residuals). The identified model's
error is listed beside it but not judged: it was fitted to these data."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from analytical.model import natural_frequencies
from analytical.params import MAX_ELEMENTS, ModelOptions
from common.errors import InputError
from results.campaign_records import FitPose, NoiseRecord, PoseCorrelation, ValidationRecord
from solvers import vv20

from .campaign import Campaign

# draws of the inputs for u_input at each pose: a standard deviation from 128 scrambled Sobol'
# points is within about 6 % of itself (1 / sqrt(2 x 128)), plenty for an uncertainty
SAMPLES = 128


def validation(campaign: Campaign, options: ModelOptions, at_scene: list[PoseCorrelation],
               fit: list[FitPose], noise: NoiseRecord) -> tuple[list[ValidationRecord], str]:
    """The rows and a note of what u_input is (or why it is missing)."""
    from solvers.uncertainty import refusal, spread_percent

    scene = campaign.scene
    u_d = noise["frequency_percent"]
    why = ("the scene declares no [uncertainty]" if scene.uncertainty is None
           else refusal(scene, options))
    if why is None:  # the inputs' ends as whole machines, as `rps uncertainty` checks them
        from scene import parse_scene
        from scene.uncertainty import check_ends
        try:
            check_ends(scene.uncertainty, scene.raw, scene.path, parse_scene)
        except InputError as exc:
            why = str(exc)
    finer = replace(options, elements=min(2 * options.elements, MAX_ELEMENTS))
    rows: list[ValidationRecord] = []
    for tp, pose_fit, pose_pairs in zip(campaign.poses, fit, at_scene):
        partner = {p["test_mode"]: p["model_mode"] for p in pose_pairs["pairs"]}
        wanted = [partner[m["test_mode"]] for m in pose_fit["modes"] if m["test_mode"] in partner]
        if not wanted:
            continue
        count = max(wanted)
        coarse = np.asarray(natural_frequencies(scene.manipulator, tp.pose,
                                                replace(options, modes=count)))
        fine = np.asarray(natural_frequencies(scene.manipulator, tp.pose,
                                              replace(finer, modes=count)))
        u_num = [None if finer == options else vv20.from_bound(100.0 * (c / f - 1.0))
                 for c, f in zip(coarse, fine)]  # at the most elements: no finer model
        spread = None
        if why is None:
            try:
                spread = spread_percent(scene, options, tp.pose, count, SAMPLES)
            except InputError as exc:  # a sample out of reach, or not a machine
                why = f"at pose {tp.name}: {exc}"
        for m in pose_fit["modes"]:
            j = partner.get(m["test_mode"])
            if j is None:
                continue
            u_input = None if spread is None else float(spread[j - 1])
            u_val = vv20.u_val(u_num[j - 1], u_input, u_d)
            rows.append(ValidationRecord(
                pose=tp.name, test_mode=m["test_mode"], model_mode=j, test_hz=m["test_hz"],
                model_hz=m["before_hz"], e_percent=m["error_before_percent"],
                e_identified_percent=m["error_after_percent"],
                u_num_percent=u_num[j - 1], u_input_percent=u_input,
                u_d_percent=u_d, u_val_percent=u_val,
                verdict=vv20.verdict(m["error_before_percent"], u_num[j - 1], u_val,
                                     "the test")))
    note = ("u_input: the scene's [uncertainty] through the fitted model at each pose "
            f"({options.describe()}, {SAMPLES} draws)" if why is None else f"no u_input: {why}")
    return rows, note
