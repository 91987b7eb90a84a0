"""Rigid moving platform: mass and inertia about its centre o (paper Eqs. 7-9).

The paper gives only r2 and the thickness h; the plate outline is a scene choice ("disk" of
radius r2, or the "triangle" A1A2A3). Eq. (8) puts m r2^2 on all three rotational axes; that
simplification is kept as `platform_inertia = "paper-eq8"` so its effect can be shown.
"""
from __future__ import annotations

import math

import numpy as np

from .params import Manipulator


def plate_area(manipulator: Manipulator) -> float:
    r2 = manipulator.platform_radius
    if manipulator.platform_shape == "disk":
        return math.pi * r2**2
    if manipulator.platform_shape == "triangle":
        side = math.sqrt(3.0) * r2
        return math.sqrt(3.0) / 4.0 * side**2
    raise ValueError(f"platform_shape = {manipulator.platform_shape!r}: unknown")


def platform_mass(manipulator: Manipulator) -> float:
    """m_p = rho * area * h."""
    return manipulator.material.density * plate_area(manipulator) * manipulator.platform_thickness


def platform_inertia_body(manipulator: Manipulator, form: str = "plate") -> np.ndarray:
    """3x3 rotational inertia about o in the platform frame (z normal to the plate).

    "plate": the homogeneous plate (thickness included): disk I_xx = I_yy = m(3r^2 + h^2)/12,
    I_zz = m r^2/2; equilateral triangle of side a: I_xx = I_yy = m a^2/24 + m h^2/12,
    I_zz = m a^2/12. "paper-eq8": m r2^2 on every axis, as printed in Eq. (8).
    """
    m = platform_mass(manipulator)
    r2, h = manipulator.platform_radius, manipulator.platform_thickness
    if form == "paper-eq8":
        return m * r2**2 * np.eye(3)
    if form != "plate":
        raise ValueError(f"platform_inertia = {form!r}: expected plate or paper-eq8")
    if manipulator.platform_shape == "disk":
        inplane = m * (3 * r2**2 + h**2) / 12.0
        polar = m * r2**2 / 2.0
    else:
        side = math.sqrt(3.0) * r2
        inplane = m * side**2 / 24.0 + m * h**2 / 12.0
        polar = m * side**2 / 12.0
    return np.diag([inplane, inplane, polar])


def platform_mass_matrix(manipulator: Manipulator, rotation: np.ndarray,
                         form: str = "plate") -> np.ndarray:
    """6x6 mass matrix on (Delta_p, Phi_p) in base coordinates, Eqs. (7)-(9): T_p oM_p T_p^T."""
    mass = np.zeros((6, 6))
    mass[:3, :3] = platform_mass(manipulator) * np.eye(3)
    mass[3:, 3:] = rotation @ platform_inertia_body(manipulator, form) @ rotation.T
    return mass
