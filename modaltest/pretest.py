"""The way back to the test engineer: the model's modes at chosen points as a UFF file (nodes
2411, modes 55) for their test software, and where to put the sensors (effective independence).

Effective independence (Kammer 1991): from candidate sensor dofs with the target modes' shapes
Phi (dofs x modes), repeatedly drop the dof contributing least to the linear independence of the
modes, E = diag(Phi (Phi^T Phi)^-1 Phi^T), until the wanted number is left. It keeps the
Fisher information det(Phi^T Phi) of the modes high, so the shapes stay distinguishable and the
MAC pairing unambiguous.
"""
from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from analytical.kinematics import PoseGeometry
from analytical.params import Manipulator
from common.errors import InputError

from . import uff
from .placement import ModeField, place, sample

MAX_POINTS = 2000  # points of a prediction file at most


def candidate_points(manipulator: Manipulator, geometry: PoseGeometry) -> np.ndarray:
    """(n, 3) candidate sensor points (m, base frame): the platform's top face on two rings
    of 12 and every leg's surface at nine stations, four sides each."""
    points = []
    for ring in (0.45, 0.9):
        r = ring * manipulator.platform_radius * (1.0 if manipulator.platform_shape == "disk"
                                                  else 0.45)
        for k in range(12):
            a = 2 * math.pi * k / 12
            local = np.array([r * math.cos(a), r * math.sin(a),
                              0.5 * manipulator.platform_thickness])
            points.append(geometry.platform_centre + geometry.rotation @ local)
    leg = manipulator.leg
    for i in range(geometry.leg_count):
        frame = geometry.leg_frames[i]
        for t in np.linspace(0.1, 0.9, 9):
            along = t * geometry.leg_lengths[i]
            radius = 0.5 * (manipulator.leg_diameter if not leg.stepped else
                            leg.housing_outer_diameter if along <= leg.housing_length
                            else leg.rod_outer_diameter)
            for side in range(4):
                a = side * math.pi / 2
                offset = radius * (math.cos(a) * frame[:, 1] + math.sin(a) * frame[:, 2])
                points.append(geometry.base_points[i] + along * frame[:, 0] + offset)
    return np.array(points)


def read_points(path: Path) -> np.ndarray:
    """(n, 3) points (m) from a CSV of x_mm, y_mm, z_mm (a header row allowed)."""
    try:
        rows = list(csv.reader(path.read_text(encoding="utf-8").splitlines()))
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"--points {path}: cannot be read ({exc})") from None
    out = []
    for k, row in enumerate(rows):
        if not row or (k == 0 and not _numbers(row)):
            continue
        if len(row) != 3 or not _numbers(row):
            raise InputError(f"--points {path}: line {k + 1} {','.join(row)!r}: expected "
                             "three numbers x_mm, y_mm, z_mm")
        out.append([float(v) * 1e-3 for v in row])
    if not out or len(out) > MAX_POINTS:
        raise InputError(f"--points {path}: {len(out)} points; expected 1 to {MAX_POINTS}")
    return np.array(out)


def _numbers(row: list[str]) -> bool:
    try:
        return all(math.isfinite(float(v)) for v in row)
    except ValueError:
        return False


def effective_independence(shapes: np.ndarray, count: int) -> np.ndarray:
    """Indices (ascending) of the `count` rows of `shapes` (dofs x modes) kept by effective
    independence."""
    keep = np.arange(shapes.shape[0])
    if count < shapes.shape[1]:
        raise InputError(f"{count} sensor dofs cannot tell {shapes.shape[1]} modes apart; give "
                         f"at least {shapes.shape[1]}")
    while len(keep) > count:
        phi = shapes[keep]
        q, _ = np.linalg.qr(phi)
        e = np.sum(q * q, axis=1)  # diag of the projector Phi (Phi^T Phi)^-1 Phi^T
        keep = np.delete(keep, int(np.argmin(e)))
    return keep


def prediction(field: ModeField, manipulator: Manipulator, geometry: PoseGeometry,
               points: np.ndarray, modes: int, tolerance: float,
               where: str) -> tuple[uff.Nodes, uff.Modes]:
    """The model's lowest `modes` modes at `points` (triaxial), as UFF records."""
    ids = np.arange(1, len(points) + 1)
    placements = place(manipulator, geometry, ids, points, tolerance, where)
    node = np.repeat(ids, 3)
    direction = np.tile(np.eye(3), (len(ids), 1))
    shapes = sample(field, geometry, placements, node, direction)[:, :modes]
    hz = np.asarray(field.frequencies_hz[:modes], float)
    return uff.Nodes(ids, points), uff.Modes(hz, None, uff.Dofs(node, direction), shapes)
