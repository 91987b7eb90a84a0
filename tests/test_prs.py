"""The 3-PRS: sliders on rails carry the revolute joints, legs keep their length.

Its physics is the 3-RPS's on a different placement of the joints (`analytical.architecture`),
so the specification is a set of identities and closures:
- closure: every leg is L long to round-off, every slider on its rail, every leg in its R
  joint's plane, for random machines and poses; the batched kinematics equals the per-pose;
- the level-pose identity: a 3-PRS with vertical rails at radius r1, level, is the 3-RPS with
  base radius r1 raised to the sliders' height and legs of the same length: the same structure,
  so the same frequencies (1e-9), by both models;
- the drive acts along the rail: with the legs vertical (r1 = r2) rail and leg coincide and the
  identity holds with a drive spring; with leaning legs the two drives differ;
- inclined rails change the frequencies; turning the layout or the whole machine does not;
- the workspace: the level band of vertical rails in closed form (the stroke shifted by the
  legs' height), and the scene's keys per architecture.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from analytical.architectures import actuation, height_reach
from analytical.kinematics import PoseError, pose_geometry
from analytical.modal import solve_modes
from analytical.model import natural_frequencies
from analytical.params import Manipulator, Material, ModelOptions, Pose
from analytical.pose_batch import pose_batch
from analytical.reach import level_band
from analytical.substructure import assemble
from common.stiffness import Stiffness
from scene import SceneError, parse_scene

STEEL = Material(210e9, 81e9, 7850.0)
OPTIONS = (ModelOptions(), ModelOptions(beam="timoshenko", elements=5))
RNG_SEED = 20261126


def prs(r1=0.35, r2=0.25, length=0.66, d=0.06, angle=90.0, stroke=(0.0, 0.6), **kw):
    return Manipulator(base_radius=r1, platform_radius=r2, leg_diameter=d,
                       platform_thickness=0.03, material=STEEL, architecture="3-PRS",
                       rail_angle=math.radians(angle), leg_length=length, slider_min=stroke[0],
                       slider_max=stroke[1], s_joint_max=math.radians(60),
                       r_joint_max=math.radians(60), **kw)


def rps_twin(m: Manipulator) -> Manipulator:
    """The 3-RPS with the same radii, legs and springs (its actuator range holds L)."""
    return Manipulator(base_radius=m.base_radius, platform_radius=m.platform_radius,
                       leg_diameter=m.leg_diameter, platform_thickness=m.platform_thickness,
                       material=m.material, actuator_min=0.5 * m.leg_length,
                       actuator_max=1.5 * m.leg_length, s_joint_max=m.s_joint_max,
                       r_joint_max=m.r_joint_max, stiffness=m.stiffness, payload=m.payload,
                       leg_angles=m.leg_angles)


def random_machines(count: int, seed: int = RNG_SEED, drive: bool = True):
    """Plausible 3-PRS machines: r1 200-500 mm, r2 0.4-1.0 r1, L 1.2-3 r1, d L/20-L/8,
    rails 60-120 degrees, a stroke of 0.5-1.5 L, a drive of 50-500 N/um (or rigid)."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        r1 = rng.uniform(0.2, 0.5)
        length = r1 * rng.uniform(1.2, 3.0)
        springs = Stiffness(actuator_axial=rng.uniform(5e7, 5e8) if drive else 0.0)
        yield prs(r1=r1, r2=r1 * rng.uniform(0.4, 1.0), length=length,
                  d=length / rng.uniform(8.0, 20.0), angle=rng.uniform(60.0, 120.0),
                  stroke=(0.0, length * rng.uniform(0.5, 1.5)), stiffness=springs,
                  leg_angles=tuple(rng.uniform(-1, 1) + np.array([0, 2, 4]) * math.pi / 3))


def random_poses(m: Manipulator, count: int, rng) -> list[Pose]:
    band = level_band(m)
    out = []
    while len(out) < count:
        pose = Pose(rng.uniform(band.low, band.high), rng.uniform(0, 2 * math.pi),
                    rng.uniform(-0.4, 0.4))
        if pose_batch(m, pose.height, pose.azimuth, pose.tilt).feasible[0]:
            out.append(pose)
    return out


# --- closure --------------------------------------------------------------------------------

