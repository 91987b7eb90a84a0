"""fem_reference.solve_pose on the paper's manipulator: no zero mode, Case 1 pairs, determinism,
results API, VTU export, refinement study, and clear FemError on bad input."""
from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

import fem_reference.tetrahedra as fem_tetrahedra
from analytical.kinematics import pose_geometry
from fem_reference import FemError, FemOptions, FemRuntime, refinement_study, solve_pose
from fem_reference.convergence import P_THEORY
from fem_reference.eigen import EigenError
from meshing.geometry import MeshSettings

SIZE = 0.04  # coarse: ~7000 dofs, ~0.5 s a pose


def options(size: float, **kwargs) -> FemOptions:
    """The tetrahedral legs (this file specifies them; the harmonic ones: test_fem_harmonic)."""
    return FemOptions(MeshSettings(size, rim_zone=0.015),  # 0.15 of the paper's 100 mm legs
                      **({"legs": "tetrahedra"} | kwargs))


def runtime(cache, **kwargs) -> FemRuntime:
    return FemRuntime(cache_dir=cache, **kwargs)


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("meshes")


@pytest.fixture(scope="module")
def case1(scene):
    return pose_geometry(scene.manipulator, scene.case("case1").pose)


@pytest.fixture(scope="module")
def case1_result(manipulator, case1, cache):
    return solve_pose(manipulator, case1, options(SIZE), runtime(cache))


def test_case1_frequencies_near_the_beam_model(scene, case1_result):
    """Two independent models of the same physics: the solid FEM against Timoshenko beams
    (shear and rotary inertia of the stocky legs included). Measured: within 0.9 % at this
    40 mm mesh (0.65 % against the refined limit), so 1.5 % per mode leaves room for the
    mesh's ~0.2 % and catches any real modelling error of the size of Euler-Bernoulli's
    4 % on modes 4-6."""
    from dataclasses import replace

    from analytical.model import natural_frequencies
    f = case1_result.frequencies_hz
    assert f.shape == (6,) and np.all(np.diff(f) >= 0)
    assert f[0] > 50.0  # no zero (mechanism) mode: the structure is locked by the joints
    beam = natural_frequencies(scene.manipulator, scene.case("case1").pose,
                               replace(scene.analytical, beam="timoshenko", modes=6))
    assert np.all(np.abs(f / beam - 1) < 0.015), np.round(100 * (f / beam - 1), 3)


def test_case1_shows_its_repeated_pairs(case1_result):
    """Case 1 is symmetric under the 120-degree turn, so f1 = f2 and f5 = f6 exactly for the
    continuum; the meshes of the three legs differ (unstructured, each leg meshed in its own
    orientation), which splits the pairs by ~1e-4 at this size (measured 6e-5 and 2e-5; the
    split falls with the mesh). 5e-4 is that asymmetry with margin, far below the 70 % and
    11 % gaps to the neighbouring modes."""
    f = case1_result.frequencies_hz
    assert f[1] / f[0] - 1 < 5e-4
    assert f[5] / f[4] - 1 < 5e-4
    assert f[2] / f[1] - 1 > 0.3 and f[4] / f[3] - 1 > 0.05
    assert [0, 1] in case1_result.clusters and [4, 5] in case1_result.clusters


def test_case2_breaks_the_pairs(manipulator, scene, cache):
    geom = pose_geometry(manipulator, scene.case("case2").pose)
    f = solve_pose(manipulator, geom, options(SIZE), runtime(cache)).frequencies_hz
    assert f[1] / f[0] - 1 > 0.03 and f[5] / f[4] - 1 > 0.02


def test_two_runs_give_identical_frequencies(manipulator, case1, tmp_path):
    a = solve_pose(manipulator, case1, options(SIZE), runtime(tmp_path, use_cache=False))
    b = solve_pose(manipulator, case1, options(SIZE), runtime(tmp_path, use_cache=False))
    assert a.mesh_digest == b.mesh_digest
    assert np.array_equal(a.frequencies_hz, b.frequencies_hz)
    assert not list(tmp_path.iterdir())  # use_cache=False writes nothing


