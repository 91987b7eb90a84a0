"""Reading results.json: load and check it, look values up by JSON pointer, pose geometry.

Nothing here computes physics. The only geometry is the pose itself (joint centres), taken from
the results file when it carries it and otherwise placed by Eq. (1) from the pose summary.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

SCHEMA = 1
CASE_KEYS = ("name", "pose", "analytical", "fem", "pairs")


def load_results(path) -> dict:
    """The parsed results file; ValueError naming the path if it is missing or malformed."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ValueError(f"{path}: results file not found") from None
    except OSError as exc:
        raise ValueError(f"{path}: cannot read results file ({exc.strerror})") from None
    try:
        results = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path}: not valid JSON (line {exc.lineno}, column {exc.colno}: "
                         f"{exc.msg})") from None
    if not isinstance(results, dict):
        raise ValueError(f"{path}: expected a JSON object at the top level")
    if results.get("schema") != SCHEMA:
        raise ValueError(f"{path}: schema {results.get('schema')!r}, this report reads "
                         f"schema {SCHEMA}")
    cases = results.get("cases")
    if not isinstance(cases, list) or not cases:
        raise ValueError(f"{path}: 'cases' must be a non-empty list")
    for i, case in enumerate(cases):
        if not isinstance(case, dict):
            raise ValueError(f"{path}: cases[{i}] is not an object")
        for key in CASE_KEYS:
            if key not in case:
                raise ValueError(f"{path}: cases[{i}] ({case.get('name', '?')!r}) lacks {key!r}")
        for model in ("analytical", "fem"):
            f = case[model].get("frequencies_hz") if isinstance(case[model], dict) else None
            if not isinstance(f, list) or not f or not all(_is_number(x) for x in f):
                raise ValueError(f"{path}: cases[{i}].{model}.frequencies_hz must be a "
                                 f"non-empty list of numbers")
        for j, pair in enumerate(case["pairs"]):
            for key in ("fem_mode", "analytical_mode", "f_fem_hz", "f_analytical_hz",
                        "error_percent", "mac"):
                if not _is_number(pair.get(key)):
                    raise ValueError(f"{path}: cases[{i}].pairs[{j}].{key} must be a number")
    for key in ("scene", "environment"):
        if not isinstance(results.get(key), dict):
            raise ValueError(f"{path}: {key!r} must be an object")
    results.setdefault("studies", {})
    return results


def _is_number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def resolve(doc, pointer: str):
    """The value at a JSON pointer ("/cases/0/pairs/1/mac")."""
    value = doc
    for token in pointer.split("/")[1:]:
        token = token.replace("~1", "/").replace("~0", "~")
        value = value[int(token)] if isinstance(value, list) else value[token]
    return value


def escape(token) -> str:
    return str(token).replace("~", "~0").replace("/", "~1")


def joint_points(case: dict) -> tuple[np.ndarray, np.ndarray]:
    """(B, A): R-joint centres on the base and S-joint centres on the platform, (3, 3) in m,
    as the pipeline's inverse kinematics placed them (pose.base_points_mm, platform_points_mm).
    """
    pose = case["pose"]
    try:
        return (np.asarray(pose["base_points_mm"], float) * 1e-3,
                np.asarray(pose["platform_points_mm"], float) * 1e-3)
    except KeyError as exc:
        raise ValueError(f"case {case.get('name')!r}: results lack pose.{exc.args[0]} "
                         "(rerun `make` with the current pipeline)") from None


def leg_axis_shapes(case: dict):
    """(stations, shapes (3 legs, n stations, 3, n modes)) of the beam model, or None.

    Accepts `analytical.leg_axis_shapes` ([leg][station][xyz][mode], with
    `analytical.leg_axis_stations` or stations 0..1 evenly spaced) or the flat `analytical.station_shapes` ((3 n, 3) x modes,
    leg-major, as pipeline.compare samples them).
    """
    a = case["analytical"]
    if a.get("leg_axis_shapes") is not None:
        shapes = np.asarray(a["leg_axis_shapes"], float)
    elif a.get("station_shapes") is not None:
        flat = np.asarray(a["station_shapes"], float)
        shapes = flat.reshape(3, -1, 3, flat.shape[-1])
    else:
        return None
    if shapes.ndim != 4 or shapes.shape[0] != 3 or shapes.shape[2] != 3:
        return None
    stations = a.get("leg_axis_stations") or a.get("stations")
    stations = np.asarray(stations or np.linspace(0, 1, shapes.shape[1]), float)
    if len(stations) != shapes.shape[1]:
        return None
    return stations, shapes