def test_closure_on_random_machines_and_poses():
    """|P_i A_i| = L, P_i = B_i + s_i u_i on the rail, the leg normal to the R axis and
    leaning forward along the rail, to round-off; the batched kinematics is the per-pose."""
    rng = np.random.default_rng(RNG_SEED)
    checked = 0
    for m in random_machines(12):
        for pose in random_poses(m, 5, rng):
            g = pose_geometry(m, pose)
            feet = m.base_radius * np.stack([np.cos(m.leg_angles), np.sin(m.leg_angles),
                                             np.zeros(3)], axis=1)
            assert np.allclose(np.linalg.norm(g.platform_points - g.base_points, axis=1),
                               m.leg_length, rtol=0, atol=1e-14)
            radial = feet / m.base_radius
            a = m.rail_angle  # the rail, in its vertical plane: cos a outward, sin a up
            rails = math.cos(a) * radial + math.sin(a) * np.array([0.0, 0.0, 1.0])
            assert np.allclose(g.drive_axes, rails, rtol=0, atol=1e-15)
            assert np.allclose(g.base_points, feet + g.actuation[:, None] * rails, atol=1e-14)
            # beta: the leg's angle from the rail in that plane, positive leaning outward
            x = g.leg_directions
            polar = np.arctan2(x[:, 2], np.einsum("ij,ij->i", x, radial))
            assert np.allclose(g.r_joint_angles, a - polar, rtol=0, atol=1e-12)
            assert np.abs(np.einsum("ij,ij->i", g.leg_directions, g.joint_axes)).max() < 1e-12
            assert np.all(np.einsum("ij,ij->i", g.leg_directions, rails) > 0)
            assert np.all((g.actuation >= m.slider_min) & (g.actuation <= m.slider_max))
            batch = pose_batch(m, pose.height, pose.azimuth, pose.tilt)
            assert batch.feasible[0]
            assert batch.actuation[0] == pytest.approx(g.actuation, abs=1e-14)
            twin = batch.geometry(0)
            for name in ("base_points", "platform_points", "leg_frames", "actuation",
                         "drive_axes", "r_joint_angles", "s_joint_angles"):
                assert np.allclose(getattr(twin, name), getattr(g, name), rtol=0, atol=1e-13)
            checked += 1
    assert checked == 60


def test_slider_limits_are_refused_by_name():
    m = prs()
    band = level_band(m)
    with pytest.raises(PoseError, match="slider 1 would travel .* above slider_max_mm = 600"):
        pose_geometry(m, Pose(band.high + 1e-3))
    with pytest.raises(PoseError, match="below slider_min_mm = 0"):
        pose_geometry(m, Pose(band.low - 1e-3))


def test_level_band_of_vertical_rails_is_the_stroke_raised_by_the_legs():
    """Vertical rails, level platform: z = s + sqrt(L^2 - (r1 - r2)^2) for every leg, so the
    level band is the stroke shifted by the legs' height, where no joint limit binds first."""
    for m in random_machines(6):
        m = replace(m, rail_angle=math.pi / 2)
        rise = math.sqrt(m.leg_length ** 2 - (m.base_radius - m.platform_radius) ** 2)
        band = level_band(m)
        assert band.low == pytest.approx(m.slider_min + rise, abs=1e-9)
        assert band.high == pytest.approx(m.slider_max + rise, abs=1e-9)
        assert (band.binding_low, band.binding_high) == ("slider_min_mm", "slider_max_mm")
        assert height_reach(m) == pytest.approx(m.slider_max + m.leg_length)


# --- the level-pose identity ------------------------------------------------------------------

@pytest.mark.parametrize("options", OPTIONS, ids=["EB s=3", "Timoshenko s=5"])
def test_level_prs_with_vertical_rails_is_the_raised_rps(options):
    """The same structure translated: equal frequencies to 1e-9, random machines and
    heights, with joint springs and a payload."""
    rng = np.random.default_rng(RNG_SEED + 1)
    springs = Stiffness(base_joint_translational=8e8, base_joint_rotational=1.3e6,
                        platform_joint_translational=3e8)
    for m in random_machines(8, drive=False):  # the drive: test_the_drive_acts_along_the_rail
        m = replace(m, rail_angle=math.pi / 2, stiffness=springs)
        band = level_band(m)
        z = rng.uniform(band.low, band.high)
        g = pose_geometry(m, Pose(z))
        s = float(g.actuation[0])
        assert np.allclose(g.actuation, s, atol=1e-15)
        twin = rps_twin(m)
        g_twin = pose_geometry(twin, Pose(z - s))
        assert np.allclose(g_twin.base_points + [0, 0, s], g.base_points, atol=1e-14)
        assert np.allclose(g_twin.r_joint_angles, g.r_joint_angles, atol=1e-14)
        assert np.allclose(g_twin.s_joint_angles, g.s_joint_angles, atol=1e-14)
        f_prs = natural_frequencies(m, Pose(z), options)
        f_rps = natural_frequencies(twin, Pose(z - s), options)
        assert np.abs(f_prs / f_rps - 1).max() < 1e-9


