"""Test data as a referee (modaltest/): node placement and sampling, correlation, and the
identification of scene keys, verified on synthetic campaigns with a known truth.

- a campaign made by the analytical model itself, without noise, is recovered to 1e-6;
- the eigenvalue sensitivities equal finite differences of the frequencies;
- a key the frequencies do not depend on is flagged, never given a confident number;
- the shipped campaign, made by our solid FEM with hidden springs and noise (campaigns/), gives
  its identifiable keys within 5 % and its true values inside the 95 % intervals;
- pairing follows the shapes, not the order of the test's modes;
- bad input is refused in one line before any solve.
"""
from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from common.errors import InputError
from modaltest import uff
from modaltest.campaign import Campaign, load_campaign
from modaltest.correlate import sampled
from modaltest.identify import Problem
from modaltest.models import analytical_field
from modaltest.placement import node_motion, place
from modaltest.run import run_correlation, run_identification, solved_modes
from modaltest.synthesize import PoseTested, hidden_scene, write_campaign
from scene import load_scene
from scene.load import SceneError
from tests.conftest import ROOT

ACTUATOR = ROOT / "scenes" / "actuator-legs.toml"
SHIPPED = ROOT / "campaigns" / "actuator-legs"
POINTS = (PoseTested("low", 600.0, 0.0, 0.0), PoseTested("tilted", 640.0, 30.0, 10.0),
          PoseTested("high", 700.0, 200.0, 6.0))
HIDDEN = {"stiffness.actuator_axial_n_per_um": 110.0,
          "stiffness.base_joint_rotational_nm_per_urad": 2.0}


def _campaign(tmp_path: Path, identify=tuple(HIDDEN), hidden=HIDDEN, points=POINTS) -> Path:
    """A campaign made by the analytical model at the scene's settings with the hidden
    values, written as UFF files."""
    return write_campaign(ACTUATOR, dict(hidden), points, tmp_path / "campaign", list(identify))


def exact(campaign: Campaign, hidden=HIDDEN) -> Campaign:
    """The campaign with each pose's modes as the model computes them with the hidden values
    (a UFF 55 file holds 6 significant digits: tests/test_modaltest_uff.py)."""
    truth = hidden_scene(campaign.raw_scene, campaign.scene_path, hidden)
    poses = []
    for tp in campaign.poses:
        field = analytical_field(truth.manipulator, tp.pose, tp.geometry, campaign.analytical,
                                 len(tp.modes.frequencies_hz))
        shapes = sampled(tp, field)
        poses.append(replace(tp, modes=uff.Modes(np.asarray(field.frequencies_hz), None,
                                                 tp.modes.dofs, shapes)))
    return replace(campaign, poses=tuple(poses))


@pytest.fixture(scope="module")
def model_made(tmp_path_factory):
    return exact(load_campaign(_campaign(tmp_path_factory.mktemp("model_made"))))


def test_a_campaign_made_by_the_model_is_recovered_to_1e_6(model_made):
    record, text = run_identification(model_made, model_made.analytical, "test")
    for p in record["parameters"]:
        truth = HIDDEN[p["key"]]
        assert p["value"] == pytest.approx(truth, rel=1e-6), p
        # exact data: the interval shrinks onto the value (to rounding)
        assert p["ci95"][0] * (1 - 1e-9) <= truth <= p["ci95"][1] * (1 + 1e-9), p
        assert p["identifiable"], p
    assert record["residual_rms_percent_after"] < 1e-5 < record["residual_rms_percent_before"]
    # the identified scene is the scene file with the values set, and reads back to them
    raw = tomllib.loads(text)
    for key, truth in HIDDEN.items():
        table, name = key.split(".")
        assert raw[table][name] == pytest.approx(truth, rel=1e-6)
    assert "# The drive:" in text  # the scene's comments kept


