"""The dynamic compliance at the tool (common/frf.py, analytical/tool_response.py,
solvers/tool_frf.py): closed forms of one and two modes, the static limit against a static
solve, the modal sum against the damped system solved directly, the batched map against the
one pose, and the peaks of a direct response found as the modal sum's."""
from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from analytical.batch_model import assemble_batch
from analytical.batch_solve import standard_form
from analytical.kinematics import pose_geometry
from analytical.pose_batch import pose_batch
from analytical.substructure import assemble, model_coordinates
from analytical.tool_response import batch_tool_modes, tool_modes
from common.errors import InputError
from common.frf import (
    Damping,
    Tool,
    band_lines,
    least_dynamic_stiffness,
    modal_table,
    rayleigh_through,
    receptance,
    residual_flexibility,
    tool_rows,
)
from common.frf_peaks import (
    direct_peaks,
    find_peaks,
)
from scene import load_scene
from scene.load import SceneError, parse_scene, read_toml
from solvers.tool_frf import analytical_tool, with_damping

ROOT = Path(__file__).resolve().parents[1]
ACTUATOR = ROOT / "scenes" / "actuator-legs.toml"


def test_one_mode_is_the_single_degree_of_freedom_closed_form():
    """m x'' + c x' + k x = F along x: H = 1 / (k - m w^2 + i c w), peak 1 / (2 zeta k)
    / sqrt(1 - zeta^2) at w_n sqrt(1 - 2 zeta^2); the mode's modal stiffness k and mass m."""
    k, m, zeta = 7.9e6, 3.2, 0.05
    wn = math.sqrt(k / m)
    phi = np.array([[1 / math.sqrt(m)], [0.0], [0.0]])
    static = np.diag([1 / k, 0.0, 0.0])
    f = np.linspace(0.0, 2.0 * wn / (2 * math.pi), 401)
    w = 2 * math.pi * f
    h = receptance(f, [wn], [zeta], phi, residual_flexibility(static, [wn], phi))
    closed = 1.0 / (k - m * w**2 + 2j * zeta * math.sqrt(k * m) * w)
    assert np.allclose(h[:, 0, 0], closed, rtol=1e-12, atol=0)
    row = modal_table([wn], [zeta], phi)[0]
    assert row["modal_stiffness_n_per_m"]["x"] == pytest.approx(k, rel=1e-12)
    assert row["effective_mass_kg"]["x"] == pytest.approx(m, rel=1e-12)
    assert row["modal_stiffness_n_per_m"]["y"] is None  # the mode does not move y
    least = least_dynamic_stiffness(band_lines(f[-1], 2000)[None], [[wn]], [[zeta]], phi[None],
                                    np.zeros((1, 3)))
    peak = 1.0 / (2 * zeta * k * math.sqrt(1 - zeta**2))
    assert 1.0 / least.stiffness_n_per_m[0, 0] == pytest.approx(peak, rel=1e-6)
    assert least.peak_hz[0, 0] == pytest.approx(wn * math.sqrt(1 - 2 * zeta**2) / (2 * math.pi),
                                                rel=2e-4)


