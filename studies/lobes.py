"""Case study: the milling stability lobes at each case (results.cases[].lobes), in the scenes
that declare a [cutting] table (chatter/, `rps lobes`).

The same cut (the scene's [cutting]: speeds and method) through three sets of tool modes: the
analytical model's at the run's fidelity (its compared modes and two more), and the solid's
at the run's mesh size and one size coarser (its solved modes). The FEM is the referee: the
analytical model's critical depth against it at every speed, and the FEM's own error from its
two meshes (the larger of Richardson's step and the GCI, as for the frequencies). Each curve
states its own discretisation error (semi-discretization: the depth at half the intervals).
"""
from __future__ import annotations

import math
import time

import numpy as np

from common.settings import as_dict
from results import CaseLobes, LobeCurve, LobeSummary, Record, Section, Table

from .registry import CaseContext, Context, Study


def _mm(values) -> list[float | None]:
    return [float(v) * 1e3 if math.isfinite(v) else None for v in np.asarray(values, float)]


def _curve(label: str, d) -> LobeCurve:
    return LobeCurve(
        model=label, critical_depth_mm=_mm(d.depth),
        chatter_frequency_hz=[float(f) if math.isfinite(f) else None for f in d.frequency_hz],
        kind=[str(k) or None for k in d.kind],
        max_error_percent=(None if d.error_percent is None
                           else float(d.error_percent.max(initial=0.0))))


def _summary(label: str, d, error: float | None, fem_error: float | None) -> LobeSummary:
    k, best = d.least, d.best
    finite_best = math.isfinite(float(d.depth[best]))
    return LobeSummary(
        model=label, least_depth_mm=None if k is None else float(d.depth[k]) * 1e3,
        least_rpm=None if k is None else float(d.speeds_hz[k]) * 60,
        kind=None if k is None else str(d.kind[k]),
        chatter_frequency_hz=None if k is None else float(d.frequency_hz[k]),
        best_rpm=float(d.speeds_hz[best]) * 60,
        best_depth_mm=float(d.depth[best]) * 1e3 if finite_best else None,
        error_percent=error, fem_error_percent=fem_error)


def _percent(a: float, b: float) -> float | None:
    return 100.0 * (a / b - 1.0) if math.isfinite(a) and math.isfinite(b) else None


def case_lobes(scene, geometry, cache) -> CaseLobes:
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
               "tool": as_dict(scene.tool), "cutting": as_dict(scene.cutting),
               "compared": compared}

    def compute():
        return _compute(scene, geometry, fine_options, coarse_options,
                        fem_runtime(scene, cache)), {}

    value, _, _ = cache.get_or_compute("lobes", payload, compute,
                                       modules=("chatter.sdm", "chatter.zoa", "chatter.lobes",
                                                "studies.lobes"))
    return CaseLobes(**value)  # type: ignore[typeddict-item]


def _compute(scene, geometry, fine_options, coarse_options, runtime) -> CaseLobes:
    from chatter.lobes import diagram
    from chatter.tool_input import from_base
    from solvers.tool_frf import analytical_tool, fem_tool_at, two_mesh_percent

    start = time.perf_counter()
    compared, point, cutting = scene.fidelity.modes, scene.tool.point, scene.cutting

    def lobes_of(tool):
        modes = from_base(tool.modes.omega, tool.zeta, tool.modes.phi, geometry.rotation,
                          cutting.feed_direction)
        return diagram(modes, cutting)

    an = lobes_of(analytical_tool(scene.manipulator, geometry, scene.analytical, scene.damping,
                                  point, compared))
    fem, coarse = (lobes_of(fem_tool_at(scene.manipulator, geometry, options, runtime,
                                        scene.damping, point, compared))
                   for options in (fine_options, coarse_options))
    ratio = coarse_options.mesh.size / fine_options.mesh.size
    both = np.isfinite(fem.depth) & np.isfinite(coarse.depth)
    safe_f, safe_c = np.where(both, fem.depth, 1.0), np.where(both, coarse.depth, 1.0)
    fem_err = np.where(both, two_mesh_percent(safe_f, safe_c, ratio), np.nan)
    errors = [_percent(a, b) for a, b in zip(an.depth, fem.depth, strict=True)]
    finite = np.array([abs(e) for e in errors if e is not None])
    k_an, k_fem = an.least, fem.least
    least_error = (None if k_an is None or k_fem is None
                   else _percent(float(an.depth[k_an]), float(fem.depth[k_fem])))
    least_fem_error = (None if k_fem is None or not math.isfinite(fem_err[k_fem])
                       else float(fem_err[k_fem]))
    return CaseLobes(
        method=cutting.method, spindle_rpm=[float(v) * 60 for v in an.speeds_hz],
        analytical=_curve(f"analytical ({scene.analytical.describe()})", an),
        fem=_curve(f"FEM ({fine_options.mesh.size * 1e3:g} mm)", fem),
        fem_coarse=_curve(f"FEM ({coarse_options.mesh.size * 1e3:g} mm)", coarse),
        fem_mesh_size_mm=fine_options.mesh.size * 1e3,
        coarse_mesh_size_mm=coarse_options.mesh.size * 1e3,
        error_percent=errors,
        fem_error_percent=[float(e) if math.isfinite(e) else None for e in fem_err],
        median_error_percent=float(np.median(finite)) if finite.size else None,
        max_error_percent=float(finite.max()) if finite.size else None,
        summary=[_summary("analytical", an, least_error, None),
                 _summary("FEM", fem, None, least_fem_error)],
        seconds=time.perf_counter() - start)


def run(ctx: Context, cc: CaseContext) -> CaseLobes | None:
    scene = ctx.scene
    if scene.cutting is None or scene.fem.platform != "rigid":
        return None  # the scene asks no cut (or has no rigid platform to hold a tool)
    cc.step("stability lobes of the cut: the analytical model's and the FEM's tool modes")
    return case_lobes(scene, cc.geometry, ctx.cache)


STUDY = Study(Record(
    "lobes", "case", CaseLobes | None, None,
    Section("lobes", "Stability lobes of the cut: the analytical model against the FEM", None),
    (Table("least", ("model", "least_depth_mm", "least_rpm", "kind", "chatter_frequency_hz",
                     "best_rpm", "best_depth_mm", "error_percent", "fem_error_percent"),
           each="summary"),)),
    "case", run)