def test_eigenvalue_sensitivities_equal_finite_differences(tmp_path):
    """Springs (K only), a payload's mass and the density (M: the -lambda dM/dp term)."""
    keys = (*HIDDEN, "payload.mass_kg", "material.density_kg_m3")
    campaign = exact(load_campaign(_campaign(tmp_path, identify=keys, points=POINTS[1:])))
    problem = Problem(campaign, campaign.analytical, solved_modes(campaign))
    problem.fitted = [(k, i) for k, tp in enumerate(campaign.poses)
                      for i in range(len(tp.modes.frequencies_hz))]
    x = np.log([p.initial for p in campaign.parameters])
    jac = problem.jacobian(x)
    h = 1e-5
    for k in range(len(x)):
        step = np.zeros_like(x)
        step[k] = h
        fd = (problem.residuals(x + step) - problem.residuals(x - step)) / (2 * h)
        # the difference quotient's own error: the eigen solve's rounding (about 1e-12 in ln f)
        # over 2 h, some 1e-7; its truncation, h^2 times the third derivative, far below
        assert np.allclose(jac[:, k], fd, rtol=1e-5, atol=1e-6 * np.abs(fd).max()), (k, jac, fd)
    assert np.all(np.abs(jac).max(axis=0) > 1e-3)  # every key moves the frequencies
    assert np.all(jac[:, 3:] < 0)  # more mass, lower frequencies: every mode


def test_a_key_the_frequencies_do_not_depend_on_is_flagged(tmp_path):
    path = _campaign(tmp_path, identify=(*HIDDEN, "manipulator.r_joint_max_deg"))
    campaign = exact(load_campaign(path))
    record, _ = run_identification(campaign, campaign.analytical, "test")
    by_key = {p["key"]: p for p in record["parameters"]}
    limit = by_key["manipulator.r_joint_max_deg"]
    assert not limit["identifiable"] and "cannot determine" in limit["reason"]
    assert limit["ci95"] == limit["bounds"]  # no confident number
    for key, truth in HIDDEN.items():  # the others are still found
        assert by_key[key]["value"] == pytest.approx(truth, rel=1e-5)


def test_correlation_pairs_by_shape_not_by_order(tmp_path, model_made):
    """The model's own modes with two frequencies exchanged (modes 4 and 5, some 20 % apart)
    and the file in reverse order: each test mode pairs with the model mode of its shape."""
    tp = model_made.poses[1]
    hz = tp.modes.frequencies_hz.copy()
    hz[[3, 4]] = hz[[4, 3]]
    order = np.arange(len(hz))[::-1]
    swapped = uff.Modes(hz[order], None, tp.modes.dofs, tp.modes.shapes[:, order])
    data = tmp_path / "swapped.unv"
    uff.write_uff(data, tp.nodes, swapped)
    text = Path(model_made.path).read_text().replace(f'data = "{POINTS[1].name}.unv"',
                                                     f'data = "{data}"')
    path = Path(model_made.path).with_name("swapped.toml")
    path.write_text(text)
    campaign = load_campaign(path)
    campaign = replace(campaign, scene=hidden_scene(campaign.raw_scene, campaign.scene_path,
                                                    HIDDEN))  # the model that made the test
    pose = run_correlation(campaign, campaign.analytical, "test")["poses"][1]
    n = len(order)
    assert len(pose["pairs"]) == n and not pose["unpaired_test_modes"]
    by_test = {p["test_mode"]: p for p in pose["pairs"]}
    for k in range(n):  # test mode k + 1 has the shape of model mode order[k] + 1
        p = by_test[k + 1]
        assert p["model_mode"] == order[k] + 1 and p["mac"] > 0.999, p
    assert abs(by_test[n - 4]["error_percent"]) > 10  # the exchanged ones: by shape


def test_a_node_moves_with_the_body_it_lies_on(model_made):
    """A platform node moves rigidly (Delta + Phi x r); a leg node on the axis moves as the
    axis; a node on a leg's surface adds the section's rotation times its offset."""
    campaign = model_made
    tp = campaign.poses[1]
    g, m = tp.geometry, campaign.scene.manipulator
    field = analytical_field(m, tp.pose, g, campaign.analytical, 6)
    e = g.leg_directions[0]
    axis_point = g.base_points[0] + 0.5 * g.leg_lengths[0] * e
    normal = np.cross(e, [0.0, 0.0, 1.0])
    normal /= np.linalg.norm(normal)
    surface = axis_point + 0.5 * m.leg.housing_outer_diameter * normal
    top = g.platform_centre + g.rotation @ np.array([0.1, 0.05, 0.5 * m.platform_thickness])
    placements = place(m, g, np.array([1, 2, 3]), np.array([top, axis_point, surface]),
                       0.01, "test")
    assert [p.body for p in placements] == ["platform", "leg 1", "leg 1"]
    motion = node_motion(field, g, placements)
    plat = field.platform_motion
    rigid = plat[:3] + np.cross(plat[3:].T, top - g.platform_centre).T
    assert np.allclose(motion[0], rigid, rtol=0, atol=1e-12 * np.abs(rigid).max())
    axis = field.leg_axis_displacements([0.5])[0, 0]
    assert np.allclose(motion[1], axis, atol=1e-12 * np.abs(axis).max())
    twist = field.leg_axis_twists([0.5])[0, 0]
    # the surface point's extra motion is (twist e + slope terms) x r: its component along the
    # twist's direction of travel is twist * radius
    extra = motion[2] - motion[1]
    along = np.cross(e, normal)
    assert np.allclose(extra.T @ along, twist * 0.5 * m.leg.housing_outer_diameter,
                       rtol=1e-6, atol=1e-9 * np.abs(motion).max())


