"""Input uncertainty through the fast model (scene/uncertainty.py, analytical/sample_batch.py,
solvers/sensitivity.py, solvers/uncertainty.py): the batched samples against the per-pose
model, closed forms of a density known within a lognormal spread (every frequency scales as
rho^-1/2), a spring's Sobol' index vanishing towards the rigid joint, the sampling statistics
converging at the stated rate and within their stated errors, and the inputs refused in one
line."""
from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from analytical.model import natural_frequencies
from analytical.params import ModelOptions
from analytical.sample_batch import assemble_samples, sample_poses
from scene.load import SceneError, parse_scene, read_toml
from solvers.sensitivity import base_rows, design
from solvers.uncertainty import machines, propagate, sample_model

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "scenes" / "paper.toml"
FAST = ModelOptions(elements=2, beam="timoshenko", modes=6)


def scene_with(inputs: dict, samples: int = 128, base: Path = PAPER, **tables):
    raw = read_toml(base)
    raw.pop("uncertainty", None)
    for table, values in tables.items():
        raw[table] = {**raw.get(table, {}), **values}
    raw["uncertainty"] = {"samples": samples, **inputs}
    return parse_scene(raw, "test scene")


def lognormal_sd(cv_percent: float) -> float:
    return math.sqrt(math.log1p((cv_percent / 100.0) ** 2))


def test_samples_solved_as_a_batch_agree_with_the_per_pose_model():
    scene = scene_with({
        "material.youngs_modulus_gpa": {"distribution": "normal", "cv_percent": 3.0},
        "material.density_kg_m3": {"distribution": "lognormal", "cv_percent": 5.0},
        "manipulator.leg_diameter_mm": {"distribution": "uniform", "low": 95.0, "high": 105.0},
        "manipulator.platform_radius_mm": {"distribution": "normal", "cv_percent": 2.0}})
    case = scene.cases["case1"]
    unit = np.random.default_rng(3).random((7, 4))
    built = machines(scene, unit)
    got = sample_model(scene, FAST, case.pose, unit, 6, False).frequencies_hz
    for k, m in enumerate(built):
        assert got[k] == pytest.approx(natural_frequencies(m, case.pose, FAST), rel=1e-10)
    poses = sample_poses(built, case.pose, shared=False)
    assert assemble_samples(built, poses, FAST).stiffness.shape[0] == 7


def test_a_follower_keeps_its_ratio_to_its_leader():
    scene = scene_with({
        "material.youngs_modulus_gpa": {"distribution": "normal", "cv_percent": 4.0},
        "material.shear_modulus_gpa": {"follows": "material.youngs_modulus_gpa"}})
    built = machines(scene, design(1, 64, 1))
    ratio = [m.material.shear_modulus / m.material.youngs_modulus for m in built]
    nominal = scene.manipulator.material
    assert ratio == pytest.approx([nominal.shear_modulus / nominal.youngs_modulus] * len(ratio),
                                  rel=1e-14)
    assert np.std([m.material.youngs_modulus for m in built]) > 0.0


def test_density_alone_scales_every_frequency_as_rho_to_the_minus_half():
    """Legs and platform of one material, no payload or springs: M scales with rho, K not, so
    f = f0 (rho / rho0)^-1/2 sample by sample, log f has half the log-spread of rho, and the
    density explains all the variance (Sobol' indices 1)."""
    cv, n = 10.0, 256
    scene = scene_with({"material.density_kg_m3": {"distribution": "lognormal",
                                                   "cv_percent": cv}}, samples=n)
    case = scene.cases["case1"]
    record = propagate(scene, FAST, case.pose, 6)
    rho0 = scene.manipulator.material.density
    unit = design(1, n, scene.uncertainty.settings.seed)
    rho = np.array([m.material.density for m in machines(scene, unit)])
    f = sample_model(scene, FAST, case.pose, unit, 6, False).frequencies_hz
    f0 = np.array([m["nominal_hz"] for m in record["modes"]])
    assert f == pytest.approx(f0 * np.sqrt(rho0 / rho)[:, None], rel=1e-9)
    s = lognormal_sd(cv)
    rows = base_rows(n, 1)
    spread = np.log(f[rows]).std(axis=0, ddof=1) / np.log(rho[rows]).std(ddof=1)
    assert spread == pytest.approx([0.5] * 6, rel=1e-9)  # exactly half, sample by sample
    for k, mode in enumerate(record["modes"]):
        # closed forms: log f is normal, mean ln f0 + s^2 / 4, sd s / 2: mean f0 exp(3 s^2 / 8),
        # quantiles f0 exp(s^2 / 4 -+ 1.96 s / 2); each within its stated 95 % sampling error
        exact = {"mean_hz": f0[k] * math.exp(3 * s * s / 8),
                 "q025_hz": f0[k] * math.exp(s * s / 4 - 1.959964 * s / 2),
                 "q975_hz": f0[k] * math.exp(s * s / 4 + 1.959964 * s / 2)}
        for key, value in exact.items():
            assert abs(mode[key] - value) <= mode[key.replace("_hz", "_error_hz")], (k, key)
        sd = exact["mean_hz"] * math.sqrt(math.exp(s * s / 4) - 1)
        assert abs(mode["std_hz"] - sd) <= mode["std_error_hz"]
        for kind in ("sobol_first", "sobol_total"):
            value = mode[kind]["material.density_kg_m3"]
            error = mode[kind + "_error"]["material.density_kg_m3"]
            assert abs(value - 1.0) <= max(error, 1e-9), (k, kind, value, error)


