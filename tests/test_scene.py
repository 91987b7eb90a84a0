"""Scene files: SI conversion at the edge, and one clear line for every bad value."""
from __future__ import annotations

import copy
import math
import tomllib

import pytest

from scene import SceneError, load_scene, parse_scene
from tests.conftest import PAPER_SCENE

RAW = tomllib.loads(PAPER_SCENE.read_text())


def test_paper_scene_is_converted_to_si_once(scene):
    m = scene.manipulator
    assert (m.base_radius, m.platform_radius, m.leg_diameter) == pytest.approx((0.3, 0.2, 0.1))
    assert m.platform_thickness == pytest.approx(0.02)
    assert m.material.youngs_modulus == pytest.approx(200e9)
    assert m.material.poisson_ratio == pytest.approx(200 / 154 - 1)
    assert scene.case("case2").pose.tilt == pytest.approx(math.radians(-12))
    assert scene.case("case1").pose.height == scene.calibrated_height
    assert scene.case("case1").height_origin == "calibrated"
    assert scene.case("case1_literal").pose.height == pytest.approx(0.49)
    assert len(scene.case("case1").paper_theory_hz) == 6


def mutated(path, value):
    raw = copy.deepcopy(RAW)
    node = raw
    for key in path[:-1]:
        node = node.setdefault(key, {})
    if value is KeyError:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return raw


@pytest.mark.parametrize("path, value, needle", [
    (("manipulator", "leg_diameter_mm"), -100.0, "leg_diameter_mm = -100.0"),
    (("manipulator", "leg_diameter_mm"), "thick", "leg_diameter_mm = 'thick'"),
    (("manipulator", "leg_diametre_mm"), 100.0, "unknown key 'leg_diametre_mm'"),
    (("manipulator", "base_radius_mm"), KeyError, "base_radius_mm: missing"),
    (("manipulator", "platform_shape"), "hexagon", "platform_shape = 'hexagon'"),
    (("manipulator", "actuator_min_mm"), 1500.0, "actuator_min"),
    (("material", "shear_modulus_gpa"), 20.0, "Poisson ratio"),
    (("analytical", "elements"), 0, "elements = 0"),
    (("analytical", "beam"), "rayleigh", "beam = 'rayleigh'"),
    (("fem", "refinement_mm"), [20.0, 28.0, 14.0], "must strictly decrease"),
    (("fem", "refinement_mm"), [20.0, 14.0], "expected at least 3 numbers"),
    (("fem", "rim_factor"), 1.5, "rim_factor = 1.5"),
    (("calibration", "height", "reason"), "", "needs its reason"),
    (("cases", "case1", "tilt_deg"), 120.0, "tilt_deg = 120.0"),
    (("cases", "case1", "paper_fea_hz"), [1.0, "x"], "paper_fea_hz"),
    (("colour",), "red", "unknown key 'colour'"),
])
def test_bad_values_are_named(path, value, needle):
    with pytest.raises(SceneError, match=needle.replace("(", r"\(").replace(")", r"\)")) as exc:
        parse_scene(mutated(path, value))
    assert "\n" not in str(exc.value)


def test_an_elastic_plate_takes_tetrahedral_legs_unless_told_otherwise():
    assert parse_scene(mutated(("fem", "platform"), "elastic")).fem.legs == "tetrahedra"
    assert parse_scene(RAW).fem.legs == "harmonic"
    raw = mutated(("fem", "platform"), "elastic")
    raw["fem"]["legs"] = "harmonic"
    with pytest.raises(SceneError, match="legs = 'harmonic' with platform = 'elastic'"):
        parse_scene(raw)


def test_calibrated_height_needs_a_calibration():
    raw = copy.deepcopy(RAW)
    del raw["calibration"]
    with pytest.raises(SceneError, match="no \\[calibration.height\\]"):
        parse_scene(raw)


def test_unreadable_files(tmp_path):
    with pytest.raises(SceneError, match="does not exist"):
        load_scene(tmp_path / "missing.toml")
    broken = tmp_path / "broken.toml"
    broken.write_text("name = \n")
    with pytest.raises(SceneError, match="not valid TOML"):
        load_scene(broken)


def test_unknown_case_lists_the_known_ones(scene):
    with pytest.raises(SceneError, match="case 'case3' is not in scene.*case1, case2"):
        scene.case("case3")


def test_paper_printed_errors_are_checked_against_its_own_frequencies(scene):
    from pipeline.run import paper_rows
    assert paper_rows(scene.case("case1"))["printed_error_note"] is None
    note = paper_rows(scene.case("case2"))["printed_error_note"]
    assert "f5: printed 3.31 %" in note and "4.06 %" in note and "f4" not in note
