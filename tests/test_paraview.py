"""The mode shapes as ParaView opens them (fem_reference.export), read back with meshio: one
VTU with the legs and the platform, every mode named with its frequency and scaled to a tenth
of the model's size, and a .pvd that steps through the modes."""
from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from analytical.kinematics import pose_geometry
from common.rigid_body import rigid_fit
from fem_reference import FemOptions, FemRuntime, solve_pose
from fem_reference.export import DISPLAY_FRACTION, plate_solid
from meshing.bodies import Plate
from meshing.geometry import MeshSettings

SIZE = 0.04  # coarse: ~8000 dofs, about a second
RIM_ZONE = 0.015  # the paper machine's: 0.15 of its 100 mm legs


@pytest.fixture(scope="module")
def result(scene, tmp_path_factory):
    geometry = pose_geometry(scene.manipulator, scene.case("case2").pose)  # tilted: no symmetry
    # the tetrahedral legs' file (the harmonic legs' display: tests/test_fem_harmonic.py)
    return solve_pose(scene.manipulator, geometry, FemOptions(MeshSettings(SIZE, rim_zone=RIM_ZONE),
                                                              legs="tetrahedra"),
                      FemRuntime(cache_dir=tmp_path_factory.mktemp("meshes")))


@pytest.fixture(scope="module")
def written(result, tmp_path_factory):
    path = tmp_path_factory.mktemp("modes") / "case2_fem.vtu"
    result.write_vtu(path, pvd=True)
    return path, meshio.read(path)


def wedge_volumes(points: np.ndarray, wedges: np.ndarray) -> np.ndarray:
    """Signed volume of right prisms, positive when the first triangle's right-hand normal
    points away from the second (VTK's wedge orientation)."""
    p = points[wedges]
    bottom = 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    return -np.einsum("ij,ij->i", bottom, p[:, 3] - p[:, 0])


def test_the_case_file_holds_legs_and_platform(written, result, scene):
    _, mesh = written
    kinds = {block.type: block.data for block in mesh.cells}
    assert set(kinds) == {"tetra10", "wedge"}
    assert len(kinds["tetra10"]) == result.n_elements
    m = scene.manipulator
    plate = result.plate
    o, n = np.asarray(plate.centre), np.asarray(plate.normal)
    x = mesh.points[np.unique(kinds["wedge"])] - o
    assert np.abs(x @ n).max() == pytest.approx(m.platform_thickness / 2)
    assert np.linalg.norm(x - np.outer(x @ n, n), axis=1).max() == pytest.approx(
        m.platform_radius)
    volume = wedge_volumes(mesh.points, kinds["wedge"])
    assert np.all(volume > 0)
    assert volume.sum() == pytest.approx(math.pi * m.platform_radius**2 * m.platform_thickness,
                                         rel=2e-3)  # the 72-gon's area
    bodies = mesh.cell_data["body"]
    assert set(np.unique(bodies[1])) == {len(result.disc.bodies)}  # one body id of its own


def test_every_mode_is_named_with_its_frequency(written, result):
    _, mesh = written
    names = list(mesh.point_data)
    assert len(names) == len(result.frequencies_hz)
    for k, (name, f) in enumerate(zip(names, result.frequencies_hz), start=1):
        match = re.fullmatch(r"mode_(\d{2})_(\d+\.\d{2})Hz", name)
        assert match and int(match.group(1)) == k
        assert float(match.group(2)) == pytest.approx(f, abs=0.005)
    np.testing.assert_allclose(mesh.field_data["frequencies_hz"], result.frequencies_hz)


