"""Case study: the dynamic compliance at the tool, both models' modal sums against the solid's
direct frequency response (results.cases[].tool_response), in the scenes that ask for it
([damping] or [tool]; solvers/tool_frf.py).

At each case: the static compliance along x, y, z (the FEM's static solve, the analytical
model's), and every peak of |H_dd| that sets the dynamic stiffness (a mode's one-mode height at
least common.frf.DIRECT_FLOOR of the direction's largest): the solid's direct response there
(five solves and a rational fit a peak, one solve at the peak), the FEM's modal sum and the
analytical model's, all three damped by one Rayleigh damping (`solvers.tool_frf.check_damping`).
The FEM's own error: a peak's frequency carries the run's estimated error of its mode; the
static compliance and a peak's height the two-mesh estimate of the FEM's modal sum at the
run's size and one size coarser (the larger of Richardson's step and the GCI, as for the
frequencies). The curves drawn are both models' |H_dd| at that shared damping (the scene's
own: `rps frf`).
"""
from __future__ import annotations

import time

import numpy as np

import results
from common.frf import DIRECTIONS
from common.settings import as_dict
from results import Section, Table

from .registry import CaseContext, Context, Study, own

CURVE_LINES = 400  # lines of the curves the report draws
MATCH = 0.2  # a peak of another model (or mesh) is the same peak within 20 % in frequency


def _percent(value: float, reference: float) -> float:
    return 100.0 * (value / reference - 1.0)


def _nearest(peaks, f: float):
    """The peak of `peaks` nearest `f` within MATCH, or None."""
    near = [q for q in peaks if abs(q.frequency_hz / f - 1.0) < MATCH]
    return min(near, key=lambda q: abs(q.frequency_hz - f)) if near else None


def tool_response(scene, geometry, fem_error, cache) -> results.ToolResponse:
    """The record of one case (module docstring), through the result cache."""
    from solvers.compare import fem_options, fem_runtime
    from solvers.refinement import coarse_size

    compared = scene.fidelity.modes
    size = scene.fem.mesh_size
    fine_options = fem_options(scene, size, modes=compared)
    coarse_options = fem_options(scene, coarse_size(scene, size), modes=compared)
    payload = {"manipulator": as_dict(scene.manipulator), "geometry": as_dict(geometry),
               "fem": as_dict(fine_options), "coarse": as_dict(coarse_options),
               "analytical": as_dict(scene.analytical), "damping": as_dict(scene.damping),
               "tool": as_dict(scene.tool), "compared": compared,
               "fem_error": None if fem_error is None else [float(e) for e in fem_error]}

    def compute():
        return _compute(scene, geometry, fem_error, fine_options, coarse_options,
                        fem_runtime(scene, cache)), {}

    value, _, _ = cache.get_or_compute("tool_response", payload, compute,
                                       modules=("solvers.tool_frf", "studies.tool_response"))
    return results.ToolResponse(**value)  # type: ignore[typeddict-item]


