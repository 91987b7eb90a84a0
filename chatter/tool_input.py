"""The tool's modes in the cut's plane, from wherever they come: a model's modes at the tool
(base frame, with the platform's rotation at the pose), `rps frf`'s frf.json, or a table of
modes as a tap test gives them.

The cut's frame: z the platform normal (the tool axis), x the feed direction in the platform's
plane at `feed_direction` from the platform's x axis about z, y = z x x. A mode's
mass-normalised tool displacement phi (base frame) reads U_x = e_x . phi, U_y = e_y . phi."""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from common.errors import InputError

from .milling import ToolModes

MAX_MODES = 200  # a tool-modes table of more modes is not a tap test


def cut_axes(rotation, feed_direction: float) -> np.ndarray:
    """(2, 3): the cut's x and y axes in base coordinates."""
    r = np.asarray(rotation, float)
    c, s = math.cos(feed_direction), math.sin(feed_direction)
    return np.stack([r @ np.array([c, s, 0.0]), r @ np.array([-s, c, 0.0])])


def from_base(omega, zeta, phi_base, rotation, feed_direction: float) -> ToolModes:
    """Modes with tool displacements phi (3, m) in base coordinates, in the cut's plane."""
    return ToolModes(np.asarray(omega, float), np.asarray(zeta, float),
                     cut_axes(rotation, feed_direction) @ np.asarray(phi_base, float))


def read_modes(data: Any, where: str, feed_direction: float) -> ToolModes:
    """A tool-modes file's content (parsed JSON or TOML): `rps frf`'s frf.json (its modes in
    the base frame, turned into the cut's with its platform rotation), or
    `modes = [{frequency_hz, damping_ratio, tool_shape_per_sqrt_kg = {x, y}}]` already in the
    cut's plane. InputError naming the file and the first bad entry."""
    if not isinstance(data, dict):
        raise InputError(f"{where}: expected a table with `modes` (a JSON object or TOML)")
    frf = data.get("record") == "frf"
    unknown = set(data) - {"modes", "name", "source"}
    if unknown and not frf:
        raise InputError(f"{where}: unknown key {sorted(unknown)[0]!r} (a tool-modes file "
                         "holds `modes`, and optionally `name` and `source`)")
    modes = data.get("modes")
    if not isinstance(modes, list) or not modes:
        raise InputError(f"{where}: `modes` must be a non-empty list of "
                         "{frequency_hz, damping_ratio, tool_shape_per_sqrt_kg}")
    if len(modes) > MAX_MODES:
        raise InputError(f"{where}: {len(modes)} modes, more than {MAX_MODES}")
    axes = ("x", "y", "z") if frf else ("x", "y")
    omega, zeta, shape = [], [], []
    for k, m in enumerate(modes):
        at = f"{where}: modes[{k}]"
        if not isinstance(m, dict):
            raise InputError(f"{at}: expected a table")
        extra = set(m) - {"frequency_hz", "damping_ratio", "tool_shape_per_sqrt_kg"}
        if extra and not frf:
            raise InputError(f"{at}: unknown key {sorted(extra)[0]!r}")
        f = _number(m.get("frequency_hz"), f"{at}.frequency_hz")
        z = _number(m.get("damping_ratio"), f"{at}.damping_ratio")
        if f <= 0:
            raise InputError(f"{at}.frequency_hz = {f:g}: expected a frequency above 0 Hz")
        if z <= 0:
            raise InputError(f"{at}.damping_ratio = {z:g}: expected a ratio above 0 (an "
                             "undamped mode chatters at any depth)")
        u = m.get("tool_shape_per_sqrt_kg")
        if not isinstance(u, dict) or set(u) - set(axes) or not u \
                or not (frf or set(u) & {"x", "y"}):
            raise InputError(f"{at}.tool_shape_per_sqrt_kg: expected {{"
                             + ", ".join(axes) + "} (1/sqrt(kg), mass-normalised)")
        omega.append(2 * math.pi * f)
        zeta.append(z)
        shape.append([_number(u.get(a, 0.0), f"{at}.tool_shape_per_sqrt_kg.{a}")
                      for a in axes])
    phi = np.array(shape).T
    if frf:
        rotation = data.get("platform_rotation")
        if rotation is None:
            raise InputError(f"{where}: a frf.json without platform_rotation (written before "
                             "rps lobes existed): write it again with rps frf")
        try:
            r = np.asarray(rotation, float)
        except (TypeError, ValueError):
            r = np.zeros(0)
        if r.shape != (3, 3) or not np.allclose(r @ r.T, np.eye(3), atol=1e-6):
            raise InputError(f"{where}: platform_rotation is not a 3 x 3 rotation")
        return from_base(omega, zeta, phi, r, feed_direction)
    return ToolModes(np.array(omega), np.array(zeta), phi)


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) \
            or not math.isfinite(value):
        raise InputError(f"{where} = {value!r}: expected a finite number")
    return float(value)
