"""A payload on the platform (issue 23, part): a rigid body both models carry identically.

Its mass about the platform centre follows the parallel-axis theorem (checked against the point
masses of a body), it turns with the platform, adding it never raises a frequency (min-max:
more mass, M' >= M), the batched model agrees with the per-pose one, and the two models, which
share only this idealisation, still agree with each other with it on board."""
from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np
import pytest

from analytical.batch_model import assemble_batch
from analytical.kinematics import pose_geometry, rotation_y, rotation_z
from analytical.model import natural_frequencies
from analytical.params import Pose
from analytical.pose_batch import pose_batch
from analytical.substructure import assemble
from common.errors import InputError
from common.payload import Payload, payload_mass_matrix
from common.rigid_body import rigid_body_mass
from scene import parse_scene
from tests.conftest import PAPER_SCENE

# a tool of 35 kg, 120 mm above the platform and 30 mm off its axis (issue 23's example, offset)
TOOL = Payload(35.0, (0.03, 0.0, 0.12), (0.40, 0.40, 0.25))


def box(centre, sides, density=1000.0, n=6):
    """Point masses of a homogeneous box on a symmetric grid: (points, weights), and its
    principal moments about its own centre (those of the same point masses)."""
    axes = [(np.arange(n) + 0.5) / n - 0.5 for _ in range(3)]
    local = np.array(list(itertools.product(*axes))) * np.asarray(sides)
    weights = np.full(len(local), density * np.prod(sides) / len(local))
    moments = [weights @ (local[:, (k + 1) % 3] ** 2 + local[:, (k + 2) % 3] ** 2)
               for k in range(3)]
    return local + np.asarray(centre), weights, tuple(moments)


def test_the_mass_about_o_is_the_bodys_own_by_the_parallel_axis_theorem():
    points, weights, moments = box((0.05, -0.02, 0.15), (0.2, 0.1, 0.3))
    payload = Payload(float(weights.sum()), (0.05, -0.02, 0.15), moments)
    assert np.allclose(payload.body_mass(), rigid_body_mass(points, weights), rtol=0,
                       atol=1e-12 * weights.sum())


def test_the_payload_turns_with_the_platform():
    points, weights, moments = box((0.05, -0.02, 0.15), (0.2, 0.1, 0.3))
    payload = Payload(float(weights.sum()), (0.05, -0.02, 0.15), moments)
    rot = rotation_z(0.7) @ rotation_y(0.3) @ rotation_z(-0.7)
    assert np.allclose(payload_mass_matrix(payload, rot), rigid_body_mass(points @ rot.T, weights),
                       rtol=0, atol=1e-12 * weights.sum())


@pytest.mark.parametrize("inertia, needle", [
    ((1.0, 0.1, 0.1), "moment 1 exceeds the sum of the other two"),
    ((0.0, 0.0, -1.0), "inertia"),
])
def test_a_body_no_body_can_be_is_refused(inertia, needle):
    with pytest.raises(InputError, match=needle):
        Payload(10.0, (0.0, 0.0, 0.0), inertia)


def test_the_scene_reads_the_payload_in_kg_mm_and_kg_m2():
    import tomllib

    raw = tomllib.loads(PAPER_SCENE.read_text(encoding="utf-8"))
    raw["payload"] = {"mass_kg": 35.0, "centre_mm": [30.0, 0.0, 120.0],
                      "inertia_kg_m2": [0.4, 0.4, 0.25]}
    assert parse_scene(raw).manipulator.payload == TOOL
    raw["payload"]["inertia_kg_m2"] = [0.4, 0.4, 0.9]
    with pytest.raises(InputError, match="payload.inertia_kg_m2"):
        parse_scene(raw)