def test_cached_mesh_gives_the_same_model(manipulator, case1, case1_result, cache):
    again = solve_pose(manipulator, case1, options(SIZE), runtime(cache))
    assert again.cache_hit and again.mesh_digest == case1_result.mesh_digest
    assert np.array_equal(again.frequencies_hz, case1_result.frequencies_hz)


def test_result_api(case1_result, case1):
    r = case1_result
    assert r.dofs < r.raw_dofs and r.mesh_size == SIZE
    assert set(r.timings) == {"mesh", "assemble", "solve", "total"}
    assert r.timings["total"] >= r.timings["solve"] > 0
    t = np.array([0.0, 0.3, 0.7, 1.0])
    legs = r.leg_axis_displacements(t)
    assert legs.shape == (3, 4, 3, 6)
    np.testing.assert_allclose(legs[:, 0], 0.0, atol=1e-12)  # B_i is fixed (R joint)
    pm = r.platform_motion
    assert pm.shape == (6, 6)
    arms = case1.platform_points - case1.platform_centre
    top = pm[None, :3] + np.cross(pm[3:].T[None], arms[:, None]).transpose(0, 2, 1)
    np.testing.assert_allclose(legs[:, -1], top, atol=1e-12)  # A_i moves with the platform
    # interior probes are continuous with the ends: nearly the same value just inside
    near = r.leg_axis_displacements([0.999])[:, 0]
    assert np.abs(near - legs[:, -1]).max() < 0.02 * np.abs(legs).max()
    json.dumps(r.to_dict())
    with pytest.raises(FemError, match="fractions"):
        r.leg_axis_displacements([1.5])


@pytest.mark.parametrize("platform,coupling", [("rigid", "distributing"), ("elastic", "rigid")])
def test_other_platform_and_coupling_options(manipulator, case1, case1_result, cache,
                                             platform, coupling):
    r = solve_pose(manipulator, case1, options(SIZE, platform=platform, coupling=coupling),
                  runtime(cache))
    f, ref = r.frequencies_hz, case1_result.frequencies_hz
    assert np.all(f > 50)
    # both options are softer: a distributing face does not stiffen the leg ends; an elastic
    # plate adds its own flexibility (and its own bending modes, from ~440 Hz)
    assert np.all(f[:3] < ref[:3]) and np.all(f[:3] > 0.9 * ref[:3])
    assert f[1] / f[0] - 1 < 1e-3
    assert r.platform_motion.shape == (6, 6)


def test_refinement_study_reports_orders_and_errors(manipulator, case1, cache):
    study = refinement_study(manipulator, case1, [0.045, 0.04, 0.035],
                             options(0.04), runtime(cache))
    d = json.loads(json.dumps(study.to_dict()))
    assert len(d["frequencies_hz"]) == 3 and len(d["observed_order"]) == 6
    err = np.array(d["relative_error"])
    assert err.shape == (3, 6) and np.all(err >= 0)
    for k, status in enumerate(d["status"]):
        assert status in ("ok", "order bounded by theory", "non-monotone", "order out of range",
                          "converged")
        if status in ("ok", "order bounded by theory"):
            assert 0 < d["observed_order"][k] <= P_THEORY
        else:
            assert d["observed_order"][k] is None
    # the finest of these coarse meshes: a few tenths of a percent, and never claimed exact
    assert 0 < d["max_relative_error"][-1] < 0.005


@pytest.mark.parametrize("p_true", [1.0, 1.42, 2.0, 3.0, 4.0, 5.0])
def test_richardson_error_estimate_is_never_optimistic(p_true):
    """Noisy four-mesh sequences of known order (sizes and noise as in the real study): the
    estimated error of every size bounds the true one whatever the order; where the order is
    at most the singular-rim one the bound is tight, above it (pre-asymptotic) the theory bound
    on the order makes it conservative, never smaller."""
    from fem_reference import richardson
    h = np.array([16.1, 13.7, 11.0, 9.2]) * 1e-3
    for seed in range(3):
        noise = 2e-6 * np.random.default_rng(seed).normal(size=4)
        f = 100.0 * (1 + 0.002 * (h / h[0]) ** p_true) * (1 + noise)
        mode = richardson(h, f)
        true = np.abs(f / 100.0 - 1)
        stated = np.asarray(mode.relative_error)
        assert np.all(stated >= 0.99 * true)
        assert mode.order <= P_THEORY
        if p_true <= P_THEORY:
            assert np.all(stated <= 1.1 * true)
        else:
            assert mode.status == "order bounded by theory"