@pytest.mark.skipif(not (SHIPPED / "campaign.toml").exists(), reason="no shipped campaign")
def test_the_shipped_fem_campaign_recovers_its_hidden_springs():
    """campaigns/actuator-legs: made by our solid FEM (a code the beam model shares no element
    with) with hidden springs, 1 % noise on frequencies and 5 % on shapes at three poses."""
    truth = tomllib.loads((SHIPPED / "provenance.toml").read_text())["hidden"]
    campaign = load_campaign(SHIPPED / "campaign.toml")
    record, _ = run_identification(campaign, campaign.analytical, "test")
    flagged = 0
    for p in record["parameters"]:
        value = truth[p["key"]]
        assert p["ci95"][0] <= value <= p["ci95"][1], p
        if p["identifiable"]:
            assert abs(p["value"] / value - 1) < 0.05, p
        else:
            flagged += 1
    assert any(p["identifiable"] for p in record["parameters"])
    # the two translational springs act in series and trade off: flagged, never confident
    assert flagged >= 2 and not any(p["identifiable"] for p in record["parameters"]
                                    if "translational" in p["key"])
    assert record["residual_rms_percent_after"] < record["residual_rms_percent_before"]


def _rps(*args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "rps", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=300)


def _refused(campaign: Path, *words: str) -> None:
    """Read like every command reads a campaign, before any solve: one line naming it."""
    with pytest.raises(InputError) as exc:
        load_campaign(campaign)
    text = str(exc.value)
    assert "\n" not in text and all(w in text for w in words), text


def test_bad_campaigns_are_refused_in_one_line_before_any_solve(tmp_path, model_made):
    base = Path(model_made.path)
    text = base.read_text()

    def variant(name: str, new: str) -> Path:
        path = base.with_name(name)
        path.write_text(new)
        return path

    base.with_name("garbage.unv").write_text("this is not a universal file\n")
    _refused(variant("a.toml", text.replace('data = "low.unv"', 'data = "garbage.unv"')),
             "garbage.unv")
    _refused(variant("b.toml", text.replace("height_mm = 600.0", "height_mm = 5000.0")),
             "cannot reach")
    _refused(variant("c.toml", text.replace('"stiffness.actuator_axial_n_per_um"',
                                            '"stiffness.no_such_key"')), "no_such_key")
    _refused(variant("d.toml", text.replace('"stiffness.actuator_axial_n_per_um"',
                                            '"manipulator.platform_shape"')),
             "platform_shape", "not a number")
    _refused(variant("e.toml", text + '\n[identify.bounds]\n'
                     '"stiffness.actuator_axial_n_per_um" = [200.0, 400.0]\n'),
             "excludes the initial value 160")
    tp = model_made.poses[0]  # a node far from every body
    xyz = tp.nodes.xyz.copy()
    xyz[2] += np.array([0.0, 0.0, 0.3])
    uff.write_uff(base.with_name("far.unv"), uff.Nodes(tp.nodes.ids, xyz), tp.modes)
    far = variant("f.toml", text.replace('data = "low.unv"', 'data = "far.unv"'))
    _refused(far, f"node {int(tp.nodes.ids[2])}", "lies on no body")
    # on the command line (correlate reads a campaign through the same `prepared`): exit
    # status 2, that one line, nothing written
    out = tmp_path / "out"
    proc = _rps("identify", "--campaign", str(far), "--out", str(out))
    assert proc.returncode == 2, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and "lies on no body" in proc.stderr
    assert not out.exists()


