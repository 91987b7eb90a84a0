"""Every plausible 3-RPS or 3-PRS machine runs end to end, or is refused up front in one line.

Machines are drawn (hypothesis) from the plausible ranges below: steel, aluminium or titanium;
base radius 150-600 mm; platform radius 0.3-1.2 times the base's; legs 2-40 diameters long at
mid stroke; plate 0.1-3 leg diameters thick (at least 1 mm); actuator stroke L_min / L_max
0.25-0.8 with L_max 1.2-4 base radii; joint limits 20-80 degrees; both joint orders. Half are
3-PRS: legs of 1.2-4 base radii and 2-40 diameters, rails at 50-130 degrees, a slider stroke
of 0.3-1.5 leg lengths starting 0-30 % of it up the rail. Each scene
has a level case and a slightly tilted one where the machine reaches them (elsewhere a random
height: the up-front check must refuse it). A draw either passes `studies.reachable.check`
(plus the scene's own load) or is refused there by ValueError in one line; after that check,
nothing may fail on a pose the pipeline chose itself.

Machines with real legs (issue 35) are drawn apart (`real_leg_machines`): 3-RPS, a housing
and a rod (rods 6-20 diameters for the mean leg, a bush gap of 2-15 % of the rod, housing walls
of 8-30 % of the bore, a hollow or solid rod), rigid joints and drive or the springs of
bearings and a ball screw; with solid legs each case must meet the FEM limit within 0.1 % on
f1-f6.

Default profile (a fixed set of draws, derandomized so CI is repeatable; `make fuzz`, about
five minutes on two workers): the load and the workspace check of 50 machines with every pose
generator of every study; the FEM (harmonic and tetrahedral legs, 0.4 leg diameters) and the
pairing of 5; the analytical hard cases of 5; a CI-size validation of 3; the FEM limit of 2
real-leg machines, one rigid and one sprung. `RPS_FUZZ=slow` draws at random, more of each
(300, 30, 30, 10, 10 + 10), and runs full validations with the report.
"""
from __future__ import annotations

import math
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st

from analytical.kinematics import pose_geometry
from analytical.model import natural_frequencies
from analytical.params import Pose
from analytical.reach import WorkspaceError, level_band, sample_poses
from scene import parse_scene
from studies import hard_cases
from studies import reachable as envelope
from studies.workspace_map import MAP_LAYERS, workspace_heights
from studies.workspace_validation import FULL, design

pytestmark = pytest.mark.fuzz  # `make fuzz` (CI runs it after `make test`)
SLOW = os.environ.get("RPS_FUZZ") == "slow"
MATERIALS = {  # E (GPa), G (GPa), rho (kg/m3)
    "steel": (200.0, 77.0, 7820.0),
    "aluminium": (70.0, 26.0, 2700.0),
    "titanium": (113.8, 42.4, 4430.0),
}


def _settings(default: int, slow: int):
    return settings(max_examples=slow if SLOW else default, deadline=None, derandomize=not SLOW,
                    database=None, suppress_health_check=list(HealthCheck))