def test_two_modes_are_the_damped_system_solved_directly():
    """A two-degree-of-freedom system with Rayleigh damping: the sum of its two modes is
    (K - w^2 M + i w C)^-1 exactly; one mode and the residual flexibility of the other give
    the static compliance exactly at 0 Hz and approach the exact response below the first
    mode."""
    m = np.diag([2.0, 1.0])
    k = np.array([[3e6, -1e6], [-1e6, 1e6]])
    damping = Damping(rayleigh_alpha=4.0, rayleigh_beta=2e-5)
    lam, x = np.linalg.eigh(np.linalg.solve(np.linalg.cholesky(m), k)
                            @ np.linalg.inv(np.linalg.cholesky(m)).T)
    x = np.linalg.inv(np.linalg.cholesky(m)).T @ x  # M-normalised
    omega = np.sqrt(lam)
    zeta = damping.ratios(omega)
    phi = np.vstack([x, np.zeros((1, 2))])  # the "tool" reads the two coordinates as x, y
    static = np.zeros((3, 3))
    static[:2, :2] = np.linalg.inv(k)
    f = np.linspace(0.0, 1.5 * omega[-1] / (2 * math.pi), 301)
    c = damping.rayleigh_alpha * m + damping.rayleigh_beta * k
    exact = np.array([np.linalg.inv(k - (2 * math.pi * fi) ** 2 * m + 2j * math.pi * fi * c)
                      for fi in f])
    both = receptance(f, omega, zeta, phi, residual_flexibility(static, omega, phi))
    assert np.abs(residual_flexibility(static, omega, phi)).max() < 1e-12 * np.abs(static).max()
    assert np.allclose(both[:, :2, :2], exact, rtol=1e-10, atol=1e-12 * np.abs(exact).max())
    one = receptance(f, omega[:1], zeta[:1], phi[:, :1],
                     residual_flexibility(static, omega[:1], phi[:, :1]))
    assert np.allclose(one[0, :2, :2], static[:2, :2], rtol=1e-12, atol=0)
    low = f < 0.3 * omega[0] / (2 * math.pi)
    gap = np.abs(one[low, :2, :2] - exact[low]).max() / np.abs(exact[low]).max()
    assert gap < 0.01
    alpha, beta = rayleigh_through(omega[0], omega[1], 0.03)
    assert Damping(rayleigh_alpha=alpha, rayleigh_beta=beta).ratios(omega) == pytest.approx(
        [0.03, 0.03], rel=1e-12)


def test_the_tool_point_moves_with_the_rigid_platform():
    """u_t = Delta + Phi x (R p): a small rotation turns the arm as the cross product does."""
    rng = np.random.default_rng(4)
    rotation = np.linalg.qr(rng.standard_normal((3, 3)))[0]
    point = rng.standard_normal(3)
    q = rng.standard_normal(6)
    assert np.allclose(tool_rows(point, rotation) @ q, q[:3] + np.cross(q[3:], rotation @ point))


@pytest.fixture(scope="module")
def actuator():
    scene = load_scene(ACTUATOR)
    geometry = pose_geometry(scene.manipulator, scene.case("tilted").pose)
    options = replace(scene.analytical, beam="timoshenko", shear="hutchinson", elements=4)
    return scene, geometry, options


def test_the_static_limit_is_a_static_solve(actuator):
    """At 0 Hz the receptance is the static compliance: the tool's displacement under a unit
    force, K q = A^T F solved directly; with every mode summed the residual flexibility
    vanishes (sum phi phi^T / omega^2 = A K^-1 A^T)."""
    scene, geometry, options = actuator
    model = assemble(scene.manipulator, geometry, options)
    tool = analytical_tool(scene.manipulator, geometry, options, scene.damping, scene.tool.point,
                           scene.fidelity.modes)
    a = np.zeros((3, model.stiffness.shape[0]))
    a[:, model.platform_slice] = tool_rows(scene.tool.point, geometry.rotation)
    for d in range(3):
        q = np.linalg.solve(model.stiffness, a[d])
        assert np.allclose(tool.receptance([0.0])[0, :, d].real, a @ q, rtol=1e-9,
                           atol=1e-9 * abs(a[d] @ q))
    assert np.abs(tool.receptance([0.0])[0].imag).max() == 0.0
    every = tool_modes(model, geometry.rotation, scene.tool.point, model.stiffness.shape[0])
    rest = residual_flexibility(every.static, every.omega, every.phi)
    assert np.abs(rest).max() < 1e-9 * np.abs(every.static).max()