def _rps_here(capsys, *args: str) -> str:
    """The command in this process (its exit status 0), its stdout."""
    from rps.app import main
    assert main(list(args)) == 0, capsys.readouterr().err
    return capsys.readouterr().out


def test_correlate_and_identify_write_their_records(tmp_path, model_made, capsys):
    out = tmp_path / "corr"
    _rps_here(capsys, "correlate", "--campaign", model_made.path, "--out", str(out))
    data = json.loads((out / "correlation.json").read_text())
    for pose in data["poses"]:
        assert {"name", "pairs"} <= set(pose)
        for p in pose["pairs"]:
            # the scene's springs against the hidden ones: errors of some percent, one shape
            assert p["error_percent"] == pytest.approx(
                100 * (p["model_hz"] / p["test_hz"] - 1), abs=1e-9)
            assert p["mac"] >= 0.6 and abs(p["error_percent"]) < 30
        assert not pose["unpaired_test_modes"]
    assert (out / "tables" / "correlation-pairs.csv").exists()
    assert (out / "correlation.html").exists()
    assert not math.isnan(data["summary"]["max_abs_error_percent"])
    out = tmp_path / "ident"
    _rps_here(capsys, "identify", "--campaign", model_made.path, "--out", str(out))
    data = json.loads((out / "identification.json").read_text())
    for p in data["parameters"]:  # from the files' 6 significant digits
        assert p["value"] == pytest.approx(HIDDEN[p["key"]], rel=1e-3) and p["identifiable"]
        assert p["ci95"][0] <= HIDDEN[p["key"]] <= p["ci95"][1]
    assert data["residual_rms_percent_after"] < 1e-3 < data["residual_rms_percent_before"]
    identified = load_scene(out / "identified.toml")
    assert identified.manipulator.stiffness.actuator_axial == pytest.approx(110e6, rel=1e-3)
    assert (out / "identification.html").exists()
    # V&V 20 of the scene's model against the test: every fitted mode, E its error before the
    # fit, u_D the identification's noise, u_val their root sum of squares
    fitted = [(f["pose"], m["test_mode"]) for f in data["fit"] for m in f["modes"]]
    rows = data["validation"]
    assert sorted((r["pose"], r["test_mode"]) for r in rows) == sorted(fitted)
    before = {(f["pose"], m["test_mode"]): m["error_before_percent"]
              for f in data["fit"] for m in f["modes"]}
    for r in rows:
        assert r["e_percent"] == before[(r["pose"], r["test_mode"])]
        assert r["u_d_percent"] == data["noise"]["frequency_percent"]
        parts = [u for u in (r["u_num_percent"], r["u_input_percent"], r["u_d_percent"]) if u]
        assert r["u_val_percent"] == pytest.approx(math.sqrt(sum(u * u for u in parts)))
        assert r["u_input_percent"] > 0.0  # the scene's [uncertainty], at the pose


def test_scene_addresses_are_refused_in_one_line():
    from scene.address import resolve
    for bad, words in (("stiffness", "table.key"), ("nowhere.key", "table one of"),
                       ("payload.centre_mm", "not a number of [payload]")):
        with pytest.raises(SceneError, match=None) as exc:
            resolve(bad)
        assert words in str(exc.value) and "\n" not in str(exc.value)


def test_a_campaign_of_frfs_gives_its_modes_through_sdypy_ema(tmp_path, monkeypatch):
    """Receptances (UFF 58) made by the model with 2 % modal damping: the modes identified
    from them (LSCF and LSFD) pair with the model's own within 0.1 % and MAC 0.99, and their
    damping within 5 %; `[ema] lower_hz` or `upper_hz` alone bands the same modes."""
    path = write_campaign(ACTUATOR, {}, POINTS[1:2], tmp_path / "frf", [], frf_damping=0.02)
    campaign = load_campaign(path)
    tp = campaign.poses[0]
    assert "sdypy-EMA" in tp.source
    assert np.allclose(tp.modes.damping_ratios, 0.02, rtol=0.05)
    pose = run_correlation(campaign, campaign.analytical, "test")["poses"][0]
    assert len(pose["pairs"]) == len(tp.modes.frequencies_hz) == 6
    for p in pose["pairs"]:
        assert abs(p["error_percent"]) < 0.1 and p["mac"] > 0.99, p
    # a band limit alone: the other end is the axis's; a band above the first modes finds the
    # modes in it as the full band does (residual terms for those below)
    full = tp.modes.frequencies_hz
    text = path.read_text()
    for table, inside in ((f"lower_hz = {float(0.5 * (full[1] + full[2]))!r}", full[2:]),
                          (f"upper_hz = {float(0.5 * (full[3] + full[4]))!r}", full[:4])):
        path.write_text(text + f"\n[ema]\n{table}\n")
        band = load_campaign(path).poses[0].modes.frequencies_hz
        assert np.allclose(band, inside, rtol=2e-4), (table, band, inside)
    path.write_text(text)
    # an identification too big to finish in reasonable time is refused before it starts
    import modaltest.campaign
    monkeypatch.setattr(modaltest.campaign, "MAX_EMA_POINTS", 1000)
    _refused(path, "FRFs x", "at most 1,000")