@st.composite
def machines(draw) -> dict:
    """A raw scene (the TOML's tables) of a plausible machine with two cases."""
    f = lambda lo, hi: draw(st.floats(lo, hi, allow_nan=False))  # noqa: E731
    r1 = f(150.0, 600.0)
    r2 = r1 * f(0.3, 1.2)
    l_max = r1 * f(1.2, 4.0)
    l_min = l_max * f(0.25, 0.8)
    diameter = 0.5 * (l_min + l_max) / f(2.0, 40.0)
    thickness = max(1.0, diameter * f(0.1, 3.0))
    e, g, rho = MATERIALS[draw(st.sampled_from(sorted(MATERIALS)))]
    order = draw(st.sampled_from([("R", "S"), ("S", "R")]))
    actuator = {"actuator_min_mm": l_min, "actuator_max_mm": l_max}
    if draw(st.booleans()):  # a 3-PRS: legs of one length, sliders on rails
        stroke = l_max * f(0.3, 1.5)
        diameter = l_max / f(2.0, 40.0)
        thickness = max(1.0, diameter * f(0.1, 3.0))
        order = ("R", "S")
        actuator = {"architecture": "3-PRS", "leg_length_mm": l_max,
                    "rail_angle_deg": f(50.0, 130.0), "slider_min_mm": stroke * f(0.0, 0.3),
                    "slider_max_mm": stroke}
    raw = {
        "name": "fuzzed machine",
        "manipulator": {
            "base_radius_mm": r1, "platform_radius_mm": r2, "leg_diameter_mm": diameter,
            "platform_thickness_mm": min(thickness, r2), **actuator,
            "s_joint_max_deg": f(20.0, 80.0),
            "r_joint_max_deg": f(20.0, 80.0), "base_joint": order[0],
            "platform_joint": order[1]},
        "material": {"youngs_modulus_gpa": e, "shear_modulus_gpa": g, "density_kg_m3": rho},
        "fidelity": {"modes": 6, "tolerance_percent": 1.0},
    }
    where, azimuth, tilt = f(0.2, 0.8), f(0.0, 360.0), f(0.5, 5.0)
    raw["cases"] = _cases(raw, where, azimuth, tilt)
    return raw


@st.composite
def real_leg_machines(draw, sprung: bool) -> dict:
    """A raw scene of a plausible 3-RPS with real legs: a housing and a rod (hollow or solid),
    rigid joints and drive, or (`sprung`) the springs of bearings and a ball screw (issue
    35)."""
    f = lambda lo, hi: draw(st.floats(lo, hi, allow_nan=False))  # noqa: E731
    r1 = f(200.0, 600.0)
    r2 = r1 * f(0.4, 1.0)
    l_max = r1 * f(1.4, 3.0)
    l_min = l_max * f(0.55, 0.8)
    rod = 0.5 * (l_min + l_max) / f(6.0, 20.0)  # the rod's outer diameter
    gap = max(1.0, rod * f(0.02, 0.15))  # radial room for a guide bush, >= 1 mm (MIN_ROD_GAP)
    bore = rod + 2.0 * gap
    housing = bore + 2.0 * max(2.0, bore * f(0.08, 0.3))  # a wall of 8-30 % of the bore
    length = max(1.25 * housing, (l_min - 1.3 * rod) * f(0.5, 0.95))
    l_min = max(l_min, length + 1.3 * rod)
    l_max = max(l_max, l_min * 1.2)
    e, g, rho = MATERIALS[draw(st.sampled_from(sorted(MATERIALS)))]
    order = draw(st.sampled_from([("R", "S"), ("S", "R")]))
    raw = {
        "name": "fuzzed machine with real legs",
        "manipulator": {
            "base_radius_mm": r1, "platform_radius_mm": r2,
            "platform_thickness_mm": min(max(10.0, housing * f(0.2, 0.5)), r2),
            "actuator_min_mm": l_min, "actuator_max_mm": l_max,
            "s_joint_max_deg": f(30.0, 60.0), "r_joint_max_deg": f(30.0, 60.0),
            "base_joint": order[0], "platform_joint": order[1]},
        "material": {"youngs_modulus_gpa": e, "shear_modulus_gpa": g, "density_kg_m3": rho},
        "leg": {"housing_length_mm": length, "housing_outer_diameter_mm": housing,
                "housing_inner_diameter_mm": bore, "rod_outer_diameter_mm": rod,
                "rod_inner_diameter_mm": rod * draw(st.sampled_from([0.0, 0.3, 0.6]))},
        "fidelity": {"modes": 6, "tolerance_percent": 1.0},
    }
    if sprung:  # bearings and a ball screw, N/um
        raw["stiffness"] = {"actuator_axial_n_per_um": f(50.0, 500.0),
                            "base_joint_translational_n_per_um": f(200.0, 2000.0),
                            "platform_joint_translational_n_per_um": f(100.0, 1000.0)}
    where, azimuth, tilt = f(0.2, 0.8), f(0.0, 360.0), f(0.5, 5.0)
    raw["cases"] = _cases(raw, where, azimuth, tilt)
    return raw


