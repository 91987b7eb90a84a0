"""A homogeneous plate of thickness h: area, mass and rotational inertia about its centre.

Outlines: "disk" of radius r, or the equilateral "triangle" inscribed in the circle of radius r
(vertices at the joint points A_i). Inertia in the plate's frame, z normal to the plate:
disk I_xx = I_yy = m (3 r^2 + h^2) / 12, I_zz = m r^2 / 2; triangle of side a = sqrt(3) r:
I_xx = I_yy = m a^2 / 24 + m h^2 / 12, I_zz = m a^2 / 12.
"""
from __future__ import annotations

import math

import numpy as np

from .errors import InputError

PLATE_SHAPES = ("disk", "triangle")


def plate_area(shape: str, radius: float) -> float:
    if shape == "disk":
        return math.pi * radius**2
    if shape == "triangle":
        side = math.sqrt(3.0) * radius
        return math.sqrt(3.0) / 4.0 * side**2
    raise InputError(f"platform_shape = {shape!r}: expected one of {', '.join(PLATE_SHAPES)}")


def plate_mass(shape: str, radius: float, thickness: float, density: float) -> float:
    """m = rho * area * h."""
    return density * plate_area(shape, radius) * thickness


def plate_inertia(shape: str, radius: float, thickness: float, density: float) -> np.ndarray:
    """3x3 rotational inertia about the centre, plate frame (z normal), kg m^2."""
    m = plate_mass(shape, radius, thickness, density)
    h = thickness
    if shape == "disk":
        inplane, polar = m * (3 * radius**2 + h**2) / 12.0, m * radius**2 / 2.0
    else:
        side = math.sqrt(3.0) * radius
        inplane, polar = m * side**2 / 24.0 + m * h**2 / 12.0, m * side**2 / 12.0
    return np.diag([inplane, inplane, polar])


def rigid_mass_matrix(mass: float, inertia_body: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """6x6 mass matrix on (translation, rotation) of the centre in base coordinates:
    diag(m I, R J R^T) (the paper's Eqs. (7)-(9))."""
    out = np.zeros((6, 6))
    out[:3, :3] = mass * np.eye(3)
    out[3:, 3:] = rotation @ inertia_body @ rotation.T
    return out
