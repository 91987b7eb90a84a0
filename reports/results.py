"""Reading results.json: one load checked against the schema (results.schema), values by
JSON pointer, and the pose and mode-shape arrays the pictures draw.

Nothing here computes physics: joint centres, leg-axis shapes and platform motions are read as
the pipeline wrote them.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from results import AnalyticalRecord, Case, FemRecord, Manipulator, Record, Results, read


def load_results(path, records: Sequence[Record]) -> Results:
    """The checked results file (`records`: the registry of study records); InputError (one
    line, naming the path) otherwise."""
    return read(path, records)


def has_paper(results: Results) -> bool:
    """Do the results carry the paper's data (any case with its rows)?"""
    return any(c["paper"] for c in results["cases"])


def main_cases(results: Results) -> list[Case]:
    """The cases with paper rows (all cases if none has them): the report's main subject."""
    return [c for c in results["cases"] if c["paper"]] or results["cases"]


def resolve(doc, pointer: str):
    """The value at a JSON pointer ("/cases/0/pairs/1/mac")."""
    value = doc
    for token in pointer.split("/")[1:]:
        token = token.replace("~1", "/").replace("~0", "~")
        value = value[int(token)] if isinstance(value, list) else value[token]
    return value


def escape(token) -> str:
    return str(token).replace("~", "~0").replace("/", "~1")


def joint_points(case: Case) -> tuple[np.ndarray, np.ndarray]:
    """(B, A): the joint centres on the base and on the platform, (legs, 3) in m."""
    pose = case["pose"]
    return (np.asarray(pose["base_points_mm"], float) * 1e-3,
            np.asarray(pose["platform_points_mm"], float) * 1e-3)


def base_circle_points(manipulator: Manipulator) -> np.ndarray:
    """The base circle's points B_i of a results' manipulator record (a 3-PRS's rail feet),
    (legs, 3) in m."""
    angles = np.radians(manipulator["leg_angles_deg"])
    return manipulator["base_radius_mm"] * 1e-3 * np.stack(
        [np.cos(angles), np.sin(angles), np.zeros(len(angles))], axis=1)


def platform_centre(case: Case) -> np.ndarray:
    """The platform centre o, (3,) in m."""
    return np.asarray(case["pose"]["centre_mm"], float) * 1e-3


def leg_axis_shapes(case: Case) -> tuple[np.ndarray, np.ndarray]:
    """(stations, shapes (legs, stations, 3, modes)) of the beam model, m."""
    a = case["analytical"]
    return np.asarray(a["leg_axis_stations"], float), np.asarray(a["leg_axis_shapes"], float)


def platform_motion(record: FemRecord | AnalyticalRecord, mode: int
                    ) -> tuple[np.ndarray, np.ndarray]:
    """(translation of o, rotation) of one mode (1-based) of a model record, m and rad."""
    motion = np.asarray(record["platform_motion"], float)[:, mode - 1]
    return motion[:3], motion[3:]