@pytest.mark.parametrize("order", [0, 1])
def test_sampling_errors_fall_at_the_stated_rate_and_bound_the_true_error(order):
    """The stated error of the mean (bootstrap, 95 %) falls as 1 / sqrt(N) (x4 samples: x1/2)
    and bounds the true error at every N (the closed form of the density case)."""
    cv = 10.0
    s = lognormal_sd(cv)
    stated, true = [], []
    for n in (64, 256, 1024):
        scene = scene_with({"material.density_kg_m3": {"distribution": "lognormal",
                                                       "cv_percent": cv}}, samples=n)
        mode = propagate(scene, FAST, scene.cases["case1"].pose, 2)["modes"][order]
        exact = mode["nominal_hz"] * math.exp(3 * s * s / 8)
        stated.append(mode["mean_error_hz"])
        true.append(abs(mode["mean_hz"] - exact))
    assert all(t <= e for t, e in zip(true, stated)), (true, stated)
    ratios = np.array(stated[:-1]) / np.array(stated[1:])
    assert np.all((1.6 < ratios) & (ratios < 2.5)), ratios  # 2 at the stated 1 / sqrt(N)


def test_a_spring_towards_the_rigid_joint_loses_its_index():
    """E within 2 % and a base joint spring within 30 %: as the spring grows stiff the joint
    tends to the rigid one, and the spring's total index tends to 0."""
    totals = []
    for k in (30.0, 3e3, 3e5):
        scene = scene_with({
            "material.youngs_modulus_gpa": {"distribution": "normal", "cv_percent": 2.0},
            "stiffness.base_joint_translational_n_per_um": {"distribution": "lognormal",
                                                            "cv_percent": 30.0}},
            samples=128, stiffness={"base_joint_translational_n_per_um": k})
        mode = propagate(scene, FAST, scene.cases["case1"].pose, 1)["modes"][0]
        totals.append(mode["sobol_total"]["stiffness.base_joint_translational_n_per_um"])
    assert totals[0] > 0.1 and totals[0] > totals[1] > totals[2]
    assert totals[2] < 1e-3


@pytest.mark.parametrize("inputs, expected", [
    ({"material.density_kg_m3": {"distribution": "normal", "cv_percent": 30.0}},
     "cv_percent = 30 for a normal input: at most 20"),
    ({"material.density_kg_m3": {"distribution": "gamma", "cv_percent": 3.0}},
     "distribution = 'gamma'"),
    ({"material.density_kg_m3": {"cv_percent": 3.0}}, "missing distribution"),
    ({"payload.mass_kg": {"distribution": "uniform", "low": 5.0, "high": 8.0}},
     "the scene's value 0 is outside low..high"),
    ({"material.density_kg_m3": {"distribution": "uniform", "cv_percent": 3.0}},
     "a uniform input takes low and high"),
    ({"material.shear_modulus_gpa": {"follows": "material.youngs_modulus_gpa"}},
     "that key has no distribution"),
    ({"material.name": {"distribution": "normal", "cv_percent": 1.0}},
     "is not a number of [material]"),
    ({"stiffness.actuator_axial_n_per_um": {"distribution": "lognormal", "cv_percent": 10.0}},
     "needs a positive value"),
    ({"material.density_kg_m3": {"distribution": "lognormal", "cv_percent": 200.0}},
     "at its low end material.density_kg_m3 = 8.40944 kg/m3: must be >= 500"),
    ({}, "no uncertain input"),
])
def test_bad_uncertainty_is_refused_in_one_line(inputs, expected):
    with pytest.raises(SceneError) as info:
        scene_with(inputs)
    text = str(info.value)
    assert expected in text and "\n" not in text, text


