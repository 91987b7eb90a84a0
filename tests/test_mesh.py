"""meshing/: gmsh bodies, physical groups, determinism, the mesh cache and its recovery."""
from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from analytical.kinematics import pose_geometry
from meshing import (
    Assembly,
    Cylinder,
    GeometryError,
    MeshCache,
    MeshSettings,
    build_mesh,
    cache_key,
    cached_mesh,
    leg_cylinders,
    pose_assembly,
)

ROD = Assembly((Cylinder("leg1", (0.0, 0.0, 0.0), (0.1, 0.2, 0.5), 0.05),))
COARSE = MeshSettings(0.04, rim_zone=0.015)  # 0.15 of the rod's 100 mm diameter


@pytest.fixture(scope="module")
def case1_geometry(scene):
    return pose_geometry(scene.manipulator, scene.case("case1").pose)


def test_legs_are_separate_second_order_bodies_with_joint_faces(manipulator, case1_geometry):
    mesh = build_mesh(pose_assembly(manipulator, case1_geometry), COARSE)
    assert mesh.bodies == ("leg1", "leg2", "leg3")
    assert sorted(mesh.faces) == sorted(f"leg{i}_{e}" for i in (1, 2, 3) for e in ("base", "top"))
    assert mesh.tets.shape[1] == 10
    # no node is shared between bodies: they are joined only by the FEM's joint constraints
    owners = [set(np.unique(mesh.tets[mesh.tet_body == b])) for b in range(3)]
    assert not (owners[0] & owners[1] or owners[0] & owners[2] or owners[1] & owners[2])
    for i in range(3):
        for end, point in (("base", case1_geometry.base_points[i]),
                           ("top", case1_geometry.platform_points[i])):
            face = mesh.faces[f"leg{i + 1}_{end}"]
            x = mesh.points[np.unique(face)]
            axis = case1_geometry.leg_directions[i]
            assert np.abs((x - point) @ axis).max() < 1e-9  # planar end face through the joint
            radial = np.linalg.norm(x - point - np.outer((x - point) @ axis, axis), axis=1)
            assert radial.max() == pytest.approx(manipulator.leg_diameter / 2, rel=1e-9)
            assert set(np.unique(face)) <= owners[i]


def test_elastic_platform_adds_a_plate_body(manipulator, case1_geometry):
    mesh = build_mesh(pose_assembly(manipulator, case1_geometry, elastic_platform=True), COARSE)
    assert mesh.bodies == ("leg1", "leg2", "leg3", "platform")
    plate = mesh.points[np.unique(mesh.tets[mesh.tet_body == 3])]
    normal = case1_geometry.rotation[:, 2]
    assert np.abs((plate - case1_geometry.platform_centre) @ normal).max() == pytest.approx(
        manipulator.platform_thickness / 2, rel=1e-9)


def test_mesh_is_deterministic():
    a, b = build_mesh(ROD, COARSE), build_mesh(ROD, COARSE)
    assert a.digest() == b.digest()
    assert np.array_equal(a.points, b.points) and np.array_equal(a.tets, b.tets)


def test_curved_mid_edge_nodes_lie_on_the_cylinder():
    mesh = build_mesh(ROD, COARSE)
    c = ROD.cylinders[0]
    axis = np.subtract(c.end, c.start) / c.length
    x = mesh.points - np.asarray(c.start)
    radial = np.linalg.norm(x - np.outer(x @ axis, axis), axis=1)
    assert radial.max() == pytest.approx(c.radius, rel=1e-9)
    on_surface = np.abs(radial - c.radius) < 1e-9
    mid_nodes = np.unique(mesh.tets[:, 4:])
    assert on_surface[mid_nodes].sum() > 20  # second-order nodes placed on the geometry


def test_cache_hit_returns_the_identical_mesh(tmp_path):
    first, hit1 = cached_mesh(ROD, COARSE, tmp_path)
    second, hit2 = cached_mesh(ROD, COARSE, tmp_path)
    assert (hit1, hit2) == (False, True)
    assert second.digest() == first.digest()
    assert np.array_equal(second.points, first.points)
    assert {k: v.tolist() for k, v in second.faces.items()} == \
        {k: v.tolist() for k, v in first.faces.items()}
    assert not list(tmp_path.glob(".*"))  # no temporary files left behind


def test_cache_key_follows_geometry_and_settings():
    moved = Assembly((replace(ROD.cylinders[0], end=(0.1, 0.2, 0.5 + 1e-6)),))
    keys = {cache_key(ROD, COARSE), cache_key(moved, COARSE),
            cache_key(ROD, MeshSettings(0.035, rim_zone=0.015)),
            cache_key(ROD, MeshSettings(0.04, 0.5, rim_zone=0.01))}
    assert len(keys) == 4
    assert cache_key(ROD, COARSE) == cache_key(ROD, MeshSettings(0.04, rim_zone=0.015))


@pytest.mark.parametrize("damage", ["garbage", "truncate", "empty", "bad-json", "other-mesh"])
def test_corrupt_cache_entry_is_rebuilt(tmp_path, damage):
    good, _ = cached_mesh(ROD, COARSE, tmp_path)
    key = cache_key(ROD, COARSE)
    mesh_path, meta_path = MeshCache(tmp_path).paths(key)
    if damage == "garbage":
        mesh_path.write_bytes(b"\x00not a mesh" * 100)
    elif damage == "truncate":
        mesh_path.write_bytes(mesh_path.read_bytes()[: mesh_path.stat().st_size // 2])
    elif damage == "empty":
        mesh_path.write_bytes(b"")
    elif damage == "bad-json":
        meta_path.write_text("{ not json")
    else:  # a valid mesh of another geometry under this key
        other = Assembly((Cylinder("leg1", (0, 0, 0), (0, 0, 0.3), 0.05),))
        cached_mesh(other, COARSE, tmp_path)
        mesh_path.write_bytes(MeshCache(tmp_path).paths(cache_key(other, COARSE))[0].read_bytes())
    rebuilt, hit = cached_mesh(ROD, COARSE, tmp_path)
    assert not hit
    assert rebuilt.digest() == good.digest()
    assert json.loads(meta_path.read_text())["digest"] == good.digest()
    again, hit = cached_mesh(ROD, COARSE, tmp_path)
    assert hit and again.digest() == good.digest()


def test_degenerate_legs_are_refused():
    b = np.array([[0.3, 0, 0], [-0.15, 0.26, 0], [-0.15, -0.26, 0]])
    a = b + [0, 0, 0.5]
    with pytest.raises(GeometryError, match="leg 2 length"):
        leg_cylinders(b, np.array([a[0], b[1], a[2]]), 0.1)
    touching = b.copy()
    touching[1] = [0.3, 0.08, 0.0]
    with pytest.raises(GeometryError, match="legs 1 and 2"):
        leg_cylinders(touching, touching + [0, 0, 0.5], 0.1)
    with pytest.raises(GeometryError, match="B3"):
        leg_cylinders(np.array([b[0], b[1], [np.nan, 0, 0]]), a, 0.1)
