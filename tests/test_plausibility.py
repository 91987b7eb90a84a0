"""Scenes the models cannot represent are refused at load, in one line naming key, value, unit.

Materials: Poisson ratio E / (2 G) - 1 in (0, 0.49] (P2 displacement tetrahedra lock towards
0.5), density 500..25,000 kg/m3, E 1..1,000 GPa (declared ranges). Geometry: every dimension
1 mm..100 m (declared), no leg shorter than its diameter, no plate thicker than its radius, no
legs overlapping at their joints. A plate thicker than the legs is modelled, not refused. A
misspelt key names the closest known key.
"""
from __future__ import annotations

import copy
import os
import stat
import tomllib

import pytest

from meshing.bodies import Assembly, Cylinder
from meshing.cache import cached_mesh
from meshing.geometry import MeshSettings
from scene import SceneError, parse_scene
from tests.conftest import PAPER_SCENE

RAW = tomllib.loads(PAPER_SCENE.read_text(encoding="utf-8"))


def scene_with(**changes):
    raw = copy.deepcopy(RAW)
    for dotted, value in changes.items():
        table, key = dotted.split("__")
        raw[table][key] = value
    return raw


@pytest.mark.parametrize("changes, message", [
    # Poisson ratio through E and G (G = E / (2 (1 + nu)))
    ({"material__shear_modulus_gpa": 200.0},
     "Poisson ratio E / (2 G) - 1 = -0.5, expected 0 < nu <= 0.49"),
    ({"material__shear_modulus_gpa": 200 / (2 * 1e-10)},
     "shear_modulus_gpa = 1000000000000.0: must be > 0 and <= 500 GPa"),
    ({"material__shear_modulus_gpa": 100.0}, "Poisson ratio E / (2 G) - 1 = 0, expected 0 < nu"),
    ({"material__shear_modulus_gpa": 200 / (2 * (1.5 - 2e-16))}, "expected 0 < nu <= 0.49"),
    ({"material__shear_modulus_gpa": 200 / (2 * 1.4995)}, "= 0.4995, expected 0 < nu <= 0.49"),
    ({"material__density_kg_m3": 1e-300},
     "density_kg_m3 = 1e-300: must be >= 500 and <= 25000 kg/m3"),
    ({"material__density_kg_m3": 30000.0}, "density_kg_m3 = 30000.0: must be >= 500 and"),
    ({"material__youngs_modulus_gpa": 0.5, "material__shear_modulus_gpa": 0.19},
     "youngs_modulus_gpa = 0.5: must be >= 1 and <= 1000 GPa"),
    ({"material__youngs_modulus_gpa": 2000.0}, "youngs_modulus_gpa = 2000.0: must be >= 1 and"),
    ({"material__youngs_modulus_gpa": 1e300}, "youngs_modulus_gpa = 1e+300: must be >= 1 and"),
    ({"manipulator__actuator_min_mm": 90.0},
     "actuator_min_mm = 90 mm: the shortest leg is shorter than its diameter "
     "leg_diameter_mm = 100 mm"),
    ({"manipulator__platform_thickness_mm": 0.5},
     "platform_thickness_mm = 0.5: must be >= 1 and <= 100000 mm"),
    ({"manipulator__actuator_max_mm": 1e300},
     "actuator_max_mm = 1e+300: must be >= 1 and <= 100000 mm"),
    ({"manipulator__platform_thickness_mm": 5000.0},
     "platform_thickness_mm = 5000 mm: thicker than the platform radius platform_radius_mm = "
     "200 mm"),
    ({"manipulator__leg_angles_deg": [0.0, 10.0, 240.0]},
     "leg_angles_deg = [0.0, 10.0, 240.0]: the parasitic-motion closure (Eq. 2) needs the legs "
     "120 degrees apart"),
    ({"manipulator__base_radius_mm": 55.0},
     "leg_diameter_mm = 100 mm: legs 1 and 2 overlap at their joints B1, B2"),
    ({"manipulator__platform_radius_mm": 55.0, "manipulator__platform_thickness_mm": 20.0},
     "legs 1 and 2 overlap at their joints A1, A2"),
])
def test_implausible_scenes_are_refused_in_one_line(changes, message):
    with pytest.raises(SceneError) as info:
        parse_scene(scene_with(**changes))
    text = str(info.value)
    assert message in text and "\n" not in text, text


def test_a_plate_thicker_than_twice_the_leg_diameter_is_modelled():
    """The joint sits where the scene puts it (the plate's mid-surface): both models take the
    leg to its joint and the whole plate's mass, so a heavier plate lowers every frequency."""
    from analytical.model import natural_frequencies

    thin = parse_scene(scene_with(manipulator__leg_diameter_mm=40.0))
    thick = parse_scene(scene_with(manipulator__leg_diameter_mm=40.0,
                                   manipulator__platform_thickness_mm=100.0))
    pose = thick.case("case1").pose
    f_thick = natural_frequencies(thick.manipulator, pose, thick.analytical)
    f_thin = natural_frequencies(thin.manipulator, pose, thin.analytical)
    assert f_thick.all() and (f_thick < f_thin).all()


@pytest.mark.parametrize("nu", [0.05, 0.3, 0.49])
def test_plausible_materials_load(nu):
    parse_scene(scene_with(material__shear_modulus_gpa=200 / (2 * (1 + nu))))


@pytest.mark.parametrize("table, typo, known", [
    ("material", "youngs_modulus", "youngs_modulus_gpa"),
    ("material", "Youngs_Modulus_GPa", "youngs_modulus_gpa"),
    ("manipulator", "leg_diametre_mm", "leg_diameter_mm"),
    ("fem", "RIM_FACTOR", "rim_factor"),
])
def test_a_misspelt_key_names_the_closest_known_one(table, typo, known):
    raw = copy.deepcopy(RAW)
    raw[table][typo] = raw[table].pop(known)
    with pytest.raises(SceneError, match=f"did you mean {known}\\?"):
        parse_scene(raw)


def test_a_key_unlike_any_gets_no_suggestion():
    raw = scene_with(manipulator__colour="red")
    with pytest.raises(SceneError) as info:
        parse_scene(raw)
    assert "unknown key 'colour'" in str(info.value) and "did you mean" not in str(info.value)


def test_a_megabyte_value_is_shortened_in_the_message():
    with pytest.raises(SceneError) as info:
        parse_scene(scene_with(material__density_kg_m3="x" * 1_000_000))
    assert len(str(info.value)) < 200


def test_mesh_cache_files_are_readable_by_others(tmp_path):
    mask = os.umask(0o022)
    try:
        cached_mesh(Assembly((Cylinder("leg1", (0, 0, 0), (0, 0, 0.3), 0.05),)),
                    MeshSettings(0.04, 1.0, rim_zone=0.0), tmp_path)
    finally:
        os.umask(mask)
    modes = {p.suffix: stat.S_IMODE(p.stat().st_mode) for p in tmp_path.iterdir()}
    assert modes == {".vtu": 0o644, ".json": 0o644}