def test_the_modal_sum_is_the_damped_model_solved_directly(actuator):
    """Rayleigh damping keeps the modes real: the sum of the compared modes and the residual
    flexibility of the rest matches (K - w^2 M + i w (alpha M + beta K))^-1 across the band,
    exactly at 0 Hz and to the neglected modes' dynamic part (a fraction of a percent) at the
    band's top, its peaks to 1e-3; the direct solve's peaks found by five solves and a
    rational fit per peak (`direct_peaks`) are those a bounded search of many solves finds, to
    1e-4 in frequency and 1e-5 in height."""
    scene, geometry, options = actuator
    model = assemble(scene.manipulator, geometry, options)
    damping = Damping(rayleigh_alpha=9.8, rayleigh_beta=2.7e-5)
    tool = with_damping(analytical_tool(scene.manipulator, geometry, options, damping,
                                        scene.tool.point, scene.fidelity.modes), damping)
    a = np.zeros((3, model.stiffness.shape[0]))
    a[:, model.platform_slice] = tool_rows(scene.tool.point, geometry.rotation)
    k, m = model.stiffness, model.mass
    c = damping.rayleigh_alpha * m + damping.rayleigh_beta * k

    def direct(f):
        w = 2 * math.pi * f
        return a @ np.linalg.solve(k - w * w * m + 1j * w * c, a.T)

    lines = tool.lines(60)
    exact = np.array([direct(f) for f in lines])
    modal = tool.receptance(lines)
    scale = np.abs(exact[:, range(3), range(3)]).max(axis=0)
    gap = np.abs(modal - exact)[:, range(3), range(3)] / scale
    assert gap.max() < 2e-3, gap.max()
    windows = {d: tool.windows(d, 0.25) for d in range(3)}
    found = direct_peaks(direct, windows, tool.modes.omega, tool.zeta)
    for d in range(3):
        brent = find_peaks(lambda f: abs(direct(f)[d, d]), windows[d])  # many solves a peak
        assert len(found[d]) == len(brent) >= 1
        for peak, ref, modal in zip(found[d], brent, tool.peaks(d, 0.25)):
            assert peak.frequency_hz == pytest.approx(ref.frequency_hz, rel=1e-4)
            assert peak.magnitude_m_per_n == pytest.approx(ref.magnitude_m_per_n, rel=1e-5)
            assert modal.frequency_hz == pytest.approx(ref.frequency_hz, rel=1e-4)
            assert modal.magnitude_m_per_n == pytest.approx(ref.magnitude_m_per_n, rel=1e-3)


def test_the_batched_map_is_the_one_pose(actuator):
    """The workspace map's batched modes, static compliance and least dynamic stiffness are the
    single pose's (the batch's Cholesky factor serves the static solve)."""
    scene, geometry, options = actuator
    cases = [scene.case(n).pose for n in ("level", "tilted")]
    batch = pose_batch(scene.manipulator, [p.height for p in cases],
                       [p.azimuth for p in cases], [p.tilt for p in cases])
    model = assemble_batch(scene.manipulator, batch, options)
    count = min(12, model_coordinates(scene.manipulator, options))
    modes = batch_tool_modes(model, standard_form(model), batch.rotation, scene.tool.point,
                             count)
    for i, pose in enumerate(cases):
        g = pose_geometry(scene.manipulator, pose)
        one = tool_modes(assemble(scene.manipulator, g, options), g.rotation, scene.tool.point,
                         count)
        assert np.allclose(modes.omega[i], one.omega, rtol=1e-10)
        lines = np.linspace(0.0, 1.2 * one.omega[5] / (2 * math.pi), 50)  # a repeated pair's
        zeta = scene.damping.ratios(one.omega)  # vectors are any basis of it: compare H
        h_batch = receptance(lines, modes.omega[i], zeta, modes.phi[i], np.zeros((3, 3)))
        h_one = receptance(lines, one.omega, zeta, one.phi, np.zeros((3, 3)))
        assert np.allclose(h_batch, h_one, rtol=1e-7, atol=1e-9 * np.abs(h_one).max())
        assert np.allclose(modes.static[i], one.static, rtol=1e-9,
                           atol=1e-12 * np.abs(one.static).max())
    zeta = scene.damping.ratios(modes.omega)
    residual = residual_flexibility(modes.static, modes.omega, modes.phi)
    lines = band_lines(1.25 * modes.omega[:, 5] / (2 * math.pi), 400)
    least = least_dynamic_stiffness(lines, modes.omega, zeta, modes.phi,
                                    np.diagonal(residual, axis1=1, axis2=2))
    for i in range(2):  # against a dense evaluation 40 times finer
        fine = band_lines(lines[i, -1], 16000)
        h = receptance(fine, modes.omega[i], zeta[i], modes.phi[i], residual[i])
        top = np.abs(h[:, range(3), range(3)]).max(axis=0)
        assert np.allclose(1.0 / least.stiffness_n_per_m[i], top, rtol=1e-6)


