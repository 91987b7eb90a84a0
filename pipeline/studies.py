"""Studies of the analytical model that the report plots (pure functions of a scene).

- element convergence s = 1..10 (the paper's Fig. 3),
- Euler-Bernoulli vs Timoshenko, true plate inertia vs Eq. (8),
- angle conventions: which reading of (phi, theta) best reproduces the paper's row of a
  tilted case,
- the height calibration, recomputed from the code so the scene value can be checked.
Which cases the paper studies run for is read from the scene (`calibration_case`,
`convention_cases`), never from case names.
"""
from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np

from analytical.calibration import calibrate_height
from analytical.kinematics import rotation_y
from analytical.model import natural_frequencies
from analytical.params import ModelOptions, Pose
from analytical.reach import layer_heights

import results
from scene import Case, Scene

ELEMENT_RANGE = tuple(range(1, 11))


def _hz(values) -> list[float]:
    return [float(v) for v in values]


def element_convergence(scene: Scene, case: Case, beam: str = "euler-bernoulli") -> dict:
    """Frequencies for s = 1..10 elements per leg, for one beam theory."""
    rows = []
    for s in ELEMENT_RANGE:
        opts = replace(scene.analytical, elements=s, beam=beam)
        rows.append(_hz(natural_frequencies(scene.manipulator, case.pose, opts)))
    return results.ElementConvergence(elements=list(ELEMENT_RANGE), beam=beam,
                                      frequencies_hz=rows)


def _setting(base: ModelOptions, beam: str, elements: int, shear: str = "cowper",
             joint_ends: str = "beam", platform_inertia: str = "plate") -> ModelOptions:
    """The scene's analytical options with one compared setting in place."""
    return replace(base, beam=beam, elements=elements, shear=shear, joint_ends=joint_ends,
                   platform_inertia=platform_inertia)


def model_variants(scene: Scene) -> dict[str, ModelOptions]:
    """The analytical settings compared throughout: the paper's and ours. Every Timoshenko
    label names its shear coefficient (analytical.beam: Cowper's or Hutchinson's); "solid
    ends" are the condensed solid end zones at the joints (analytical.end_zones)."""
    base = scene.analytical
    eb, timo = "euler-bernoulli", "timoshenko"
    return {
        "paper (EB, s=3, Eq. 8 inertia)": _setting(base, eb, 3, platform_inertia="paper-eq8"),
        "EB, s=3, plate inertia": _setting(base, eb, 3),
        "Timoshenko (Cowper), s=3, plate inertia": _setting(base, timo, 3),
        "Timoshenko (Hutchinson), s=3, plate inertia": _setting(base, timo, 3, "hutchinson"),
        "Timoshenko (Cowper), s=10, plate inertia": _setting(base, timo, 10),
        "Timoshenko (Hutchinson), s=5, solid ends, plate inertia": _setting(
            base, timo, 5, "hutchinson", joint_ends="solid"),
    }


SOLID_END_ELEMENTS = (1, 2, 3, 4, 5)  # s of the beam middle between two solid end zones


def speed_settings(scene: Scene) -> dict[str, ModelOptions]:
    """Every analytical setting whose time and error the speed-vs-error plot shows: beam
    theories (with their shear coefficient) at s = 1..10, and Timoshenko (Hutchinson) middles
    between solid end zones."""
    base, out = scene.analytical, {}
    for beam, shear, tag in (("euler-bernoulli", "cowper", "EB"),
                             ("timoshenko", "cowper", "Timoshenko (Cowper)"),
                             ("timoshenko", "hutchinson", "Timoshenko (Hutchinson)")):
        for s in (1, 2, 3, 5, 10):
            out[f"{tag}, s={s}"] = _setting(base, beam, s, shear)
    for s in SOLID_END_ELEMENTS:
        out[f"Timoshenko (Hutchinson) + solid ends, s={s}"] = _setting(
            base, "timoshenko", s, "hutchinson", joint_ends="solid")
    return out


def time_model(scene: Scene, case: Case, options: ModelOptions, runs: int = 30) -> float:
    """Median wall time (s) of one pose: kinematics, synthesis and eigen solve."""
    natural_frequencies(scene.manipulator, case.pose, options)
    samples = []
    for _ in range(runs):
        start = time.perf_counter()
        natural_frequencies(scene.manipulator, case.pose, options)
        samples.append(time.perf_counter() - start)
    return float(np.median(samples))


def _tilt_azimuth(rotation: np.ndarray) -> tuple[float, float]:
    """Tilt and azimuth of the platform normal of any rotation (torsion dropped: a 3-RPS with
    zero-torsion T&T angles cannot reach it)."""
    normal = rotation[:, 2]
    return math.atan2(normal[1], normal[0]), math.acos(max(-1.0, min(1.0, normal[2])))


def convention_cases(scene: Scene) -> list[Case]:
    """The tilted cases with the paper's theoretical row: where the reading of its angles
    matters (a level pose reads the same in every convention)."""
    return [c for c in scene.cases.values()
            if c.paper_theory_hz and (c.pose.tilt != 0.0 or c.pose.azimuth != 0.0)]