def _cases(raw: dict, where: float, azimuth: float, tilt: float) -> dict:
    """A level case `where` of the way up the level band and the same height tilted a little
    (halved until reachable), as a user reads them off their machine; a random height where
    the machine has no level band (the check must refuse the scene)."""
    try:
        scene = parse_scene(raw | {"cases": {"probe": {"height_mm": 1.0}}})
        band = level_band(scene.manipulator)
    except ValueError:
        man = raw["manipulator"]
        return {"level": {"height_mm": where * man.get("actuator_max_mm",
                                                        man.get("leg_length_mm"))}}
    z = band.low + where * band.width
    for _ in range(20):
        if _reaches(scene, z, azimuth, tilt):
            break
        tilt *= 0.5
    return {"level": {"height_mm": z * 1e3},
            "tilted": {"height_mm": z * 1e3, "azimuth_deg": azimuth, "tilt_deg": tilt}}


def _reaches(scene, z: float, azimuth: float, tilt: float) -> bool:
    try:
        pose_geometry(scene.manipulator, Pose(z, math.radians(azimuth), math.radians(tilt)))
    except ValueError:
        return False
    return True


def checked(raw: dict):
    """The scene and its workspace record, or None when it is refused up front in one line."""
    try:
        scene = parse_scene(raw)
        record = envelope.check(scene, "full")
    except ValueError as exc:
        text = str(exc)
        assert text and "\n" not in text, text
        event(f"refused up front: {text.split(':')[0][:40]}")
        return None
    event("checked, run")
    return scene, record


def _all_reachable(m, poses) -> None:
    for p in poses:
        pose_geometry(m, p)  # raises PoseError if a study chose an unreachable pose


@_settings(50, 300)
@given(machines())
def test_every_study_pose_of_a_checked_machine_is_reachable(raw):
    got = checked(raw)
    if got is None:
        return
    scene, record = got
    m = scene.manipulator
    assert record["level_band_mm"][0] <= record["layer_band_mm"][0] <= \
        record["layer_band_mm"][1] <= record["level_band_mm"][1]
    _all_reachable(m, [Pose(float(z)) for z in workspace_heights(scene, MAP_LAYERS)])
    _all_reachable(m, [Pose(p["height"], p["azimuth"], p["tilt"]) for p in design(m, FULL)])
    _all_reachable(m, sample_poses(m, 50, np.random.default_rng(1)))
    start, end, _ = hard_cases.straight_path(m)
    t = np.linspace(0.0, 1.0, 120)
    _all_reachable(m, [Pose(start.height + s * (end.height - start.height),
                            start.azimuth + s * (end.azimuth - start.azimuth),
                            start.tilt + s * (end.tilt - start.tilt)) for s in t])
    for case in scene.cases.values():
        f = natural_frequencies(m, case.pose, scene.analytical)
        assert np.all(np.isfinite(f)) and np.all(f > 0) and np.all(np.diff(f) >= 0)


@_settings(5, 30)
@given(machines())
def test_the_fem_solves_and_pairs_every_case_of_a_checked_machine(raw):
    import tempfile
    from dataclasses import replace

    from runtime.cache import ResultCache
    from solvers.compare import analytical_case, error_table, fem_case

    got = checked(raw)
    if got is None:
        return
    scene, _ = got
    with tempfile.TemporaryDirectory() as tmp:
        cache = ResultCache(tmp)
        for legs in ("harmonic", "tetrahedra"):
            sized = replace(scene, fem=replace(scene.fem, legs=legs))
            for case in scene.cases.values():
                geometry = pose_geometry(scene.manipulator, case.pose)
                fem = fem_case(sized, geometry, cache, 0.4 * scene.manipulator.leg_diameter)
                hz = np.asarray(fem.record["frequencies_hz"])
                assert np.all(np.isfinite(hz)) and np.all(hz > 0)
                rows = error_table(analytical_case(sized, case, sized.analytical), fem,
                                   scene.analytical.modes)
                assert rows