def test_an_order_above_theory_is_not_used_to_shrink_the_estimate():
    """p = 4 fits these three values exactly, but the rims allow 1.42: the extrapolation goes
    as far as 1.42 takes it (further than the fitted 4 would)."""
    from fem_reference import richardson
    h = np.array([0.04, 0.032, 0.025])
    f = 100.0 + 1e4 * h**4
    mode = richardson(h, f)
    assert mode.observed_order == pytest.approx(4.0, abs=1e-3)
    assert mode.order == pytest.approx(P_THEORY)
    assert mode.extrapolated_hz < 100.0  # beyond the smooth limit: conservative
    assert mode.relative_error[-1] > (f[-1] - 100.0) / 100.0


def test_richardson_handles_exact_and_non_monotone_sequences():
    from fem_reference import richardson
    h = np.array([0.04, 0.028, 0.02])
    f = 100.0 + 3.0 * h**1.2
    mode = richardson(h, f)
    assert mode.status == "ok" and mode.order == pytest.approx(1.2, rel=1e-6)
    assert mode.extrapolated_hz == pytest.approx(100.0, rel=1e-9)
    wobbly = richardson(h, np.array([100.3, 100.1, 100.2]))
    assert wobbly.status == "non-monotone" and wobbly.order is None
    # widened: the largest change (0.2) carried to the finest size at the theory order,
    # more than the last change (0.1) alone
    tail = 0.2 / ((0.028 / 0.02) ** P_THEORY - 1)
    assert wobbly.relative_error[-1] == pytest.approx(tail / 100.2)
    assert wobbly.relative_error[-1] > 0.2 / 100.2


@pytest.mark.parametrize("kwargs,message", [
    ({"modes": 0}, "modes = 0"),
    ({"coupling": "glue"}, "coupling = 'glue'"),
    ({"platform": "soft"}, "platform = 'soft'"),
])
def test_bad_options_raise_fem_error(kwargs, message):
    with pytest.raises(FemError, match=message):
        options(0.02, **kwargs)


@pytest.mark.parametrize("kwargs,message", [
    ({"size": -0.02}, "size = -0.02 m: must be >= 1e-05 and <= 100 m"),
    ({"size": float("nan")}, "size = nan m: expected a finite number"),
    ({"size": 0.02, "rim_factor": 0.0}, "rim_factor = 0.0: must be >= 0.005 and <= 1"),
    ({"size": 0.02, "rim_zone": -1e-3}, "rim_zone = -0.001 m: must be >= 0 and <= 100 m"),
])
def test_bad_mesh_settings_name_the_value(kwargs, message):
    with pytest.raises(ValueError, match=message):
        MeshSettings(**({"rim_zone": 0.015} | kwargs))


def test_bad_sizes_and_geometry_raise_fem_error(manipulator, case1, cache):
    with pytest.raises(FemError, match=r"mesh_size_mm = 500: coarser than the leg diameter 100 mm"):
        solve_pose(manipulator, case1, options(0.5), runtime(cache))
    with pytest.raises(FemError, match=r"mesh_size_mm = 2: about \d+ dofs expected, above "
                                       r"max_dofs = 600000"):
        solve_pose(manipulator, case1, options(0.002), runtime(cache))
    with pytest.raises(FemError, match="max_dofs = 5000"):
        solve_pose(manipulator, case1, options(SIZE), runtime(cache, max_dofs=5000))
    zero = replace(case1, platform_points=case1.base_points.copy())
    with pytest.raises(FemError, match="leg 1 length = 0"):
        solve_pose(manipulator, zero, options(SIZE), runtime(cache))
    crossing = replace(case1, base_points=case1.base_points[[1, 0, 2]])
    with pytest.raises(FemError, match="legs 1 and 2"):
        solve_pose(manipulator, crossing, options(SIZE), runtime(cache))
    assert not list(cache.glob(".*"))  # nothing half-written