def test_no_payload_is_the_plain_platform_and_a_payload_lowers_every_frequency(scene):
    pose = scene.case("case2").pose
    opts = replace(scene.analytical, modes=12)
    plain = natural_frequencies(scene.manipulator, pose, opts)
    empty = replace(scene.manipulator, payload=Payload())
    assert np.array_equal(natural_frequencies(empty, pose, opts), plain)
    loaded = natural_frequencies(replace(scene.manipulator, payload=TOOL), pose, opts)
    assert np.all(loaded <= plain * (1 + 1e-12))  # min-max: M grows, no frequency rises
    assert np.all(loaded[:3] < 0.99 * plain[:3])  # and the platform modes feel 35 kg


def test_the_batched_model_carries_the_offset_payload_as_the_per_pose_one(scene):
    m = replace(scene.manipulator, payload=TOOL)
    batch = pose_batch(m, [0.52, 0.6, 0.7], [0.3, 2.0, 4.1], [0.05, 0.1, 0.15])
    batch = batch.take(batch.feasible)
    assert len(batch) == 3
    model = assemble_batch(m, batch, scene.analytical)
    for n in range(len(batch)):
        one = assemble(m, batch.geometry(n), scene.analytical)
        assert np.abs(model.mass[n] - one.mass).max() < 1e-13 * np.abs(one.mass).max()


@pytest.mark.slow
def test_both_models_agree_with_a_payload_as_without(scene, tmp_path):
    """The payload is the one idealisation the models share; the legs stay each model's own.
    The best beam model's error against the FEM (harmonic legs, 32 mm, paired by shape) with a
    35 kg tool on board stays within 0.05 percentage points of its error without it."""
    from runtime.cache import ResultCache
    from solvers.compare import analytical_case, error_table, fem_case

    opts = replace(scene.analytical, beam="timoshenko", shear="hutchinson", joint_ends="solid",
                   elements=5, modes=6)
    cache = ResultCache(tmp_path)
    worst = {}
    for label, manipulator in (("plain", scene.manipulator),
                               ("tool", replace(scene.manipulator, payload=TOOL))):
        s = replace(scene, manipulator=manipulator, analytical=opts)
        case = s.case("case2")
        fem = fem_case(s, pose_geometry(manipulator, case.pose), cache, 0.032)
        rows = error_table(analytical_case(s, case, opts), fem, 6)
        worst[label] = np.array([r["error_percent"] for r in rows])
        assert min(r["mac"] for r in rows) > 0.99, label
    assert np.abs(worst["tool"] - worst["plain"]).max() < 0.05, worst


def test_an_elastic_plate_with_a_payload_is_refused(scene):
    from fem_reference import FemError, FemOptions, solve_pose
    from meshing.geometry import MeshSettings

    m = replace(scene.manipulator, payload=TOOL)
    geometry = pose_geometry(m, Pose(0.5436))
    with pytest.raises(FemError, match="elastic.*payload"):
        solve_pose(m, geometry, FemOptions(MeshSettings(0.08, rim_zone=scene.fem.mesh.rim_zone),
                                           platform="elastic", legs="tetrahedra"))


def test_the_symmetry_and_scaling_claims_are_the_structures_payload_or_not(scene):
    """Repeated pairs, turned layouts and material scaling hold for the machine's structure; a
    payload off the axis breaks the symmetry and does not scale with the density, so the hard
    cases check the machine without it (studies.hard_cases.base.bare)."""
    from studies import hard_cases as hc

    carrying = replace(scene, manipulator=replace(scene.manipulator, payload=TOOL))
    for row in (hc.repeated_pairs(carrying, runs=20), hc.turned_layout(carrying, poses=20),
                hc.aluminium_scaling(carrying), hc.titanium_scaling(carrying)):
        assert row.passed, row


def test_an_elastic_plate_with_a_payload_is_refused_at_load():
    import tomllib

    raw = tomllib.loads(PAPER_SCENE.read_text(encoding="utf-8"))
    raw["payload"] = {"mass_kg": 35.0}
    raw["fem"]["platform"] = "elastic"
    with pytest.raises(InputError, match="fem.platform = 'elastic' with \\[payload\\] mass_kg"):
        parse_scene(raw)
