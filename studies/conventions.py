"""Study: which reading of the paper's printed (phi, theta) of a tilted case best reproduces its
theoretical row (results.studies.angle_conventions); readings mapped to Eq. (1), none fitted."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

import results
from analytical.kinematics import rotation_y
from analytical.model import natural_frequencies
from analytical.params import Pose
from scene import Case, Scene

from .registry import PAPER_READING, Context, Study, floats, own


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


def angle_conventions(scene: Scene, case: Case) -> results.AngleConventions:
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
            entry["frequencies_hz"] = floats(f)
            entry["deviation_percent"] = floats(dev)
            entry["worst_percent"] = float(np.abs(dev).max())
        out.append(entry)
    return results.AngleConventions(case=case.name, azimuth_deg=math.degrees(phi),
                                    tilt_deg=math.degrees(theta), readings=out)


def run(ctx: Context) -> list[results.AngleConventions]:
    return [angle_conventions(ctx.scene, c) for c in convention_cases(ctx.scene)]


STUDY = Study(own("angle_conventions", "scene", section=PAPER_READING), "scene", run,
              profiles=("full", "ci"))