def test_the_way_back_writes_the_prediction_and_suggests_sensors(tmp_path, capsys):
    """`rps modes`: the model's modes at candidate points as UFF (2411 + 55), read back to the
    file's 6 digits, and effective independence keeping the dofs that tell the modes apart."""
    out = tmp_path / "prediction.unv"
    payload = json.loads(_rps_here(capsys, "modes", "--scene", str(ACTUATOR), "--case",
                                   "tilted", "--out", str(out), "--suggest", "12", "--json"))
    content = uff.read_uff(out)
    assert content.modes is not None
    assert np.allclose(content.modes.frequencies_hz, payload["frequencies_hz"], rtol=1e-5)
    scene = load_scene(ACTUATOR)
    from analytical.model import natural_frequencies
    direct = natural_frequencies(scene.manipulator, scene.case("tilted").pose, scene.analytical)
    assert np.allclose(payload["frequencies_hz"], direct[:len(payload["frequencies_hz"])],
                       rtol=1e-12)
    rows = (tmp_path / "prediction.sensors.csv").read_text().splitlines()
    assert len(rows) == 13 and rows[0] == "node,x_mm,y_mm,z_mm,direction"


def test_effective_independence_keeps_the_dofs_that_tell_modes_apart():
    from modaltest.pretest import effective_independence
    shapes = np.array([[1.0, 0.0], [0.0, 1.0], [1e-3, 1e-3], [0.7, 0.7], [1e-4, 0.0]])
    assert list(effective_independence(shapes, 2)) == [0, 1]
    rng = np.random.default_rng(3)
    tall = rng.standard_normal((40, 4))
    keep = effective_independence(tall, 6)
    assert len(keep) == 6 and np.linalg.matrix_rank(tall[keep]) == 4
    with pytest.raises(InputError):
        effective_independence(tall, 3)


def test_a_rigid_spring_is_identified_from_its_bounds(tmp_path):
    """The paper's machine has rigid joints and drive (0 in the scene); a drive spring
    identified from bounds (the fit starts at their geometric middle) is recovered."""
    paper = ROOT / "scenes" / "paper.toml"
    hidden = {"stiffness.actuator_axial_n_per_um": 400.0}
    points = (PoseTested("a", 543.6, 0.0, 0.0), PoseTested("b", 600.0, 30.0, 10.0))
    path = write_campaign(paper, hidden, points, tmp_path / "paper", list(hidden),
                          extra='\n[identify.bounds]\n"stiffness.actuator_axial_n_per_um" = '
                          "[40.0, 40000.0]\n")
    campaign = exact(load_campaign(path), hidden)
    record, text = run_identification(campaign, campaign.analytical, "test")
    p = record["parameters"][0]
    assert p["initial"] == 0.0 and p["value"] == pytest.approx(400.0, rel=1e-6), p
    assert tomllib.loads(text)["stiffness"]["actuator_axial_n_per_um"] == pytest.approx(400.0)


def _scene_text(raw: dict) -> str:
    """A drawn machine's raw scene as TOML (numbers, names, lists; its cases last)."""
    def value(v):
        if isinstance(v, str):
            return f'"{v}"'
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(value(x) for x in v) + "]"
        return repr(v) if isinstance(v, int) else repr(float(v))
    lines = [f'name = "{raw["name"]}"']
    for table, entries in raw.items():
        if isinstance(entries, dict) and table != "cases":
            lines += ["", f"[{table}]"] + [f"{k} = {value(v)}" for k, v in entries.items()]
    for name, case in raw["cases"].items():
        lines += ["", f"[cases.{name}]"] + [f"{k} = {value(v)}" for k, v in case.items()]
    return "\n".join(lines) + "\n"