def test_damping_and_tool_keys_are_read_and_refused_in_one_line(tmp_path):
    raw = read_toml(ACTUATOR)
    scene = parse_scene(raw)
    assert scene.damping.modal_ratio == (0.03,) and scene.dynamics_given
    assert scene.tool.point == pytest.approx((0.0, 0.0, -0.15))
    listed = parse_scene({**raw, "damping": {"modal_ratio": [0.02, 0.04]}})
    assert listed.damping.ratios(np.ones(4)).tolist() == [0.02, 0.04, 0.04, 0.04]
    plain = {k: v for k, v in raw.items() if k not in ("damping", "tool")}
    assert not parse_scene(plain).dynamics_given
    for bad, words in (({"damping": {"modal_ratio": 0.0}}, "modal_ratio"),
                       ({"damping": {"modal_ratio": 0.02, "rayleigh_beta_s": 1e-5}}, "not both"),
                       ({"damping": {"modal_ratio": "2 %"}}, "modal_ratio"),
                       ({"tool": {"point_mm": [0.0, 0.0]}}, "point_mm"),
                       ({"tool": {"point": [0.0, 0.0, 1.0]}}, "point")):
        with pytest.raises(SceneError, match=words) as err:
            parse_scene({**raw, **bad})
        assert "\n" not in str(err.value)
    with pytest.raises(InputError):
        Damping(rayleigh_alpha=-1.0)
    assert Tool().point == (0.0, 0.0, 0.0)


def test_rps_frf_writes_the_record_and_the_universal_file(tmp_path, capsys):
    """`rps frf`: frf.json with the issue's keys (base-frame directions, the 0 Hz line the
    static compliance), the modes' modal stiffness, and the nine receptances as UFF 58 read
    back by pyuff; bad options refused in one line, exit 2, nothing written."""
    import json

    from modaltest import uff
    from rps.app import main

    out = tmp_path / "frf"
    assert main(["frf", "--scene", str(ACTUATOR), "--case", "tilted", "--out", str(out),
                 "--lines", "500"]) == 0
    capsys.readouterr()
    data = json.loads((out / "frf.json").read_text())
    assert len(data["frequency_hz"]) == 500 and data["frequency_hz"][0] == 0.0
    assert data["point_mm"] == [0.0, 0.0, -150.0]
    for pair in ("xx", "yy", "zz"):
        h = data["receptance_m_per_n"][pair]
        assert len(h["re"]) == len(h["im"]) == 500
    static = np.array(data["static_compliance_m_per_n"])
    assert data["receptance_m_per_n"]["xx"]["re"][0] == pytest.approx(static[0, 0], rel=1e-12)
    for mode in data["modes"]:
        assert {"frequency_hz", "damping_ratio", "modal_stiffness_n_per_m"} <= set(mode)
        assert mode["damping_ratio"] == 0.03
    # what an independent code does with the record: its modes and residual summed again
    w = 2 * np.pi * np.asarray(data["frequency_hz"])
    rebuilt = np.array(data["residual_flexibility_m_per_n"], complex)[None] + sum(
        np.einsum("d,e->de", *[np.array([m["tool_shape_per_sqrt_kg"][c] for c in "xyz"])] * 2)[None]
        / ((2 * np.pi * m["frequency_hz"]) ** 2 - w[:, None, None] ** 2
           + 2j * m["damping_ratio"] * 2 * np.pi * m["frequency_hz"] * w[:, None, None])
        for m in data["modes"])
    for pair, (i, j) in {"xx": (0, 0), "xy": (0, 1), "yz": (1, 2), "zz": (2, 2)}.items():
        h = np.array(data["receptance_m_per_n"][pair]["re"]) + 1j * np.array(
            data["receptance_m_per_n"][pair]["im"])
        assert np.allclose(rebuilt[:, i, j], h, rtol=1e-9, atol=1e-12 * np.abs(h).max())
    for m in data["modes"]:
        k, shape = m["modal_stiffness_n_per_m"]["x"], m["tool_shape_per_sqrt_kg"]["x"]
        assert k is None or k == pytest.approx((2 * np.pi * m["frequency_hz"]) ** 2 / shape**2)
    content = uff.read_uff(out / "frf.unv")
    assert content.frfs is not None and content.frfs.values.shape == (9, 499)
    xx = np.array(data["receptance_m_per_n"]["xx"]["re"][1:]) + 1j * np.array(
        data["receptance_m_per_n"]["xx"]["im"][1:])
    assert np.allclose(content.frfs.values[0], xx, rtol=1e-12)
    for bad, words in ((["--lines", "2"], "--lines 2"), (["--top-hz", "-5"], "--top-hz")):
        gone = tmp_path / "never"
        code = main(["frf", "--scene", str(ACTUATOR), "--out", str(gone), *bad])
        err = capsys.readouterr().err.strip()
        assert code == 2 and words in err and "\n" not in err and not gone.exists(), err