@_settings(5, 30)
@given(machines())
def test_the_hard_cases_of_a_checked_machine_run(raw):
    got = checked(raw)
    if got is None:
        return
    scene, _ = got
    rows = hard_cases.evaluate(scene)
    assert len(rows) == len(hard_cases.CHEAP) + len(hard_cases.LIMITS)
    assert all(math.isfinite(r["measured"]) for r in rows)


@_settings(3, 10)
@given(raw=machines())
def test_a_checked_machine_validates(raw, tmp_path_factory):
    import tomllib  # noqa: F401 (the scene goes through a file, as a user's does)
    from functools import partial

    from pipeline.run import validate
    from reports.build import render_report
    from studies import RECORDS

    got = checked(raw)
    if got is None:
        return
    tmp = tmp_path_factory.mktemp("fuzz")
    path = tmp / "scene.toml"
    path.write_text(_toml(raw), encoding="utf-8")
    results = validate(str(path), tmp / "out", tmp / "cache",
                       profile="full" if SLOW else "ci",
                       report=partial(render_report, records=RECORDS) if SLOW else None)
    assert results["studies"]["workspace_validation"]["failed"] == 0
    assert results["studies"]["reachable_workspace"]["validation_poses"] >= 1


@pytest.mark.parametrize("sprung", [False, True], ids=["rigid", "sprung"])
@_settings(1, 10)
@given(data=st.data())
def test_solid_legs_meet_the_fem_limit_on_random_real_legs(sprung, data):
    """Issue 35's criterion on machines nobody tuned for: with solid legs (s = 8) every case
    is within 0.1 % of the FEM limit (harmonic legs, the scene's Richardson sequence) on
    f1-f6, plus the limit's own stated error."""
    import tempfile
    from dataclasses import replace

    from runtime.cache import ResultCache
    from solvers.refinement import fem_refinement, study_sizes

    raw = data.draw(real_leg_machines(sprung))
    got = checked(raw)
    assume(got is not None)  # the ranges give reachable machines: none compared is a failure
    scene, _ = got
    options = replace(scene.analytical, legs="solid", joint_ends="beam", elements=8, modes=6)
    with tempfile.TemporaryDirectory() as tmp:
        for case in scene.cases.values():
            geometry = pose_geometry(scene.manipulator, case.pose)
            study = fem_refinement(scene, geometry, ResultCache(tmp),
                                   study_sizes(scene.fem_study.refinement))
            limit = np.asarray(study["extrapolated_hz"][:6])
            stated = np.asarray(study["estimated_error_percent"][:6])
            error = 100 * np.abs(natural_frequencies(scene.manipulator, case.pose, options)
                                 / limit - 1)
            assert np.all(error <= 0.1 + stated), (case.name, error.round(3), stated.round(3))


@pytest.mark.parametrize("sprung", [False, True], ids=["rigid", "sprung"])
@_settings(1, 10)
@given(data=st.data())
def test_solid_legs_from_pieces_are_the_legs_condensed_at_every_pose_on_random_real_legs(
        sprung, data):
    """Issue 51's criterion on machines nobody tuned for: the solid legs read from pieces of
    their stroke (one stretched mesh a piece, interpolated in the length) are the legs
    condensed afresh at every pose within 1e-4 on f1-f10 at random reachable poses: two
    meshes of the same size, each within its own discretisation error (measured up to 6.7e-5
    on f1, 5e-7 on the actuator-legs scene)."""
    from tests.test_solid_leg_pieces import pieces_against_fresh

    raw = data.draw(real_leg_machines(sprung))
    got = checked(raw)
    assume(got is not None)
    scene, _ = got
    with pytest.MonkeyPatch.context() as patch:
        error = pieces_against_fresh(scene, patch, count=3,
                                     seed=data.draw(st.integers(0, 999)))
    assert error.max() < 1e-4, error.max(axis=0)