def test_eigensolver_failure_is_a_fem_error(manipulator, case1, cache, monkeypatch):
    def fail(*args, **kwargs):
        raise EigenError("ARPACK did not converge: 3 of 8 eigenpairs found")
    monkeypatch.setattr(fem_tetrahedra, "lowest_modes", fail)
    with pytest.raises(FemError, match="eigensolver failed .ARPACK did not converge"):
        solve_pose(manipulator, case1, options(SIZE), runtime(cache))


def test_gmsh_failure_is_a_fem_error(manipulator, case1, tmp_path, monkeypatch):
    import meshing.cache
    from meshing.geometry import GmshFailure

    def fail(*args, **kwargs):
        raise GmshFailure("12 inverted curved tetrahedra (min scaled Jacobian -0.1)")
    monkeypatch.setattr(meshing.cache, "build_mesh", fail)
    with pytest.raises(FemError, match="mesh_size_mm = 40: gmsh failed"):
        solve_pose(manipulator, case1, options(SIZE), runtime(tmp_path))
    assert not list(tmp_path.iterdir())


def test_every_mesh_records_its_element_quality(case1_result):
    from meshing.geometry import MIN_QUALITY
    assert MIN_QUALITY <= case1_result.min_quality <= 1.0
    assert case1_result.to_dict()["min_scaled_jacobian"] == case1_result.min_quality


def test_a_mesh_below_the_quality_threshold_is_repaired_or_refused(scene, monkeypatch):
    """Below MIN_QUALITY the mesh is rebuilt once with the high-order optimiser; kept if that
    clears the threshold, else refused with the value named."""
    from analytical.kinematics import pose_geometry
    from analytical.params import Pose
    from analytical.reach import layer_band
    from common.worker import stoppable
    from meshing import geometry
    from meshing.bodies import pose_assembly

    # the lowest level pose of the workspace at 45 mm: Netgen leaves a worst curved element of
    # 0.23, the high-order optimiser 0.76 (measured)
    low = Pose(height=layer_band(scene.manipulator)[0], azimuth=0.0, tilt=0.0)
    asm = pose_assembly(scene.manipulator, pose_geometry(scene.manipulator, low))
    settings = MeshSettings(0.045, rim_factor=0.3, rim_zone=0.02, rim_grading=1.0)
    first = geometry._build_with(asm, settings, {}).info["min_scaled_jacobian"]
    repaired = stoppable(geometry._build_with, asm, settings, geometry.REPAIR_OPTIONS)
    q = repaired.info["min_scaled_jacobian"]
    assert q > first  # the optimiser improves the worst curved element
    monkeypatch.setattr(geometry, "MIN_QUALITY", 0.5 * (first + q))
    mesh = geometry.build_mesh(asm, settings)
    assert mesh.info["min_scaled_jacobian"] == q and mesh.digest() == repaired.digest()
    monkeypatch.setattr(geometry, "MIN_QUALITY", q + 1e-3)
    with pytest.raises(geometry.GmshFailure,
                       match=rf"min scaled Jacobian {q:.3g} below {q + 1e-3:g} after repair"):
        geometry.build_mesh(asm, settings)


@pytest.mark.parametrize("size, expected", [
    (0.032, (0.040, 0.032, 0.025, 0.020)),  # in the design: the design
    (0.030, (0.040, 0.032, 0.030, 0.025, 0.020)),  # between its sizes: inserted
    (0.010, (0.020, 0.016, 0.0125, 0.010)),  # finer: the design's ratios, ending at it
    (0.050, (0.050, 0.040, 0.03125, 0.025)),  # coarser: the design's ratios, starting at it
])
def test_refinement_sequence_around_a_size(size, expected):
    from fem_reference.convergence import sequence_around
    sizes = sequence_around(size, (0.040, 0.032, 0.025, 0.020))
    assert sizes == pytest.approx(expected, rel=1e-12)
    assert size in sizes and list(sizes) == sorted(sizes, reverse=True)