def test_an_input_whose_end_is_no_machine_is_refused_by_the_propagating_command(tmp_path):
    """platform_radius_mm within 20 %: its low end (4.75 sd) is a 9.9 mm plate radius, thinner
    than the plate: refused in one line naming the key and the end, exit 2, nothing written."""
    import re
    import subprocess
    import sys

    text = PAPER.read_text(encoding="utf-8")
    raw = re.sub(r"(?ms)^\[uncertainty\].*?(?=^\[)", "", text) + (
        '\n[uncertainty]\n"manipulator.platform_radius_mm" = '
        '{ distribution = "normal", cv_percent = 20.0 }\n')
    path = tmp_path / "scene.toml"
    path.write_text(raw, encoding="utf-8")
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "rps", "uncertainty", "--scene", str(path),
                           "--out", str(out)], capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 2, done.stderr
    line = done.stderr.strip()
    assert "\n" not in line and '"manipulator.platform_radius_mm": at its low end' in line, line
    assert not out.exists()


def test_the_vv20_verdict_reads_e_against_its_uncertainties():
    from solvers import vv20

    assert vv20.from_bound(0.3) == pytest.approx(0.3 / math.sqrt(3))
    assert vv20.u_val(0.3, 0.4, None) == pytest.approx(0.5)
    assert vv20.u_val(None, 1.2, 0.5) == pytest.approx(1.3)
    assert vv20.verdict(0.05, 0.03, 1.0).startswith("not resolved")  # |E| <= 2 u_num
    assert vv20.verdict(-1.9, 0.03, 1.0).startswith("within 2 u_val")  # |E| <= 2 u_val
    assert vv20.verdict(2.1, 0.03, 1.0).startswith("the model's error matters")
    assert vv20.verdict(2.1, None, 1.0).startswith("the model's error matters")


def test_inputs_that_are_valid_only_together_are_moved_together():
    """A rod's outer diameter with its bore following it: each sample's pair is checked as a
    pair (moving one first would leave a wall thinner than 1 mm on the way)."""
    scene = scene_with({"leg.rod_outer_diameter_mm": {"distribution": "uniform", "low": 41.0,
                                                      "high": 62.0},
                        "leg.rod_inner_diameter_mm": {"follows": "leg.rod_outer_diameter_mm"}},
                       base=ROOT / "scenes" / "actuator-legs.toml")
    built = machines(scene, design(1, 64, 1))
    assert min(m.leg.rod_outer_diameter - m.leg.rod_inner_diameter for m in built) > 0.0
    ratio = [m.leg.rod_inner_diameter / m.leg.rod_outer_diameter for m in built]
    assert ratio == pytest.approx([ratio[0]] * len(ratio), rel=1e-12)


def test_the_band_along_a_path_holds_the_scene_values_and_names_a_pose_out_of_reach():
    scene = scene_with({"material.youngs_modulus_gpa": {"distribution": "normal",
                                                        "cv_percent": 3.0}})
    from solvers.uncertainty import band, nominal

    case = scene.cases["case1"]
    far = replace(case.pose, height=1.2)  # beyond the legs' full length
    found = band(scene, FAST, [case.pose, far], 3, samples=64)
    low, median, high = found[0]["f1_hz"]
    f1 = nominal(scene, FAST, case.pose, 3, False).frequencies_hz[0, 0]
    assert low < f1 < high and low < median < high
    assert high / low == pytest.approx(math.exp(2 * 1.96 * 0.5 * 0.03), rel=0.1)  # f ~ E^1/2
    assert "cannot reach the pose" in found[1]["refused"]


def test_an_unreachable_sample_is_refused_before_any_solve():
    scene = scene_with({"manipulator.actuator_max_mm": {
        "distribution": "uniform", "low": 1100.0, "high": 1300.0}},
        manipulator={"actuator_max_mm": 1200.0})
    case = scene.cases["case1"]
    high = replace(case.pose, height=1.18)
    with pytest.raises(Exception) as info:
        sample_model(scene, FAST, high, design(1, 64, 1), 3, False)
    assert "cannot reach the pose" in str(info.value)


