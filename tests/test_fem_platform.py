"""The FEM's rigid platform: mass and inertia integrated over its own meshed plate
(fem_reference.rigid_platform), checked against the closed forms of a homogeneous plate."""
from __future__ import annotations

import math

import numpy as np
import pytest

from analytical.kinematics import pose_geometry
from common.plate import plate_inertia, plate_mass
from common.rigid_body import rigid_body_mass
from fem_reference.rigid_platform import meshed_plate_mass
from meshing.bodies import Plate, platform_plate

R, H, RHO = 0.2, 0.02, 7820.0
CORNERS = tuple((R * math.cos(a), R * math.sin(a), 0.0) for a in (0.0, 2 * math.pi / 3,
                                                                  4 * math.pi / 3))


def _closed_form(shape):
    out = np.zeros((6, 6))
    out[:3, :3] = plate_mass(shape, R, H, RHO) * np.eye(3)
    out[3:, 3:] = plate_inertia(shape, R, H, RHO)
    return out


# Tolerances: the triangle's faces are flat, so its P2 elements are straight and the quadrature
# (order 4) integrates rho and rho x x^T exactly: round-off only. The disk's rim is a circle
# that the curved (quadratic isoparametric) elements follow to O((size / r)^4) in area; at the
# default size 0.2 r that is measured at 1e-6 (2e-7 at 0.1 r), so 1e-5 leaves a margin of
# ten without hiding a wrong formula (any missed term, e.g. h^2 / 12, is 0.3 % or more).
@pytest.mark.parametrize("shape, tol", [("disk", 1e-5), ("triangle", 1e-9)])
def test_meshed_plate_mass_and_inertia_equal_the_closed_forms(shape, tol):
    plate = Plate("platform", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), H, shape, R, CORNERS)
    meshed = meshed_plate_mass(plate, np.eye(3), RHO, 0.2 * R)
    exact = _closed_form(shape)
    scale = np.abs(exact[3:, 3:]).max()
    assert meshed[0, 0] == pytest.approx(exact[0, 0], rel=tol)
    assert np.abs(meshed[3:, 3:] - exact[3:, 3:]).max() <= tol * scale
    # centred on o: no coupling of translation and rotation beyond quadrature round-off
    assert np.abs(meshed[:3, 3:]).max() <= tol * exact[0, 0] * R


def test_a_tilted_platform_carries_its_inertia_into_base_coordinates(scene):
    """diag(R, R) M diag(R, R)^T: the inertia turns with the plate, the mass does not."""
    geometry = pose_geometry(scene.manipulator, scene.case("case2").pose)
    plate = platform_plate(scene.manipulator, geometry)
    rot = np.asarray(geometry.rotation)
    m = scene.manipulator
    meshed = meshed_plate_mass(plate, rot, m.material.density, 0.2 * m.platform_radius)
    j = plate_inertia(m.platform_shape, m.platform_radius, m.platform_thickness,
                      m.material.density)
    assert np.abs(meshed[3:, 3:] - rot @ j @ rot.T).max() <= 1e-5 * j.max()
    assert not np.allclose(meshed[3:, 3:], j, rtol=1e-3)  # the pose is tilted


def test_an_off_centre_point_mass_couples_translation_and_rotation():
    """One point of mass 2 at r = (1, 0, 0): S = (2, 0, 0), J = diag(0, 2, 2); the coupling
    block is -[S x], so a rotation about z moves the mass along y."""
    m6 = rigid_body_mass(np.array([[1.0, 0.0, 0.0]]), np.array([2.0]))
    assert np.allclose(np.diag(m6), [2, 2, 2, 0, 2, 2])
    velocity_of_mass = np.array([0, 0, 0, 0, 0, 1.0])  # omega_z = 1: v = omega x r = (0, 1, 0)
    momentum = m6 @ velocity_of_mass
    assert np.allclose(momentum[:3], [0.0, 2.0, 0.0])
    assert np.allclose(m6, m6.T)