def _compute(scene, geometry, fem_error, fine_options, coarse_options,
             runtime) -> results.ToolResponse:
    from solvers.tool_frf import analytical_tool, fem_check, with_damping

    start = time.perf_counter()
    compared, point = scene.fidelity.modes, scene.tool.point
    analytical = analytical_tool(scene.manipulator, geometry, scene.analytical, scene.damping,
                                 point, compared)
    check = fem_check(scene.manipulator, geometry, scene.damping, point, compared,
                      fine_options, coarse_options, runtime)
    fem, damping = check.fem, check.damping
    unmatched = ([] if check.not_solved is None else
                 [results.ToolUnmatched(direction="all", reason=check.not_solved)])
    g_fem, g_an = np.diagonal(fem.modes.static), np.diagonal(analytical.modes.static)
    g_err = check.two_mesh_percent(g_fem, np.diagonal(check.coarse.modes.static))
    static = [results.ToolStatic(direction=d, fem_m_per_n=float(g_fem[i]),
                                 fem_error_percent=float(g_err[i]),
                                 analytical_m_per_n=float(g_an[i]),
                                 error_percent=_percent(float(g_an[i]), float(g_fem[i])))
              for i, d in enumerate(DIRECTIONS)]
    fem_d, an_d, coarse_d = (with_damping(m, damping) for m in (fem, analytical, check.coarse))
    peaks = []
    for d, name in enumerate(DIRECTIONS):
        fem_peaks, coarse_peaks, an_peaks = (m.peaks(d) for m in (fem_d, coarse_d, an_d))
        for p in check.direct.get(d, []):
            modal, twin, an_peak = (_nearest(found, p.frequency_hz)
                                    for found in (fem_peaks, coarse_peaks, an_peaks))
            missing = ("the FEM's modal sum" if modal is None else "the coarser mesh"
                       if twin is None else "the analytical model" if an_peak is None else None)
            if modal is None or twin is None or an_peak is None:
                unmatched.append(results.ToolUnmatched(
                    direction=name, reason=f"the solid's peak at {p.frequency_hz:.4g} Hz (mode "
                    f"{p.mode + 1}) has none in {missing} within {100 * MATCH:g} %"))
                continue
            f_err = (None if fem_error is None or p.mode >= len(fem_error)
                     else float(fem_error[p.mode]))
            peaks.append(results.ToolPeak(
                direction=name, fem_mode=p.mode + 1, fem_direct_hz=p.frequency_hz,
                fem_direct_m_per_n=p.magnitude_m_per_n, fem_frequency_error_percent=f_err,
                fem_magnitude_error_percent=float(check.two_mesh_percent(
                    [modal.magnitude_m_per_n], [twin.magnitude_m_per_n])[0]),
                fem_modal_hz=modal.frequency_hz, fem_modal_m_per_n=modal.magnitude_m_per_n,
                fem_modal_magnitude_error_percent=_percent(modal.magnitude_m_per_n,
                                                           p.magnitude_m_per_n),
                analytical_hz=an_peak.frequency_hz,
                analytical_m_per_n=an_peak.magnitude_m_per_n,
                frequency_error_percent=_percent(an_peak.frequency_hz, p.frequency_hz),
                magnitude_error_percent=_percent(an_peak.magnitude_m_per_n,
                                                 p.magnitude_m_per_n)))
    lines = an_d.lines(CURVE_LINES, min(an_d.band_top_hz, fem_d.band_top_hz))

    def curve(model) -> dict[str, list[float]]:  # at the check's damping: the peaks on them
        h = model.receptance(lines)
        return {name: np.abs(h[:, d, d]).tolist() for d, name in enumerate(DIRECTIONS)}

    return results.ToolResponse(
        point_mm=[1e3 * v for v in point], damping=scene.damping.describe(),
        check_damping=damping.describe() + " (through the scene's damping at the FEM's first "
        "and highest compared mode, shared by all three)",
        analytical=scene.analytical.describe(),
        fem_mesh_size_mm=fine_options.mesh.size * 1e3,
        coarse_mesh_size_mm=coarse_options.mesh.size * 1e3,
        static=static, peaks=peaks, unmatched=unmatched,
        curves=results.ToolCurves(frequency_hz=lines.tolist(),
                                  analytical_m_per_n=curve(an_d), fem_m_per_n=curve(fem_d)),
        seconds=time.perf_counter() - start)


def run(ctx: Context, cc: CaseContext) -> results.ToolResponse | None:
    if not ctx.scene.dynamics_given or ctx.scene.fem.platform != "rigid":
        return None  # the scene does not ask (or has no rigid platform to hold a tool)
    cc.step("dynamic compliance at the tool: both models against the FEM's direct response")
    return tool_response(ctx.scene, cc.geometry, cc.fem_error, ctx.cache)


STUDY = Study(own(
    "tool_response", "case",
    section=Section("tool-response", "Dynamic compliance at the tool: both models against "
                    "the solid's direct frequency response", None,
                    asks="[damping] or [tool], a rigid platform"),
    tables=(Table("peak_frequencies", ("direction", "fem_mode", "fem_direct_hz",
                                       "fem_frequency_error_percent", "analytical_hz",
                                       "frequency_error_percent"), each="peaks"),
            Table("peak_heights", ("direction", "fem_mode", "fem_direct_m_per_n",
                                   "fem_magnitude_error_percent", "analytical_m_per_n",
                                   "magnitude_error_percent",
                                   "fem_modal_magnitude_error_percent"), each="peaks"),
            Table("static", ("direction", "fem_m_per_n", "fem_error_percent",
                             "analytical_m_per_n", "error_percent"), each="static"),
            Table("unmatched", ("direction", "reason"), each="unmatched"))),
    "case", run)
