"""The calibrated height is reproducible from the code, and Case 1 matches the paper's row."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from analytical.calibration import calibrate_height
from analytical.model import natural_frequencies
from analytical.params import ModelOptions


def test_case1_reproduces_the_paper_theoretical_row_within_one_percent(scene):
    case = scene.case("case1")
    f = natural_frequencies(scene.manipulator, case.pose, ModelOptions(elements=3))
    deviation = f / np.array(case.paper_theory_hz) - 1
    assert np.abs(deviation).max() < 0.01, np.round(100 * deviation, 3)


def test_scene_height_is_the_minimax_calibration_of_case1(scene):
    case = scene.case("case1")
    cal = calibrate_height(scene.manipulator, case.pose, case.paper_theory_hz,
                           ModelOptions(elements=3))
    assert cal.height == pytest.approx(scene.calibrated_height, abs=0.05e-3)  # 0.1 mm rounding
    assert cal.worst_deviation < 0.0037


def test_literal_reading_misses_the_row_and_triangle_plate_cannot_reach_it(scene):
    case = scene.case("case1")
    literal = natural_frequencies(scene.manipulator, scene.case("case1_literal").pose)
    assert np.abs(literal / np.array(case.paper_theory_hz) - 1).min() > 0.15
    triangle = replace(scene.manipulator, platform_shape="triangle")
    cal = calibrate_height(triangle, case.pose, case.paper_theory_hz, ModelOptions(elements=3))
    assert cal.worst_deviation > 0.038
    eq8 = calibrate_height(scene.manipulator, case.pose, case.paper_theory_hz,
                           ModelOptions(elements=3, platform_inertia="paper-eq8"))
    assert eq8.worst_deviation > 0.05
