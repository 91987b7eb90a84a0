"""Solid joint ends: the condensed end-zone superelement, and the beam model that carries it.

The superelement's properties hold for any mesh, so they are checked on a coarse one (SMALL,
built once per coupling into a temporary cache). The model's accuracy is checked as shipped:
the default zone mesh against the FEM limits measured once with fine meshes
(tests/baselines/fem_limits.json, provenance inside).
"""
from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest
import scipy.linalg as la

from analytical.beam import Section, assemble_beam
from analytical.end_zones import JointEndsUnavailable
from analytical.leg_chain import leg_segments
from analytical.model import natural_frequencies
from analytical.params import ModelOptions
from joint_ends import EndZone
from tests.conftest import ROOT

pytest.importorskip("gmsh")
pytest.importorskip("skfem")

from joint_ends.cache import cached_zone  # noqa: E402
from joint_ends.zone import COUPLINGS, ZoneMesh, cylinder_mesh, rigid_motion  # noqa: E402

SMALL = ZoneMesh(size=0.25)  # coarse: seconds per zone
LIMITS = json.loads((ROOT / "tests" / "baselines" / "fem_limits.json").read_text())


@pytest.fixture(scope="module")
def steel(manipulator):
    mat = manipulator.material
    return manipulator.leg_diameter, mat.youngs_modulus, mat.shear_modulus, mat.density


@pytest.fixture(scope="module")
def zone_cache(tmp_path_factory):
    return tmp_path_factory.mktemp("zones")


@pytest.fixture(scope="module")
def zones(steel, zone_cache):
    d, e, g, rho = steel
    return {c: cached_zone(d, 0.5 * d, e, g, rho, c, SMALL, zone_cache) for c in COUPLINGS}


def _rigid_modes(length: float) -> np.ndarray:
    """(12, 6): nodal motions of the joint node (x = 0) and the interface node (x = length)
    under unit rigid translations and rotations about the joint."""
    r = np.zeros((12, 6))
    for node, x in enumerate((0.0, length)):
        r[6 * node:6 * node + 3] = rigid_motion(np.array([[x, 0.0, 0.0]]), np.zeros(3))
        r[6 * node + 3:6 * node + 6, 3:] = np.eye(3)
    return r


def _turn(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    r = np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])
    return la.block_diag(*[r] * 4)


@pytest.mark.parametrize("coupling", COUPLINGS)
def test_the_superelement_is_symmetric_semidefinite_with_exactly_six_rigid_body_modes(
        zones, coupling):
    k, m = zones[coupling].stiffness, zones[coupling].mass
    assert np.array_equal(k, k.T) and np.array_equal(m, m.T)
    w = np.linalg.eigvalsh(k) / np.abs(k).max()
    assert np.all(np.abs(w[:6]) < 1e-11) and np.all(w[6:] > 1e-5), w
    assert np.linalg.eigvalsh(m).min() > 0.0


@pytest.mark.parametrize("coupling", COUPLINGS)
def test_rigid_motion_costs_no_energy_and_carries_the_cylinders_mass(zones, steel, coupling):
    """K R = 0 to round-off; R^T M R is the rigid cylinder's mass and inertia about the joint
    (m, m r^2 / 2 about the axis, m (r^2 / 4 + l^2 / 3) across), to the curved mesh's
    geometric accuracy."""
    zone = zones[coupling]
    d, _, _, rho = steel
    r_modes = _rigid_modes(zone.length)
    assert np.abs(zone.stiffness @ r_modes).max() < 1e-11 * np.abs(zone.stiffness).max()
    rigid = r_modes.T @ zone.mass @ r_modes
    radius, length = d / 2, zone.length
    mass = rho * math.pi * radius**2 * length
    assert rigid[:3, :3] == pytest.approx(mass * np.eye(3), rel=1e-4, abs=1e-6 * mass)
    inertia = np.diag([mass * radius**2 / 2] + [mass * (radius**2 / 4 + length**2 / 3)] * 2)
    assert np.diag(rigid[3:, 3:]) == pytest.approx(np.diag(inertia), rel=1e-3)


@pytest.mark.parametrize("coupling", COUPLINGS)
def test_turning_the_zone_about_the_leg_axis_changes_nothing(zones, coupling):
    """The leg's frame about its own axis is arbitrary (it follows the pose): the superelement
    must not depend on it, for any angle, not only the quarter turns it was averaged over."""
    zone = zones[coupling]
    for angle in (0.37, 1.1, 2.9):
        q = _turn(angle)
        for a in (zone.stiffness, zone.mass):
            assert np.allclose(q.T @ a @ q, a, rtol=0, atol=1e-12 * np.abs(a).max())