@pytest.mark.fuzz
@pytest.mark.parametrize("kind", ["machine", "real legs"])
def test_random_machines_propagate_as_their_per_pose_model(kind):
    """Random plausible machines (3-RPS and 3-PRS, real legs with springs) with random
    tolerances on the material, a dimension and a spring: each sample solved in the batch is
    its own machine's per-pose model, the statistics are ordered and the indices bounded;
    with the density alone every frequency is f0 (rho0 / rho)^1/2 sample by sample."""
    from hypothesis import event, given
    from hypothesis import strategies as st

    from tests.test_fuzz_machines import _settings, real_leg_machines
    from tests.test_fuzz_machines import machines as random_machines

    strategy = random_machines() if kind == "machine" else real_leg_machines(sprung=True)

    @_settings(4, 20)
    @given(raw=strategy, cv=st.floats(1.0, 8.0), seed=st.integers(0, 2**20))
    def check(raw, cv, seed):
        try:
            base = parse_scene(raw)
        except SceneError:
            event("machine refused up front")
            return  # refused up front: the machine tests say how
        case = base.cases.get("tilted") or next(iter(base.cases.values()))
        dimension = ("manipulator.platform_thickness_mm" if kind == "machine"
                     else "leg.rod_outer_diameter_mm")
        inputs = {"material.youngs_modulus_gpa": {"distribution": "normal", "cv_percent": cv},
                  "material.shear_modulus_gpa": {"follows": "material.youngs_modulus_gpa"},
                  dimension: {"distribution": "normal", "cv_percent": 0.2}}
        if "stiffness" in raw:
            inputs["stiffness.actuator_axial_n_per_um"] = {"distribution": "lognormal",
                                                           "cv_percent": 4 * cv}
        try:
            scene = parse_scene({**raw, "uncertainty": {"samples": 64, "seed": seed, **inputs}})
        except SceneError:
            event("an input's end refused")
            return  # an end out of range (a thin part): refused in one line, tested above
        try:
            record = propagate(scene, FAST, case.pose, 4)
        except Exception as exc:  # a sample out of reach is the one refusal allowed here
            assert "cannot reach the pose" in str(exc), exc
            event("a sample out of reach")
            return
        event("propagated")
        unit = design(len(scene.uncertainty.inputs), 64, seed)[:: 37]
        got = sample_model(scene, FAST, case.pose, unit, 4, False).frequencies_hz
        for k, m in enumerate(machines(scene, unit)):
            assert got[k] == pytest.approx(natural_frequencies(m, case.pose,
                                                                replace(FAST, modes=4)),
                                           rel=1e-9)
        for mode in record["modes"]:
            assert mode["q025_hz"] <= mode["mean_hz"] <= mode["q975_hz"]
            for key, total in mode["sobol_total"].items():
                assert -0.1 <= total <= 1.2, (key, total)
        dense = {"material.density_kg_m3": {"distribution": "lognormal", "cv_percent": cv}}
        alone = parse_scene({**raw, "uncertainty": {"samples": 64, "seed": seed, **dense}})
        unit = design(1, 64, seed)
        f = sample_model(alone, FAST, case.pose, unit, 4, False).frequencies_hz
        rho = np.array([m.material.density for m in machines(alone, unit)])
        f0 = propagate(alone, FAST, case.pose, 4)["modes"]
        if alone.manipulator.payload.mass == 0.0:
            assert f == pytest.approx(np.array([m["nominal_hz"] for m in f0])
                                      * np.sqrt(alone.manipulator.material.density
                                                / rho)[:, None], rel=1e-9)

    check()



def test_a_design_beyond_its_budget_is_refused_before_it_is_built():
    """The pilot's estimate refuses 65,536 x 3 runs against a 1 s budget in one line, having
    built only the pilot's machines."""
    from solvers.uncertainty import OverBudget

    scene = scene_with({"material.density_kg_m3": {"distribution": "lognormal",
                                                   "cv_percent": 5.0}}, samples=1 << 16)
    with pytest.raises(OverBudget) as info:
        propagate(scene, FAST, scene.cases["case1"].pose, 3, budget_seconds=1.0)
    text = str(info.value)
    assert "196,608 model runs" in text and "above the 1 s allowed" in text and "\n" not in text


def test_a_run_with_solid_ends_propagates_through_beam_ends_and_says_so():
    """A solid end zone is a solid FEM of the material: a run whose chosen model has solid
    ends propagates uncertain material through the same settings with beam ends (named in the
    record), and keeps its own model where only springs or payload are uncertain."""
    from solvers.uncertainty import refusal, run_model

    solid = replace(FAST, joint_ends="solid")
    scene = scene_with({"material.density_kg_m3": {"distribution": "normal", "cv_percent": 1.0}})
    assert refusal(scene, solid) is not None and refusal(scene, FAST) is None
    assert run_model(scene, solid) == replace(solid, joint_ends="beam", legs="beam")
    springs = scene_with({"payload.mass_kg": {"distribution": "uniform", "low": 0.0,
                                              "high": 5.0}})
    assert run_model(springs, solid) == solid