@pytest.mark.parametrize("sprung", [False, True], ids=["rigid", "sprung"])
@_settings(1, 10)
@given(data=st.data())
def test_reduced_solid_legs_are_the_kept_ones_on_random_real_legs(sprung, data):
    """Issue 51's criterion on machines nobody tuned for: the batched model, each part's
    interior reduced to the modes chosen for the machine, is the per-pose model (every
    station kept) within 1e-4 on f1-f10 at random reachable poses."""
    from tests.test_solid_leg_pieces import reduced_against_kept

    raw = data.draw(real_leg_machines(sprung))
    got = checked(raw)
    assume(got is not None)
    scene, _ = got
    error = reduced_against_kept(scene, count=3, seed=data.draw(st.integers(0, 999)))
    assert error.max() < 1e-4, error.max(axis=0)


def _toml(raw: dict) -> str:
    def value(v):
        return f'"{v}"' if isinstance(v, str) else repr(float(v) if not isinstance(v, int)
                                                         else v)
    lines = [f'name = "{raw["name"]}"']
    for table in ("manipulator", "material", "fidelity"):
        lines += ["", f"[{table}]"] + [f"{k} = {value(v)}" for k, v in raw[table].items()]
    for name, case in raw["cases"].items():
        lines += ["", f"[cases.{name}]"] + [f"{k} = {value(v)}" for k, v in case.items()]
    return "\n".join(lines) + "\n"


def test_a_machine_without_a_level_pose_is_refused_naming_the_binding_limit():
    raw = {"name": "no level pose",
           "manipulator": {"base_radius_mm": 600.0, "platform_radius_mm": 200.0,
                           "leg_diameter_mm": 40.0, "platform_thickness_mm": 20.0,
                           "actuator_min_mm": 300.0, "actuator_max_mm": 700.0,
                           "s_joint_max_deg": 20.0, "r_joint_max_deg": 60.0},
           "material": {"youngs_modulus_gpa": 200.0, "shear_modulus_gpa": 77.0,
                        "density_kg_m3": 7820.0},
           "cases": {"level": {"height_mm": 500.0}}}
    with pytest.raises(ValueError) as info:
        envelope.check(parse_scene(raw))
    text = str(info.value)
    assert "S-joint" in text and "\n" not in text, text


def test_the_level_band_is_bound_by_the_joint_limit_where_it_binds_first():
    """A lean of 400 mm with alpha_max = 45 deg needs z >= 400 mm (tan 45 = 1): the S-joint
    limit, not the actuator's L_min, bounds the band below."""
    raw = {"name": "lean", "manipulator": {
        "base_radius_mm": 600.0, "platform_radius_mm": 200.0, "leg_diameter_mm": 40.0,
        "platform_thickness_mm": 20.0, "actuator_min_mm": 300.0, "actuator_max_mm": 1200.0,
        "s_joint_max_deg": 45.0, "r_joint_max_deg": 60.0},
        "material": {"youngs_modulus_gpa": 200.0, "shear_modulus_gpa": 77.0,
                     "density_kg_m3": 7820.0},
        "cases": {"level": {"height_mm": 800.0}}}
    band = level_band(parse_scene(raw).manipulator)
    assert band.low == pytest.approx(0.4, abs=1e-9) and band.binding_low == "s_joint_max_deg"
    assert band.high == pytest.approx(math.sqrt(1.2**2 - 0.4**2), abs=1e-9)
    assert band.binding_high == "actuator_max_mm"
    with pytest.raises(WorkspaceError):
        level_band(parse_scene(raw | {"manipulator": raw["manipulator"] | {
            "s_joint_max_deg": 10.0}}).manipulator)