def test_a_rigid_joint_face_is_stiffer_than_a_distributing_one(zones):
    """Same mesh, more constraint: K_rigid - K_distributing is positive semi-definite (the
    minimum-energy principle) and not zero (the rigid face holds warping back)."""
    diff = zones["rigid"].stiffness - zones["distributing"].stiffness
    w = np.linalg.eigvalsh(diff)
    scale = np.abs(zones["rigid"].stiffness).max()
    assert w.min() > -1e-9 * scale and w.max() > 1e-4 * scale


def test_a_cache_hit_returns_identical_matrices_and_a_damaged_entry_is_rebuilt(
        steel, zone_cache, zones, capsys, monkeypatch):
    d, e, g, rho = steel
    import joint_ends.cache as cache

    def no_build(*args, **kwargs):
        raise AssertionError("a cached zone was rebuilt")

    with monkeypatch.context() as patch:
        patch.setattr(cache, "build_zone", no_build)
        again = cached_zone(d, 0.5 * d, e, g, rho, "rigid", SMALL, zone_cache)
    assert np.array_equal(again.stiffness, zones["rigid"].stiffness)
    assert np.array_equal(again.mass, zones["rigid"].mass)
    damaged = next(zone_cache.glob("*.npz"))
    damaged.write_bytes(damaged.read_bytes()[:-10])
    for coupling in COUPLINGS:
        rebuilt = cached_zone(d, 0.5 * d, e, g, rho, coupling, SMALL, zone_cache)
        assert np.array_equal(rebuilt.stiffness, zones[coupling].stiffness)
    assert capsys.readouterr().err.count("failed its check") == 1


def _beam_leg_hz(steel, length: float, zone: EndZone | None, s: int = 40) -> np.ndarray:
    """Cantilever (joint end held, other end free): Timoshenko-Hutchinson elements, after a
    solid end zone at the held end when one is given."""
    d, e, g, rho = steel
    section = Section.solid_circle(d, e / (2 * g) - 1, "hutchinson")
    lz = 0.0 if zone is None else zone.length
    k, m = assemble_beam(e, g, rho, section, length - lz, s, "timoshenko")
    if zone is not None:
        n = k.shape[0] + 6
        k_all, m_all = np.zeros((n, n)), np.zeros((n, n))
        k_all[:12, :12], m_all[:12, :12] = zone.stiffness, zone.mass
        k_all[6:, 6:] += k
        m_all[6:, 6:] += m
        k, m = k_all[6:, 6:], m_all[6:, 6:]
    else:
        k, m = k[6:, 6:], m[6:, 6:]
    w = la.eigh(k, m, eigvals_only=True, subset_by_index=[0, 5])
    return np.sqrt(w) / (2 * math.pi)


def _solid_leg_hz(steel, length: float, mesh: ZoneMesh) -> np.ndarray:
    """The same cantilever as one solid, its joint face held (a rigid face at a fixed point)."""
    from analytical.params import Material
    from fem_reference.assembly import stiffness_and_mass
    from fem_reference.discretisation import discretise
    from fem_reference.eigen import lowest_modes

    d, e, g, rho = steel
    disc = discretise(cylinder_mesh(d, length, mesh))
    k, m = stiffness_and_mass(disc, Material(e, g, rho))
    held = (3 * disc.face_nodes["zone_base"][:, None] + np.arange(3)).ravel()
    free = np.setdiff1d(np.arange(disc.n_dofs), held)
    return lowest_modes(k[free][:, free].tocsr(), m[free][:, free].tocsr(), 6).frequencies_hz


def test_a_leg_with_a_solid_end_vibrates_as_the_solid_leg_and_a_plain_beam_does_not(
        steel, zones):
    """A leg four diameters long, clamped by a rigid face, free at the other end. Both solids
    share the mesh settings, so their discretisation errors (dominated by the same singular
    rim) cancel: first bending (modes 1-2), torsion (3) and axial (6) agree within 0.1 %
    (measured -0.03, +0.01, +0.07 % with the consistent rod mass; the beam middle's bar
    elements now converge from below, as (kh)^4). The plain Timoshenko beam misses the first
    bending by 0.86 %."""
    d = steel[0]
    length = 4 * d
    solid = _solid_leg_hz(steel, length, SMALL)
    zone = zones["rigid"]
    with_end = _beam_leg_hz(steel, length, EndZone(zone.length, zone.stiffness, zone.mass))
    plain = _beam_leg_hz(steel, length, None)
    error = 100 * (with_end / solid - 1)
    assert np.all(np.abs(error[[0, 1, 2, 5]]) < 0.1), error
    assert np.all(100 * (solid[:2] / plain[:2] - 1) > 0.5)