def calibration_case(scene: Scene) -> Case | None:
    """The case the scene's calibrated height is checked on: the first case at the calibrated
    height that carries the paper's theoretical row (None when there is none)."""
    return next((c for c in scene.cases.values()
                 if c.height_origin == "calibrated" and c.paper_theory_hz), None)


def angle_conventions(scene: Scene, case: Case) -> dict:
    """Plausible readings of the paper's printed (phi, theta) of a tilted case, each mapped to
    our Eq. (1) parameters (none fitted), against the paper's theoretical row: a
    results.AngleConventions."""
    phi, theta = case.pose.azimuth, case.pose.tilt
    rx = lambda a: np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)],
                             [0, math.sin(a), math.cos(a)]])
    readings = {
        "Eq. (1) as printed: phi = azimuth, theta = tilt": (phi, theta),
        "theta sign flipped": (phi, -theta),
        "roles swapped: phi = tilt, theta = azimuth": (theta, phi),
        "Section 2 wording: theta about x, then phi about y (R = Rx Ry)":
            _tilt_azimuth(rx(theta) @ rotation_y(phi)),
        "phi about y, then theta about x (R = Ry Rx)": _tilt_azimuth(rotation_y(phi) @ rx(theta)),
        "phi measured from the base y-axis": (phi + math.pi / 2, theta),
    }
    target = np.asarray(case.paper_theory_hz)
    out = []
    for name, (azimuth, tilt) in readings.items():
        pose = Pose(case.pose.height, azimuth, tilt)
        entry = results.ConventionReading(
            reading=name, azimuth_deg=math.degrees(azimuth), tilt_deg=math.degrees(tilt),
            frequencies_hz=None, deviation_percent=None, worst_percent=None, note=None)
        try:
            f = natural_frequencies(scene.manipulator, pose,
                                    replace(scene.analytical, modes=len(target)))
        except ValueError as exc:
            entry["note"] = " ".join(str(exc).split())
        else:
            dev = 100 * (f / target - 1)
            entry.update(frequencies_hz=_hz(f), deviation_percent=_hz(dev),
                         worst_percent=float(np.abs(dev).max()))
        out.append(entry)
    return results.AngleConventions(case=case.name, azimuth_deg=math.degrees(phi),
                                    tilt_deg=math.degrees(theta), readings=out)


def height_calibration(scene: Scene, case: Case) -> dict:
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
        deviation_percent=_hz(100 * cal.deviations),
        settings=f"Euler-Bernoulli, s = 3, {scene.manipulator.platform_shape} plate inertia")


def workspace_heights(scene: Scene, layers: int) -> np.ndarray:
    """Heights (m) of the map's layers, evenly over the reachable layer band
    (`analytical.reach.layer_band`)."""
    return layer_heights(scene.manipulator, layers)


MAP_LAYERS = 8  # height layers of the workspace map


def workspace_map(scene: Scene, layers: int = MAP_LAYERS, rings: int = 6, azimuths: int = 36,
                  modes: int = 3) -> dict:
    """The first `modes` frequencies over the regular workspace (the paper's Fig. 6), sorted
    and per family: each mode followed by its shape from pose to pose (MAC), so where two
    families cross the map shows it; the crossings are listed."""
    from analytical.workspace import frequency_map

    fmap = frequency_map(scene.manipulator, replace(scene.analytical, modes=modes),
                         workspace_heights(scene, layers), rings, azimuths)
    tracking = fmap.tracking

    def listed(values):
        return np.where(np.isnan(values), None, values).tolist()

    return results.Workspace(**{
        "heights_mm": (fmap.heights * 1e3).tolist(),
        "regular_tilt_deg": np.degrees(fmap.radii).tolist(),
        "tilts_deg": np.degrees(fmap.tilts).tolist(),
        "azimuths_deg": np.degrees(fmap.azimuths).tolist(),
        "frequencies_hz": listed(fmap.frequencies_hz),
        "tracked_frequencies_hz": listed(fmap.tracked_hz),
        "crossings": [{"families": [a + 1, b + 1], "height_mm": c.height * 1e3,
                       "tilt_deg": math.degrees(c.tilt), "azimuth_deg": math.degrees(c.azimuth),
                       "frequency_hz": c.frequency_hz, "along": c.along}
                      for c in fmap.crossings for a, b in [c.families]],
        "tracking": {
            "families": "f_k of family k at the level pose of the layer at "
                        f"{tracking.root_height * 1e3:.1f} mm, followed by MAC of leg and "
                        "platform shapes",
            "root_height_mm": tracking.root_height * 1e3,
            "modes_followed": tracking.window,
            "steps": tracking.steps,
            "steps_matched_by_shape": tracking.steps_with_shapes,
            "poses_with_shapes": tracking.poses_with_shapes,
            "min_mac": None if math.isnan(tracking.min_mac) else tracking.min_mac,
            "open_rings": tracking.open_rings,
            "lost_families": [j + 1 for j in tracking.lost],
        },
        "settings": f"{scene.analytical.beam}, s = {scene.analytical.elements}, "
                    f"{scene.analytical.platform_inertia} inertia",
    })