# A confident wrong answer (issue 53's "Intervals"), mended: this sprung real-leg machine, reached
# by the random test below in some runs, was identified with every key "identifiable" and its
# 95 % intervals 0.1 % wide but 11-20 % off the hidden values: the fit had stopped in a wrong
# minimum (its partners exchanged at a repeated pair) whose residuals, 0.47 % rms, the stated
# noise of 1e-3 % could not explain, and the intervals used that noise all the same.
MISIDENTIFIED = {
    "name": "fuzzed machine with real legs",
    "manipulator": {"base_radius_mm": 420.0754030425771,
                    "platform_radius_mm": 232.59948074650475,
                    "platform_thickness_mm": 81.81541792505337,
                    "actuator_min_mm": 770.6798985818444, "actuator_max_mm": 1092.1960479107004,
                    "s_joint_max_deg": 30.0, "r_joint_max_deg": 30.0, "base_joint": "S",
                    "platform_joint": "R"},
    "material": {"youngs_modulus_gpa": 113.8, "shear_modulus_gpa": 42.4,
                 "density_kg_m3": 4430.0},
    "leg": {"housing_length_mm": 309.6606139646626,
            "housing_outer_diameter_mm": 163.63083585010673,
            "housing_inner_diameter_mm": 124.12325961937783,
            "rod_outer_diameter_mm": 116.42974665578404,
            "rod_inner_diameter_mm": 34.928923996735215},
    "fidelity": {"modes": 6, "tolerance_percent": 1.0},
    "stiffness": {"actuator_axial_n_per_um": 345.0, "base_joint_translational_n_per_um": 1731.0,
                  "platform_joint_translational_n_per_um": 737.0},
    "cases": {"level": {"height_mm": 880.9647584620039},
              "tilted": {"height_mm": 880.9647584620039, "azimuth_deg": 0.0, "tilt_deg": 1.0}}}


def _identified_within_intervals(raw: dict, folder: Path) -> dict:
    """A campaign made by the model with hidden springs (30 % softer) or modulus (7 % lower)
    at the machine's cases, identified: every hidden value inside its 95 % interval and every
    key called identifiable within identifiable_within_percent of it."""
    scene = folder / "scene.toml"
    scene.write_text(_scene_text(raw))
    hidden = ({f"stiffness.{k}": 0.7 * v for k, v in raw["stiffness"].items()}
              if "stiffness" in raw else
              {"material.youngs_modulus_gpa": 0.93 * raw["material"]["youngs_modulus_gpa"]})
    points = [PoseTested(n, c["height_mm"], c.get("azimuth_deg", 0.0),
                         c.get("tilt_deg", 0.0)) for n, c in raw["cases"].items()]
    campaign = load_campaign(write_campaign(scene, hidden, points, folder / "c", list(hidden),
                                            extra="frequency_noise_percent = 1e-3\n"))
    assert campaign.identify.frequency_noise_percent == 1e-3
    record, _ = run_identification(campaign, campaign.analytical, "fuzz")
    within = campaign.identify.identifiable_within_percent / 100
    for p in record["parameters"]:
        truth = hidden[p["key"]]
        assert p["ci95"][0] <= truth <= p["ci95"][1], p
        assert not p["identifiable"] or abs(p["value"] / truth - 1) <= within, p
    return record


def test_a_machine_once_misidentified_with_confidence_is_identified(tmp_path):
    """The profile of its correlated keys (the others re-fitted along it) finds a lower sum of
    squares than the fit's: the fit restarts from there and finds the hidden springs, every
    one inside its interval, the residuals within the stated noise."""
    record = _identified_within_intervals(MISIDENTIFIED, tmp_path)
    assert "restarted" in record["optimiser"], record["optimiser"]
    assert record["noise"]["source"] == "stated"
    assert record["residual_rms_percent_after"] < 3 * record["noise"]["frequency_percent"]