def _options(scene, coupling: str, joint_ends: str = "solid", elements: int = 5):
    return replace(scene.analytical, beam="timoshenko", shear="hutchinson", elements=elements,
                   platform_inertia="plate", joint_ends=joint_ends, joint_coupling=coupling,
                   modes=6)


@pytest.mark.parametrize("coupling", COUPLINGS)
def test_solid_ends_bring_the_ci_cases_within_a_tenth_of_a_percent_of_the_fem_limit(
        scene, coupling):
    """Timoshenko (Hutchinson) s = 5 between default solid end zones against the FEM's
    h -> 0 limit (fine meshes, Richardson; its own uncertainty is in the baseline file, a few
    0.01 %), f1..f6 of every CI case. With beam ends the rigid faces' first modes are off by
    more than 0.4 %."""
    for name in scene.ci_cases:
        limit = np.asarray(LIMITS["cases"][name][coupling]["limit_hz"])
        pose = scene.case(name).pose
        model = natural_frequencies(scene.manipulator, pose, _options(scene, coupling))
        error = 100 * (model / limit - 1)
        assert np.abs(error).max() < 0.1, (name, coupling, error)
        if coupling == "rigid":
            beam = natural_frequencies(scene.manipulator, pose,
                                       _options(scene, coupling, "beam"))
            assert np.abs(100 * (beam[:3] / limit[:3] - 1)).max() > 0.4


def test_the_model_does_not_depend_on_where_the_legs_stand(scene):
    """Turning every leg about the vertical axis (leg angles + 40 degrees) turns the whole
    manipulator: the limb frames change, the frequencies do not."""
    opts = _options(scene, "rigid")
    pose = scene.case(scene.ci_cases[-1]).pose
    turned = replace(scene.manipulator, leg_angles=tuple(a + math.radians(40.0)
                                                         for a in scene.manipulator.leg_angles))
    a = natural_frequencies(scene.manipulator, pose, opts)
    b = natural_frequencies(turned, replace(pose, azimuth=pose.azimuth + math.radians(40.0)),
                            opts)
    assert b == pytest.approx(a, rel=1e-9)


def test_legs_too_short_for_two_end_zones_are_refused_in_one_line(manipulator):
    zone = EndZone(0.3, np.eye(12), np.eye(12))
    opts = ModelOptions(joint_ends="solid")
    with pytest.raises(JointEndsUnavailable) as info:
        leg_segments(manipulator, opts, {"leg": zone}, np.array([0.55]))
    assert "\n" not in str(info.value) and "550 mm" in str(info.value)


@pytest.mark.parametrize("missing", ["joint_ends", "gmsh"])
def test_without_the_solid_builder_solid_ends_fail_in_one_line(scene, monkeypatch, missing):
    """As in a base install (numpy and scipy only): the model asks for a zone it cannot build
    (a zone length never built before, so neither cache can answer)."""
    import sys

    import analytical.end_zones as end_zones

    monkeypatch.setitem(sys.modules, missing, None)
    opts = replace(_options(scene, "rigid"), end_zone=0.371)
    with pytest.raises(JointEndsUnavailable) as info:
        end_zones.solid_end_zone(scene.manipulator, opts)
    message = str(info.value)
    assert "\n" not in message and missing in message and "joint_ends = 'beam'" in message


def test_workspace_maps_assemble_the_same_solid_ends_as_the_single_pose_model(scene):
    """The batched model of the maps (analytical.batch_model) against the per-pose model, at
    poses from compact to tall and tilted."""
    from analytical.batch_model import assemble_batch
    from analytical.kinematics import pose_geometry
    from analytical.params import Pose
    from analytical.pose_batch import pose_batch
    from analytical.substructure import assemble

    opts = _options(scene, "rigid", elements=3)
    poses = [Pose(0.3, 0.2, -0.1), Pose(0.5436, math.radians(10), math.radians(-12)),
             Pose(0.8, 0.9, 0.3)]
    batch = assemble_batch(scene.manipulator,
                           pose_batch(scene.manipulator, np.array([p.height for p in poses]),
                                      np.array([p.azimuth for p in poses]),
                                      np.array([p.tilt for p in poses])), opts)
    for k, pose in enumerate(poses):
        single = assemble(scene.manipulator, pose_geometry(scene.manipulator, pose), opts)
        assert single.stiffness.shape == (18 * 5, 18 * 5)  # s + 2 segments per leg
        for a, b in ((single.stiffness, batch.stiffness[k]), (single.mass, batch.mass[k])):
            assert np.allclose(a, b, rtol=0, atol=1e-12 * np.abs(a).max())