def test_modes_are_scaled_to_a_tenth_of_the_model_and_recoverable(written, result):
    _, mesh = written
    size = np.linalg.norm(np.ptp(mesh.points, axis=0))
    assert mesh.field_data["model_size_m"][0] == pytest.approx(size)
    assert mesh.field_data["display_fraction"][0] == DISPLAY_FRACTION == 0.1
    scales = mesh.field_data["mode_scale"]
    n = result.disc.n_nodes
    for k, name in enumerate(mesh.point_data):
        u = mesh.point_data[name]
        assert np.linalg.norm(u, axis=1).max() == pytest.approx(0.1 * size, rel=1e-12)
        raw = result.modes_raw[:, k].reshape(n, 3)  # mass-normalised
        np.testing.assert_allclose(u[:n] / scales[k], raw, rtol=0, atol=1e-12 * abs(raw).max())


def test_the_platform_moves_rigidly_with_each_mode(written, result):
    _, mesh = written
    wedges = next(block.data for block in mesh.cells if block.type == "wedge")
    ids = np.unique(wedges)
    o = result.geometry.platform_centre
    motion = result.platform_motion
    for k, name in enumerate(mesh.point_data):
        u = mesh.point_data[name][ids] / mesh.field_data["mode_scale"][k]
        fitted = rigid_fit(mesh.points[ids], u[:, :, None], o)[:, 0]
        np.testing.assert_allclose(fitted, motion[:, k], atol=1e-9 * abs(motion[:, k]).max())
        expected = motion[:3, k] + np.cross(motion[3:, k], mesh.points[ids] - o)
        np.testing.assert_allclose(u, expected, atol=1e-12)


def test_the_pvd_steps_through_the_modes(written, result):
    path, mesh = written
    pvd = path.with_suffix(".pvd")
    sets = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
    assert [int(d.get("timestep")) for d in sets] == list(range(1, len(result.frequencies_hz)
                                                               + 1))
    for d, name in zip(sets, mesh.point_data):
        piece = path.parent / d.get("file")
        assert piece.is_file()
        step = meshio.read(piece)
        np.testing.assert_array_equal(step.point_data["displacement"], mesh.point_data[name])
        k = int(d.get("timestep"))
        assert step.field_data["frequency_hz"][0] == pytest.approx(result.frequencies_hz[k - 1])
        assert len(step.cells) == 2  # legs and platform in every step


def test_an_elastic_platform_is_shown_as_meshed(scene, result, tmp_path):
    elastic = solve_pose(scene.manipulator, result.geometry,
                         FemOptions(MeshSettings(SIZE, rim_zone=RIM_ZONE), platform="elastic",
                                    legs="tetrahedra"),
                         FemRuntime(cache_dir=tmp_path / "meshes"))
    elastic.write_vtu(tmp_path / "elastic.vtu")
    mesh = meshio.read(tmp_path / "elastic.vtu")
    assert [block.type for block in mesh.cells] == ["tetra10"]  # the plate is among the tets
    assert len(np.unique(mesh.cell_data["body"][0])) == 4
    assert not (tmp_path / "elastic.pvd").exists()  # only when asked


@pytest.mark.parametrize("shape, area", [("disk", math.pi * 0.04 * 72 / (2 * math.pi)
                                          * math.sin(2 * math.pi / 72)),
                                         ("triangle", 3 * math.sqrt(3) / 4 * 0.04)])
def test_plate_solid_fills_the_plate(shape, area):
    """A tilted plate of radius 0.2 m, thickness 0.02 m: the wedges fill exactly the outline
    (the regular 72-gon for a disk) through the thickness, all with VTK's orientation."""
    normal = np.array([0.3, -0.2, 1.0]) / np.linalg.norm([0.3, -0.2, 1.0])
    o = np.array([0.1, 0.05, 0.6])
    e1 = np.cross(normal, [0, 0, 1.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    corners = tuple(tuple(o + 0.2 * (math.cos(a) * e1 + math.sin(a) * e2))
                    for a in (0.0, -2 * math.pi / 3, 2 * math.pi / 3))  # clockwise on purpose
    plate = Plate("platform", tuple(o), tuple(normal), 0.02, shape, 0.2, corners)
    points, wedges = plate_solid(plate)
    volume = wedge_volumes(points, wedges)
    assert np.all(volume > 0)
    assert volume.sum() == pytest.approx(area * 0.02, rel=1e-12)
