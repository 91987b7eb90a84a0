"""What sets the lowest modes (issue 23): the drive's stiffness swept in both models, the knee,
and the strain energy by part; carried by results.json and shown by the report.

The physics: springs in series, so lowering the drive's stiffness lowers every frequency of both
models (min-max), towards the mechanism on soft springs; the energy of a mode splits among legs,
joints and drive and sums to the whole; where the drive is soft its share of mode 1 tends to all.
"""
from __future__ import annotations

import json
import math
import shutil
from dataclasses import replace

import numpy as np
import pytest

import results
import studies.lowest_modes as lowest_modes_module
from runtime.cache import ResultCache
from scene import load_scene
from studies import RECORDS
from studies.lowest_modes import FACTORS, knee, lowest_modes
from tests.conftest import ROOT

SCENE = ROOT / "scenes" / "actuator-legs.toml"


def test_the_knee_of_two_springs_in_series_is_where_they_are_equal():
    """f1^2 = 1 / (1 / (c k) + 1 / f0^2): f1 = f0 / sqrt(2) exactly where c k = f0^2."""
    f0, c = 100.0, 40.0
    factors = np.array(FACTORS)
    f1 = 1.0 / np.sqrt(1.0 / (c * factors * 100.0) + 1.0 / f0**2)
    expected = f0**2 / (c * 100.0)
    assert knee(factors, f1, f0) == pytest.approx(expected, rel=0.1)  # log interpolation
    assert knee(factors, np.full(len(factors), f0), f0) is None  # never crossed


def test_a_soft_drive_is_swept_only_as_low_as_a_scene_may_declare():
    """A scene may declare a drive of 2 kN/m; 0.01 of it is no spring a scene could hold (and
    the study would stop on it): the sweep starts where the drive is still admissible."""
    from common.stiffness import MIN_SPRING
    from studies.lowest_modes import swept
    assert swept(160e6) == FACTORS  # the shipped scene's 160 N/um: the whole sweep
    assert swept(2 * MIN_SPRING) == (1.0, 3.0, 10.0, 30.0, 100.0)


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """The study on the shipped realistic scene, one case, at a coarse FEM (the pairing and the
    trends, not the last digit, are what is checked), at 0.01, 1 and 100 times its drive."""
    scene = load_scene(SCENE)
    scene = replace(scene, fem=scene.fem.with_size(0.05),  # the run's kind of choice
                    analytical=replace(scene.analytical, beam="timoshenko", shear="hutchinson"))
    cache = ResultCache(tmp_path_factory.mktemp("cache"))
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(lowest_modes_module, "FACTORS", FACTORS[::4])
        return lowest_modes(scene, ["level"], cache)


def test_lowering_the_drive_stiffness_never_raises_a_frequency_in_either_model(study):
    (case,) = study
    for model in ("analytical_hz", "fem_hz"):
        table = np.array([p[model] for p in case["sweep"]] + [case["rigid_drive"][model]])
        assert np.all(np.diff(table, axis=0) >= -1e-9 * table[1:]), model


def test_both_models_follow_the_sweep_within_the_scenes_tolerance(study):
    (case,) = study
    for point in case["sweep"]:
        assert max(abs(e) for e in point["error_percent"]) < 1.0, point["factor"]
        # every FEM answer of the sweep states its two-mesh error, the GCI included: the run's
        # mesh is within half a percent of the solid at every drive stiffness
        assert max(point["fem_estimated_error_percent"]) < 0.5, point["factor"]
        assert all(e >= g for e, g in zip(point["fem_estimated_error_percent"],
                                          point["fem_gci_percent"]))


def test_the_strain_energy_of_every_mode_is_shared_out_whole(study):
    (case,) = study
    for row in case["shares"]:
        total = sum(row[f"{p}_percent"] for p in ("legs", "joints", "drive", "platform"))
        assert total == pytest.approx(100.0, abs=1e-6)
        assert row["platform_percent"] == 0.0  # a rigid platform stores none
    assert case["sets_lowest"] == case["shares"][0]["largest"]


def test_a_soft_drive_holds_the_energy_of_the_lowest_mode(tmp_path):
    scene = load_scene(SCENE)
    springs = scene.manipulator.stiffness.scaled(1e-3, {"actuator_axial"})
    soft = replace(scene, manipulator=replace(scene.manipulator, stiffness=springs))
    from studies.lowest_modes import shares
    rows = shares(soft, soft.case("level").pose, 3)
    assert all(r["drive_percent"] > 95.0 for r in rows)


def test_results_carry_the_study_and_the_report_shows_it(study, tmp_path):
    """The fixture's results with this scene's springs and the study: the schema admits them,
    and the report has the section, its figure and both tables."""
    from reports.build import build_report
    from tests.test_report import FIXTURES, RESULTS, _ci_profile

    data = _ci_profile(json.loads(RESULTS.read_text()))  # no other study, no 3-D pictures
    for case in data["cases"]:
        case["fem"]["vtu"] = None
    data["scene"]["manipulator"]["stiffness"]["actuator_axial_n_per_um"] = 160.0
    data["scene"]["manipulator"]["leg"].update(
        housing_length_mm=420.0, housing_outer_diameter_mm=110.0, housing_inner_diameter_mm=80.0,
        rod_outer_diameter_mm=60.0, rod_inner_diameter_mm=40.0)
    data["studies"]["lowest_modes"] = json.loads(json.dumps(study))
    results.validated(data, RECORDS, "test")
    (tmp_path / "results.json").write_text(json.dumps(data))
    shutil.copytree(FIXTURES / "modes", tmp_path / "modes")
    html, _ = build_report(tmp_path / "results.json", tmp_path, records=RECORDS)
    page = html.read_text(encoding="utf-8")
    assert "What sets the lowest modes" in page and 'data-chart="sweep:level"' in page
    assert "drive axial stiffness" in page and 'alt="leg profile"' in page
    for picture in ("stiffness_sweep_level.png", "leg_profile.png"):  # the PDF's
        assert (tmp_path / "figures" / picture).stat().st_size > 2_000
    assert "Strain energy of every mode by part" in page
    knees = study[0]["knee_factors"]
    assert ("Knees: " in page) == any(k is not None for k in knees)
    assert ("No knee within the sweep" in page) == any(k is None for k in knees)
    assert not math.isnan(study[0]["shares"][0]["frequency_hz"])