@pytest.mark.fuzz
def test_identification_on_random_machines(tmp_path_factory):
    """Machines drawn from the fuzz's plausible ranges (3-RPS and 3-PRS, both joint orders,
    three metals; real legs with bearings and a ball screw): a campaign made by the model with
    hidden values (springs 30 % softer, or the modulus 7 % lower) at the machine's two cases,
    written as UFF files, is identified with every hidden value inside its 95 % interval and
    every key called identifiable within identifiable_within_percent of it.

    The data's only noise is the UFF 55 file's 6 significant digits, a relative error of at
    most 5e-6 in each frequency; the campaign states a noise of 1e-3 % (sigma = 1e-5 in ln f),
    twice that bound. Then the truth lies inside the interval on every draw, not 95 % of them:
    an error vector e with |e_i| <= sigma / 2 moves key k by at most (sigma / 2) ||row_k(J+)||_1
    <= (sigma / 2) sqrt(m) ||row_k(J+)||_2 = 1.73 sd_k for m = 12 paired frequencies, inside
    1.96 sd_k. (A residual-based interval is a 95 % statement and misses the truth on about
    one key in twenty: asserting it on every key of every draw is a test that must fail.)"""
    from hypothesis import HealthCheck, given, settings

    from tests.test_fuzz_machines import checked, machines, real_leg_machines

    def identified(raw: dict) -> None:
        if checked(raw) is None:  # refused up front (tests/test_fuzz_machines.py)
            return
        _identified_within_intervals(raw, tmp_path_factory.mktemp("machine"))

    once = settings(max_examples=6, deadline=None, derandomize=True, database=None,
                    suppress_health_check=list(HealthCheck))
    once(given(machines())(identified))()
    once(given(real_leg_machines(True))(identified))()


# Two springs in series (issue 53): the drive and the base joint's bearings act in series along
# each leg, so the frequencies see mostly their combination and the two keys trade off
# (correlated about -1); the campaign is made by the analytical model with 0.1 % noise on the
# frequencies and 5 % on the shapes at three poses, fresh noise every draw, sigma estimated
# from the residuals.
SERIES = {"stiffness.actuator_axial_n_per_um": 120.0,
          "stiffness.base_joint_translational_n_per_um": 500.0}


def _series_coverage(folder: Path, draws: int) -> tuple[int, int, float]:
    """Over `draws` noise draws (seeds 0, 1, ...): how many keys were flagged identifiable,
    how many of those intervals covered the truth, and the largest |z| of a flagged key, z
    the truth's distance from the value in the standard errors of its 95 % interval (its half
    on the truth's side over 1.96, in ln)."""
    flagged, covered, worst = 0, 0, 0.0
    for seed in range(draws):
        path = write_campaign(ACTUATOR, SERIES, POINTS, folder / f"draw{seed}", list(SERIES),
                              frequency_noise=0.001, shape_noise=0.05, seed=seed)
        campaign = load_campaign(path)
        assert campaign.identify.frequency_noise_percent == 0.0  # estimated
        record, _ = run_identification(campaign, campaign.analytical, "coverage")
        for p in record["parameters"]:
            if not p["identifiable"]:
                continue
            truth, value, (low, high) = SERIES[p["key"]], p["value"], p["ci95"]
            flagged += 1
            covered += low <= truth <= high
            half = math.log(high / value) if truth > value else math.log(value / low)
            worst = max(worst, abs(1.96 * math.log(truth / value) / half))
    return flagged, covered, worst


@pytest.mark.fuzz
def test_series_springs_flagged_identifiable_cover_the_truth_over_40_draws(tmp_path):
    """Every key flagged identifiable covers the truth in at least 9 of 10 of its draws (95 %
    asked), and no flagged key lies beyond 3 standard errors of the truth in any draw: a
    confident wrong answer is the one kind an identification must not give."""
    flagged, covered, worst = _series_coverage(tmp_path, 40)
    assert flagged >= 40  # a key is flagged in most draws: the test tests something
    assert covered >= 0.9 * flagged and worst <= 3.0, (flagged, covered, worst)


def test_series_springs_flagged_identifiable_cover_the_truth(tmp_path):
    """The first 4 draws of the test above (40 draws, `make fuzz`; the fourth draws the
    noise estimate lowest of the 40, and its base spring was flagged identifiable 14 % off the
    truth, z = 3.3, before identifiability was decided at the noise's upper bound): at most
    one flagged key's interval misses the truth, none by more than 3 standard errors."""
    flagged, covered, worst = _series_coverage(tmp_path, 4)
    assert flagged >= 4
    assert covered >= flagged - 1 and worst <= 3.0, (flagged, covered, worst)
