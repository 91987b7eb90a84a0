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
frequencies). The curves drawn are both models' |H_dd| at the scene's own damping.
"""
from __future__ import annotations

import time

import numpy as np
from pydantic import FiniteFloat, with_config
from typing_extensions import TypedDict

from common.frf import DIRECT_FLOOR, DIRECTIONS
from common.settings import as_dict
from results import STRICT, Record, Section, Table

from .registry import CaseContext, Context, Study

CURVE_LINES = 400  # lines of the curves the report draws


@with_config(STRICT)
class ToolStatic(TypedDict):
    direction: str
    fem_m_per_n: FiniteFloat
    fem_error_percent: FiniteFloat
    analytical_m_per_n: FiniteFloat
    error_percent: FiniteFloat  # analytical against the FEM


@with_config(STRICT)
class ToolPeak(TypedDict):
    direction: str
    fem_mode: int
    fem_direct_hz: FiniteFloat
    fem_direct_m_per_n: FiniteFloat
    fem_frequency_error_percent: FiniteFloat | None  # the run's estimate for the mode
    fem_magnitude_error_percent: FiniteFloat  # two-mesh, of the FEM's modal sum
    fem_modal_hz: FiniteFloat
    fem_modal_m_per_n: FiniteFloat
    fem_modal_magnitude_error_percent: FiniteFloat  # FEM modal sum against its direct response
    analytical_hz: FiniteFloat
    analytical_m_per_n: FiniteFloat
    frequency_error_percent: FiniteFloat  # analytical against the direct response
    magnitude_error_percent: FiniteFloat


@with_config(STRICT)
class ToolCurves(TypedDict):
    frequency_hz: list[FiniteFloat]
    analytical_m_per_n: dict[str, list[FiniteFloat]]  # |H_dd|, d = x, y, z
    fem_m_per_n: dict[str, list[FiniteFloat]]


@with_config(STRICT)
class ToolResponse(TypedDict):
    point_mm: list[FiniteFloat]
    damping: str
    check_damping: str
    analytical: str
    fem_mesh_size_mm: FiniteFloat
    coarse_mesh_size_mm: FiniteFloat
    static: list[ToolStatic]
    peaks: list[ToolPeak]
    unmatched: list[str]
    curves: ToolCurves
    seconds: FiniteFloat


def _percent(value: float, reference: float) -> float:
    return 100.0 * (value / reference - 1.0)


def tool_response(scene, geometry, fem_error, cache) -> ToolResponse:
    """The record of one case (module docstring), through the result cache."""
    from solvers.compare import fem_options, fem_runtime
    from solvers.refinement import coarse_size

    compared = scene.fidelity.modes
    size = scene.fem.mesh_size
    coarse = coarse_size(scene, size)
    fine_options = fem_options(scene, size, modes=compared)
    coarse_options = fem_options(scene, coarse, modes=compared)
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
    return ToolResponse(**value)  # type: ignore[typeddict-item]


def _compute(scene, geometry, fem_error, fine_options, coarse_options, runtime) -> dict:
    from fem_reference import solve_pose
    from fem_reference.convergence import two_mesh_error, two_mesh_gci
    from solvers.tool_frf import (
        analytical_tool,
        check_damping,
        direct_check,
        fem_tool,
        with_damping,
    )

    start = time.perf_counter()
    compared, point = scene.fidelity.modes, scene.tool.point
    analytical = analytical_tool(scene.manipulator, geometry, scene.analytical, scene.damping,
                                 point, compared)
    from fem_reference.resources import MemoryLimitError

    fine = solve_pose(scene.manipulator, geometry, fine_options, runtime)
    unmatched: list[str] = []
    fem = fem_tool(fine, scene.damping, point, compared)
    damping = check_damping(scene.damping, fem)
    try:  # the complex factors' memory is checked before the first of them
        direct = direct_check(fine, fem, damping, point)
    except MemoryLimitError as exc:  # a side study's budget: said, not fatal to the run
        direct = {}
        unmatched.append(f"the solid's direct response was not solved: {exc}")
    del fine  # its matrices are large: the coarse solve need not hold both
    coarse_fem = fem_tool(solve_pose(scene.manipulator, geometry, coarse_options, runtime),
                          scene.damping, point, compared)
    ratio = coarse_options.mesh.size / fine_options.mesh.size

    def estimate(fine_values, coarse_values) -> np.ndarray:
        pair = (np.abs(fine_values), np.abs(coarse_values), ratio)
        return np.maximum(two_mesh_error(*pair), two_mesh_gci(*pair))

    g_fem, g_an = np.diagonal(fem.modes.static), np.diagonal(analytical.modes.static)
    g_err = estimate(g_fem, np.diagonal(coarse_fem.modes.static))
    static = [ToolStatic(direction=d, fem_m_per_n=float(g_fem[i]),
                         fem_error_percent=float(g_err[i]),
                         analytical_m_per_n=float(g_an[i]),
                         error_percent=_percent(float(g_an[i]), float(g_fem[i])))
              for i, d in enumerate(DIRECTIONS)]
    fem_d, an_d, coarse_d = (with_damping(m, damping) for m in (fem, analytical, coarse_fem))
    peaks = []
    for d, name in enumerate(DIRECTIONS):
        fem_peaks = {p.mode: p for p in fem_d.peaks(d, DIRECT_FLOOR)}
        coarse_peaks = coarse_d.peaks(d, DIRECT_FLOOR)
        an_peaks = an_d.peaks(d)
        for p in direct.get(d, []):
            modal = fem_peaks.get(p.mode)
            near = [q for q in an_peaks if abs(q.frequency_hz / p.frequency_hz - 1) < 0.2]
            twin = [q for q in coarse_peaks if q.mode == p.mode]
            if modal is None or not near or not twin:
                unmatched.append(f"{name}: the FEM's peak at {p.frequency_hz:.4g} Hz (mode "
                                 f"{p.mode + 1}) has no "
                                 + ("analytical peak within 20 %" if not near else
                                    "counterpart in the FEM's modal sum" if modal is None else
                                    "counterpart on the coarser mesh"))
                continue
            an_peak = min(near, key=lambda q: abs(q.frequency_hz - p.frequency_hz))
            f_err = (None if fem_error is None or p.mode >= len(fem_error)
                     else float(fem_error[p.mode]))
            peaks.append(ToolPeak(
                direction=name, fem_mode=p.mode + 1, fem_direct_hz=p.frequency_hz,
                fem_direct_m_per_n=p.magnitude_m_per_n, fem_frequency_error_percent=f_err,
                fem_magnitude_error_percent=float(estimate(
                    [modal.magnitude_m_per_n], [twin[0].magnitude_m_per_n])[0]),
                fem_modal_hz=modal.frequency_hz, fem_modal_m_per_n=modal.magnitude_m_per_n,
                fem_modal_magnitude_error_percent=_percent(modal.magnitude_m_per_n,
                                                           p.magnitude_m_per_n),
                analytical_hz=an_peak.frequency_hz,
                analytical_m_per_n=an_peak.magnitude_m_per_n,
                frequency_error_percent=_percent(an_peak.frequency_hz, p.frequency_hz),
                magnitude_error_percent=_percent(an_peak.magnitude_m_per_n,
                                                 p.magnitude_m_per_n)))
    lines = analytical.lines(CURVE_LINES)

    def curve(model) -> dict[str, list[float]]:
        h = model.receptance(lines)
        return {name: np.abs(h[:, d, d]).tolist() for d, name in enumerate(DIRECTIONS)}

    return {
        "point_mm": [1e3 * v for v in point],
        "damping": scene.damping.describe(),
        "check_damping": damping.describe() + " (through the scene's damping at the FEM's "
                         "first and highest compared mode, shared by all three)",
        "analytical": scene.analytical.describe(),
        "fem_mesh_size_mm": fine_options.mesh.size * 1e3,
        "coarse_mesh_size_mm": coarse_options.mesh.size * 1e3,
        "static": static, "peaks": peaks, "unmatched": unmatched,
        "curves": {"frequency_hz": lines.tolist(), "analytical_m_per_n": curve(analytical),
                   "fem_m_per_n": curve(fem)},
        "seconds": time.perf_counter() - start,
    }


def run(ctx: Context, cc: CaseContext) -> ToolResponse | None:
    if not ctx.scene.dynamics_given:  # the scene does not ask: nothing computed
        return None
    cc.step("dynamic compliance at the tool: both models against the FEM's direct response")
    scene = ctx.scene
    if scene.fem.platform != "rigid":
        return None
    return tool_response(scene, cc.geometry, cc.fem_error, ctx.cache)


STUDY = Study(Record(
    "tool_response", "case", ToolResponse | None, None,
    Section("tool-response", "Dynamic compliance at the tool: both models against the solid's "
            "direct frequency response", None),
    (Table("peaks", ("direction", "fem_mode", "fem_direct_hz", "fem_frequency_error_percent",
                     "analytical_hz", "frequency_error_percent", "fem_direct_m_per_n",
                     "fem_magnitude_error_percent", "analytical_m_per_n",
                     "magnitude_error_percent", "fem_modal_magnitude_error_percent"),
           each="peaks"),
     Table("static", ("direction", "fem_m_per_n", "fem_error_percent", "analytical_m_per_n",
                      "error_percent"), each="static"))),
    "case", run)

