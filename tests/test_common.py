"""Helpers below both models: rigid-body kinematics, plate inertia, settings declarations."""
from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np
import pytest

from analytical.kinematics import pose_geometry
from common.plate import plate_inertia, plate_mass
from common.rigid_body import rigid_fit, skew
from common.settings import as_dict, setting
from fem_reference.model import FemOptions
from meshing.geometry import MeshSettings
from runtime.cache import content_key
from solvers.compare import fem_cache_payload


def test_skew_is_the_cross_product():
    rng = np.random.default_rng(1)
    a, b = rng.standard_normal((2, 5, 3))
    assert np.allclose(np.einsum("nij,nj->ni", skew(a), b), np.cross(a, b))
    assert np.allclose(skew(a[0]), -skew(a[0]).T)


def test_rigid_fit_recovers_a_rigid_motion_and_ignores_orthogonal_noise():
    rng = np.random.default_rng(2)
    points = rng.standard_normal((40, 3))
    centre = np.array([0.1, -0.2, 0.3])
    t, w = np.array([1e-3, -2e-3, 5e-4]), np.array([2e-3, 1e-3, -3e-3])
    u = t + np.cross(w, points - centre)
    assert np.allclose(rigid_fit(points, u, centre), np.r_[t, w], atol=1e-14)
    # a field with a unit mass matrix gives the same answer as plain least squares
    mass = np.eye(3 * len(points))
    assert np.allclose(rigid_fit(points, u, centre, mass=mass), np.r_[t, w], atol=1e-14)


@pytest.mark.parametrize("shape", ["disk", "triangle"])
def test_plate_inertia_matches_a_numerical_integration(shape):
    """Closed forms against a midpoint-rule integration of r^2 over the plate volume."""
    r, h, rho = 0.2, 0.03, 7800.0
    n = 400
    x = (np.arange(n) + 0.5) / n * 2 * r - r
    z = (np.arange(8) + 0.5) / 8 * h - h / 2
    xx, yy, zz = np.meshgrid(x, x, z, indexing="ij")
    if shape == "disk":
        inside = xx**2 + yy**2 <= r**2
    else:  # equilateral triangle with vertices on the circle of radius r
        verts = np.array([[r * math.cos(a), r * math.sin(a)] for a in (0, 2 * math.pi / 3,
                                                                         4 * math.pi / 3)])
        inside = np.ones_like(xx, bool)
        for k in range(3):
            p, q = verts[k], verts[(k + 1) % 3]
            normal = np.array([q[1] - p[1], p[0] - q[0]])
            inside &= ((xx - p[0]) * normal[0] + (yy - p[1]) * normal[1]) <= 0
    dv = (2 * r / n) ** 2 * (h / 8)
    m = rho * inside.sum() * dv
    izz = rho * ((xx**2 + yy**2) * inside).sum() * dv
    ixx = rho * ((yy**2 + zz**2) * inside).sum() * dv
    assert plate_mass(shape, r, h, rho) == pytest.approx(m, rel=5e-3)
    j = plate_inertia(shape, r, h, rho)
    assert j[2, 2] == pytest.approx(izz, rel=1e-2)
    assert j[0, 0] == pytest.approx(ixx, rel=1e-2) and j[1, 1] == j[0, 0]


def _key(manipulator, geometry, options):
    return content_key(fem_cache_payload(manipulator, geometry, options))


def test_every_fem_option_is_in_the_result_cache_key(scene):
    """The key is the whole options object: change any field, the key changes."""
    geometry = pose_geometry(scene.manipulator, scene.case("case1").pose)
    base = scene.fem
    reference = _key(scene.manipulator, geometry, base)
    changed = {
        "size": replace(base, mesh=replace(base.mesh, size=base.mesh.size * 0.9)),
        "rim_factor": replace(base, mesh=replace(base.mesh, rim_factor=0.7)),
        "rim_zone": replace(base, mesh=replace(base.mesh, rim_zone=0.02)),
        "rim_grading": replace(base, mesh=replace(base.mesh, rim_grading=0.5)),
        "platform": replace(base, platform="elastic", legs="tetrahedra"),
        "legs": replace(base, legs="tetrahedra"),
        "coupling": replace(base, coupling="distributing"),
        "modes": replace(base, modes=base.modes + 1),
        "platform_mesh": replace(base, platform_mesh=base.platform_mesh * 0.5),
    }
    declared = {f.name for f in fields(MeshSettings)} | {f.name for f in fields(FemOptions)}
    assert declared - {"mesh"} == set(changed), "a new option needs a line here"
    keys = {name: _key(scene.manipulator, geometry, opts) for name, opts in changed.items()}
    assert reference not in keys.values() and len(set(keys.values())) == len(keys)


def test_a_new_mesh_knob_changes_the_key_without_touching_the_key_code(scene):
    @dataclass(frozen=True)
    class MeshSettingsWithKnob(MeshSettings):
        curvature_nodes: int = setting(7, kind=int, minimum=3, doc="a new knob")

    geometry = pose_geometry(scene.manipulator, scene.case("case1").pose)
    mesh = MeshSettingsWithKnob(**as_dict(scene.fem.mesh))
    a = _key(scene.manipulator, geometry, replace(scene.fem, mesh=mesh))
    b = _key(scene.manipulator, geometry,
             replace(scene.fem, mesh=replace(mesh, curvature_nodes=9)))
    assert a != b != _key(scene.manipulator, geometry, scene.fem)


def test_declared_ranges_are_checked_from_python_too():
    with pytest.raises(ValueError, match="rim_factor = 1.5: must be >= 0.005 and <= 1"):
        MeshSettings(0.03, rim_factor=1.5, rim_zone=0.015)