@pytest.mark.slow
def test_both_models_meet_the_solids_direct_response(tmp_path):
    """The solid's direct frequency response (the damped system solved at each frequency, no
    modal truncation) at a tool point off the platform centre of the paper's machine, case 2
    (tilted), at the scene's mesh, 2 % damping: the FEM's own modal sum meets it within 1e-4
    in peak frequency and 0.2 % in peak height (measured: 1e-4 % on a resonant peak, 0.08 % on
    a weak one riding on the static flexibility of the modes left out, whose dynamic part the
    residual term omits); the analytical model (its best setting, solid joint ends) puts its
    peaks where its modes are (a peak's frequency error is its mode's, within 0.02 %-points),
    their heights within 5 % (measured 0.01-0.07 %) and the static compliance within 1 %
    (measured 0.015 %); every FEM figure carries its two-mesh error."""
    from runtime.cache import ResultCache
    from studies.tool_response import tool_response

    scene = load_scene(ROOT / "scenes" / "paper.toml")
    scene = replace(scene, tool=Tool((0.03, -0.02, 0.12)), damping=Damping((0.02,)),
                    analytical=replace(scene.analytical, beam="timoshenko",
                                       shear="hutchinson", elements=5, joint_ends="solid"))
    geometry = pose_geometry(scene.manipulator, scene.case("case2").pose)
    record = tool_response(scene, geometry, None, ResultCache(tmp_path / "cache"))
    assert not record["unmatched"], record["unmatched"]
    assert {p["direction"] for p in record["peaks"]} == {"x", "y", "z"}
    from fem_reference import solve_pose
    from solvers.compare import fem_options
    from solvers.tool_frf import analytical_tool
    fem_hz = solve_pose(scene.manipulator, geometry,
                        fem_options(scene, scene.fem.mesh_size, modes=6)).frequencies_hz
    model_hz = analytical_tool(scene.manipulator, geometry, scene.analytical, scene.damping,
                               scene.tool.point, 6).modes.frequencies_hz
    for p in record["peaks"]:
        assert abs(p["fem_modal_magnitude_error_percent"]) < 0.2, p
        assert p["fem_modal_hz"] == pytest.approx(p["fem_direct_hz"], rel=1e-4), p
        j = p["fem_mode"] - 1
        mode_error = 100 * (model_hz[j] / fem_hz[j] - 1)
        assert abs(p["frequency_error_percent"] - mode_error) < 0.02, (p, mode_error)
        assert abs(p["magnitude_error_percent"]) < 5.0, p
        assert math.isfinite(p["fem_magnitude_error_percent"])
    for row in record["static"]:
        assert abs(row["error_percent"]) < 1.0 and math.isfinite(row["fem_error_percent"])