def test_the_drive_acts_along_the_rail():
    """With r1 = r2 the level legs are vertical, rail and leg coincide, and the identity holds
    with a drive spring; with leaning legs a drive along the rail is not one along the leg."""
    drive = Stiffness(actuator_axial=1.5e8)
    vertical = prs(r1=0.3, r2=0.3, stiffness=drive)
    z = 0.9
    s = float(pose_geometry(vertical, Pose(z)).actuation[0])
    f_prs = natural_frequencies(vertical, Pose(z), OPTIONS[1])
    f_rps = natural_frequencies(rps_twin(vertical), Pose(z - s), OPTIONS[1])
    assert np.abs(f_prs / f_rps - 1).max() < 1e-9
    leaning = prs(stiffness=drive)
    s = float(pose_geometry(leaning, Pose(z)).actuation[0])
    f_prs = natural_frequencies(leaning, Pose(z), OPTIONS[1])
    f_rps = natural_frequencies(rps_twin(leaning), Pose(z - s), OPTIONS[1])
    assert np.abs(f_prs / f_rps - 1).max() > 1e-3
    rigid = natural_frequencies(replace(leaning, stiffness=Stiffness()), Pose(z), OPTIONS[1])
    assert np.all(f_prs < rigid)  # a spring in the load path softens every mode


def test_batched_maps_equal_the_per_pose_model():
    """The workspace maps' batched assembly (drive along the rail included) is the per-pose
    model's, to 1e-10."""
    from analytical.batch_model import assemble_batch
    from analytical.batch_solve import batch_frequencies, standard_form

    rng = np.random.default_rng(RNG_SEED + 3)
    for m in random_machines(4):
        poses = random_poses(m, 6, rng)
        batch = pose_batch(m, [p.height for p in poses], [p.azimuth for p in poses],
                           [p.tilt for p in poses])
        hz = batch_frequencies(standard_form(assemble_batch(m, batch, OPTIONS[1])), 6)
        each = np.array([natural_frequencies(m, p, OPTIONS[1]) for p in poses])
        assert np.abs(hz / each - 1).max() < 1e-10


def test_inclined_rails_change_the_frequencies():
    """The same platform pose, rails at 90 and at 75 degrees: the sliders sit elsewhere, the
    legs lean differently, the frequencies move."""
    upright, inclined = prs(), prs(angle=75.0)
    pose = Pose(0.95, 0.4, 0.1)
    f_up = natural_frequencies(upright, pose, OPTIONS[0])
    f_in = natural_frequencies(inclined, pose, OPTIONS[0])
    assert np.abs(f_in / f_up - 1).max() > 1e-3


def test_turned_layout_and_rigid_rotations_leave_frequencies_unchanged():
    rng = np.random.default_rng(RNG_SEED + 2)
    for m in random_machines(4):
        pose = random_poses(m, 1, rng)[0]
        f = natural_frequencies(m, pose, OPTIONS[1])
        turn = rng.uniform(-math.pi, math.pi)
        turned = replace(m, leg_angles=tuple(a + turn for a in m.leg_angles))
        f_turned = natural_frequencies(turned, replace(pose, azimuth=pose.azimuth + turn),
                                       OPTIONS[1])
        assert np.abs(f_turned / f - 1).max() < 1e-9
        g = pose_geometry(m, pose)
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        moved = g.transformed(q * np.sign(np.linalg.det(q)), rng.normal(size=3))
        here, there = (solve_modes(assemble(m, geometry, OPTIONS[1]), 6).frequencies_hz
                       for geometry in (g, moved))
        assert np.abs(there / here - 1).max() < 1e-9
        assert np.abs(here / f - 1).max() < 1e-12


# --- the scene --------------------------------------------------------------------------------

def _raw(**manipulator) -> dict:
    base = {"architecture": "3-PRS", "base_radius_mm": 350.0, "platform_radius_mm": 250.0,
            "leg_diameter_mm": 60.0, "platform_thickness_mm": 30.0, "leg_length_mm": 660.0,
            "slider_max_mm": 500.0, "s_joint_max_deg": 50.0, "r_joint_max_deg": 50.0}
    base.update(manipulator)
    return {"manipulator": {k: v for k, v in base.items() if v is not None},
            "material": {"youngs_modulus_gpa": 210.0, "shear_modulus_gpa": 81.0,
                         "density_kg_m3": 7850.0},
            "cases": {"level": {"height_mm": 900.0}}}


