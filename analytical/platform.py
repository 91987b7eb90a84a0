"""Rigid moving platform: mass and inertia about its centre o (paper Eqs. 7-9).

The paper gives only r2 and the thickness h; the plate outline is a scene choice ("disk" of
radius r2, or the "triangle" A1A2A3). Eq. (8) puts m r2^2 on all three rotational axes; that
simplification is kept as `platform_inertia = "paper-eq8"` so its effect can be shown. The plate
formulas themselves live in `common.plate` (tested against closed forms there).
"""
from __future__ import annotations

import numpy as np

from common.errors import InputError
from common.payload import payload_mass_matrix
from common.plate import plate_area as _area
from common.plate import plate_inertia, plate_mass, rigid_mass_matrix

from .params import Manipulator


def plate_area(manipulator: Manipulator) -> float:
    return _area(manipulator.platform_shape, manipulator.platform_radius)


def platform_mass(manipulator: Manipulator) -> float:
    """m_p = rho * area * h."""
    m = manipulator
    return plate_mass(m.platform_shape, m.platform_radius, m.platform_thickness,
                      m.material.density)


def platform_inertia_body(manipulator: Manipulator, form: str = "plate") -> np.ndarray:
    """3x3 rotational inertia about o in the platform frame (z normal to the plate).

    "plate": the homogeneous plate (thickness included, `common.plate`). "paper-eq8": m r2^2 on
    every axis, as printed in Eq. (8).
    """
    m = manipulator
    if form == "paper-eq8":
        return platform_mass(m) * m.platform_radius**2 * np.eye(3)
    if form != "plate":
        raise InputError(f"platform_inertia = {form!r}: expected plate or paper-eq8")
    return plate_inertia(m.platform_shape, m.platform_radius, m.platform_thickness,
                         m.material.density)


def platform_mass_matrix(manipulator: Manipulator, rotation: np.ndarray,
                         form: str = "plate") -> np.ndarray:
    """6x6 mass matrix on (Delta_p, Phi_p) in base coordinates, Eqs. (7)-(9): T_p oM_p T_p^T,
    with the scene's payload (`common.payload`) fixed to the plate."""
    plate = rigid_mass_matrix(platform_mass(manipulator),
                              platform_inertia_body(manipulator, form), rotation)
    if manipulator.payload.mass == 0.0:  # no payload (it has no inertia without mass)
        return plate
    return plate + payload_mass_matrix(manipulator.payload, rotation)