@pytest.mark.fuzz
def test_the_tool_receptance_on_random_machines():
    """Machines drawn from the fuzz's plausible ranges (3-RPS and 3-PRS, both joint orders,
    three metals; real legs with springs), a random tool point and damping, at both cases:
    the static limit is the static solve; with Rayleigh damping the modal sum of every mode is
    the damped model solved directly; the summed modes with the residual flexibility miss it
    by exactly the dynamic part of the modes left out, every one of which resonates above the
    band; the batched map's least dynamic stiffness is the one pose's."""
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    from tests.test_fuzz_machines import checked, machines, real_leg_machines

    def check(raw: dict, point, zeta) -> None:
        found = checked(raw)
        if found is None:
            return
        scene = found[0]
        damping = Damping((zeta,))
        for case in scene.cases.values():
            g = pose_geometry(scene.manipulator, case.pose)
            model = assemble(scene.manipulator, g, scene.analytical)
            n = model.stiffness.shape[0]
            a = np.zeros((3, n))
            a[:, model.platform_slice] = tool_rows(point, g.rotation)
            tool = analytical_tool(scene.manipulator, g, scene.analytical, damping, point,
                                   scene.fidelity.modes)
            static = a @ np.linalg.solve(model.stiffness, a.T)
            assert np.allclose(tool.receptance([0.0])[0].real, static, rtol=1e-8,
                               atol=1e-9 * np.abs(static).max())
            every = tool_modes(model, g.rotation, point, n)
            alpha, beta = rayleigh_through(every.omega[0], every.omega[5], zeta)
            ray = Damping(rayleigh_alpha=alpha, rayleigh_beta=beta)
            c = alpha * model.mass + beta * model.stiffness
            lines = tool.lines(25)
            exact = np.array([a @ np.linalg.solve(
                model.stiffness - (2 * np.pi * f) ** 2 * model.mass + 2j * np.pi * f * c, a.T)
                for f in lines])
            whole = receptance(lines, every.omega, ray.ratios(every.omega), every.phi,
                               np.zeros((3, 3)))
            diag = (slice(None), range(3), range(3))
            scale = np.abs(exact[diag]).max(axis=0)
            assert (np.abs(whole - exact)[diag] / scale).max() < 1e-7
            summed = with_damping(tool, ray)
            m = len(summed.modes.omega)
            assert np.all(every.omega[m:] / (2 * np.pi) > summed.band_top_hz)
            def dynamic(omega, phi):  # the modes' terms less their static part
                return (receptance(lines, omega, ray.ratios(omega), phi, np.zeros((3, 3)))
                        + residual_flexibility(np.zeros((3, 3)), omega, phi))  # - sum/w^2

            # (of every mode less the summed ones: a repeated pair split by the cut has
            # another basis in each solve)
            left = dynamic(every.omega, every.phi) - dynamic(summed.modes.omega,
                                                            summed.modes.phi)
            gap = summed.receptance(lines) + left - exact
            assert (np.abs(gap)[diag] / scale).max() < 1e-7
        batch = pose_batch(scene.manipulator, [c.pose.height for c in scene.cases.values()],
                           [c.pose.azimuth for c in scene.cases.values()],
                           [c.pose.tilt for c in scene.cases.values()])
        from analytical.tool_response import least_stiffness_map
        least = least_stiffness_map(scene.manipulator, scene.analytical, batch, damping,
                                       point, scene.fidelity.modes, 2000)
        for i, case in enumerate(scene.cases.values()):
            g = pose_geometry(scene.manipulator, case.pose)
            one = analytical_tool(scene.manipulator, g, scene.analytical, damping, point,
                                  scene.fidelity.modes).least()
            assert np.allclose(least.stiffness_n_per_m[i], one.stiffness_n_per_m[0],
                               rtol=1e-9)

    points = st.tuples(*[st.floats(-0.3, 0.3, allow_nan=False)] * 3)
    zetas = st.floats(0.005, 0.1, allow_nan=False)
    once = settings(max_examples=12, deadline=None, derandomize=True, database=None,
                    suppress_health_check=list(HealthCheck))
    once(given(machines(), points, zetas)(check))()
    once(given(real_leg_machines(True), points, zetas)(check))()