def test_scene_reads_a_prs_in_si():
    m = parse_scene(_raw(rail_angle_deg=80.0, slider_min_mm=20.0)).manipulator
    assert (m.architecture, m.leg_length, m.slider_min, m.slider_max) == ("3-PRS", 0.66, 0.02,
                                                                         0.5)
    assert m.rail_angle == pytest.approx(math.radians(80.0))
    assert (m.actuator_min, m.actuator_max) == (0.66, 0.66)  # the legs' one length
    act = actuation(m)
    assert (act.low, act.high, act.low_key) == (0.02, 0.5, "slider_min_mm")


@pytest.mark.parametrize("change, message", [
    (dict(actuator_min_mm=300.0), "actuator_min_mm = 300.0 with architecture = '3-PRS': the "
     "key belongs to a 3-RPS"),
    (dict(leg_length_mm=None), r"leg_length_mm: missing"),
    (dict(slider_max_mm=None), r"slider_max_mm: missing"),
    (dict(slider_min_mm=600.0), "slider_min_mm = 600 mm is not below slider_max_mm = 500 mm"),
    (dict(rail_angle_deg=5.0), "rail_angle_deg = 5.0: must be >= 20"),
    (dict(leg_length_mm=40.0), "leg_length_mm = 40 mm: the shortest leg is shorter than its "
     "diameter"),
    (dict(base_joint="S", platform_joint="R"), r"it admits only \(R, S\)"),
    (dict(architecture="3-RRR"), "architecture = '3-RRR': expected one of 3-RPS, 3-PRS"),
])
def test_scene_refuses_what_a_prs_cannot_be(change, message):
    with pytest.raises(SceneError, match=message) as info:
        parse_scene(_raw(**change))
    assert "\n" not in str(info.value)


def test_a_rps_scene_refuses_prs_keys():
    raw = _raw(architecture=None, leg_length_mm=None, slider_max_mm=None,
               actuator_min_mm=300.0, actuator_max_mm=900.0, rail_angle_deg=80.0)
    with pytest.raises(SceneError, match="rail_angle_deg = 80.0 with architecture = '3-RPS': "
                       "the key belongs to a 3-PRS"):
        parse_scene(raw)


def test_a_prs_leg_is_a_link_not_an_actuator():
    raw = _raw(leg_diameter_mm=None)
    raw["leg"] = {"housing_length_mm": 300.0, "housing_outer_diameter_mm": 80.0,
                  "rod_outer_diameter_mm": 50.0}
    with pytest.raises(SceneError, match="links of fixed length"):
        parse_scene(raw)


@pytest.mark.parametrize("legs", ["harmonic", "tetrahedra"])
def test_level_identity_holds_for_the_fem(legs, tmp_path):
    """The FEM meshes the same legs, translated: the harmonic legs give the raised 3-RPS's
    frequencies to 1e-9; gmsh meshes a translated body anew, so the tetrahedral legs agree
    within the discretisation error of a 0.5 d mesh (measured 1e-4). With r1 = r2 the level
    legs are vertical, along the rails, so the drive spring is the same in both; the same
    machine with r2 < r1 (legs leaning, a drive along the rail, not the leg) differs."""
    from fem_reference.model import FemRuntime, solve_pose

    m = prs(r1=0.3, r2=0.3, stiffness=Stiffness(actuator_axial=1.5e8,
                                                 base_joint_translational=8e8))
    z = 0.95
    g = pose_geometry(m, Pose(z))
    s = float(g.actuation[0])
    twin = rps_twin(m)
    options = replace(parse_scene(_raw()).fem, legs=legs).with_size(0.5 * m.leg_diameter)
    runtime = FemRuntime(cache_dir=tmp_path)
    f_prs = solve_pose(m, g, options, runtime).frequencies_hz
    f_rps = solve_pose(twin, pose_geometry(twin, Pose(z - s)), options, runtime).frequencies_hz
    assert np.abs(f_prs / f_rps - 1).max() < (1e-9 if legs == "harmonic" else 1e-3)
    if legs == "harmonic":
        leaning = replace(m, platform_radius=0.22)
        g = pose_geometry(leaning, Pose(z))
        s = float(g.actuation[0])
        f_prs = solve_pose(leaning, g, options, runtime).frequencies_hz
        twin = rps_twin(leaning)
        f_rps = solve_pose(twin, pose_geometry(twin, Pose(z - s)), options,
                           runtime).frequencies_hz
        assert np.abs(f_prs / f_rps - 1).max() > 1e-3
