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

from chatter.lobes import finite_mm, mm_list
from common.settings import as_dict
from results import CaseLobes, LobeBand, LobeCurve, LobeSummary, Record, Section, Table

from .registry import CaseContext, Context, Study

BAND_SAMPLES = 256  # plain draws of the inputs (a power of two: Sobol' points' balance); 146
                    # at least for the least draw to bound the 2.5 % quantile from below with
                    # 97.5 % confidence (quantile_interval: 256 give the 2nd and 13th least)
BAND_SPEEDS = 60  # speeds of the band (the stability map's count)
BAND_BUDGET_SECONDS = 300.0  # a case's band in a run; beyond, refused in the record


def _curve(label: str, d) -> LobeCurve:
    return LobeCurve(
        model=label, critical_depth_mm=mm_list(d.depth),
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


def case_lobes(scene, geometry, cache, pose=None) -> CaseLobes:
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
    value = dict(value)
    value["band"] = (None if scene.uncertainty is None or pose is None
                     else lobe_band(scene, pose, cache))
    return CaseLobes(**value)  # type: ignore[typeddict-item]


def band_speeds(cutting) -> np.ndarray:
    """The band's speeds (rev/s): the case's, thinned to BAND_SPEEDS evenly over its range."""
    speeds = cutting.speeds_hz()
    if len(speeds) <= BAND_SPEEDS:
        return speeds
    return speeds[np.unique(np.round(np.linspace(0, len(speeds) - 1, BAND_SPEEDS)).astype(int))]


def lobe_band(scene, pose, cache, samples: int | None = None) -> LobeBand:
    """The critical depth's band over the scene's [uncertainty] at `pose` (results.LobeBand),
    through the result cache; refused in the record (never fatal, not cached) when a draw is
    out of reach or the estimate exceeds BAND_BUDGET_SECONDS."""
    from importlib.metadata import version

    from common.errors import InputError
    from solvers.uncertainty import run_model

    samples = samples or BAND_SAMPLES
    options = run_model(scene, scene.analytical)
    payload = {"manipulator": as_dict(scene.manipulator), "pose": as_dict(pose),
               "analytical": as_dict(options), "uncertainty": scene.raw["uncertainty"],
               "damping": as_dict(scene.damping), "tool": as_dict(scene.tool),
               "cutting": as_dict(scene.cutting), "compared": scene.fidelity.modes,
               "samples": samples, "scipy": version("scipy")}
    start = time.perf_counter()
    try:
        value, _, _ = cache.get_or_compute(
            "lobe_band", payload, lambda: (_band(scene, options, pose, samples), {}),
            modules=("chatter.sdm", "chatter.lobes", "studies.lobes", "solvers.uncertainty",
                     "analytical.sample_batch", "analytical.tool_response",
                     "scene.uncertainty", "scene.address"))
    except InputError as exc:  # a draw out of reach, refused as a machine, or over budget
        return _refused(scene, options, samples, str(exc), time.perf_counter() - start)
    return LobeBand(**value)  # type: ignore[typeddict-item]


def _refused(scene, options, samples: int, why: str, seconds: float) -> LobeBand:
    return LobeBand(samples=samples, model=options.describe(),
                    inputs=list(scene.uncertainty.names), spindle_rpm=[],
                    nominal_depth_mm=[], q025_depth_mm=[], median_depth_mm=[],
                    q975_depth_mm=[], least_nominal_mm=None, least_q025_mm=None,
                    least_q025_interval_mm=[None, None], least_median_mm=None,
                    least_q975_mm=None, level_error_percent=None, refused=why,
                    seconds=seconds)


def _band(scene, options, pose, samples: int) -> LobeBand:
    """The band (lobe_band): the scene's machine's full diagram at the band's speeds, then
    every draw at the coarse level of intervals bracketed about the scene's machine's coarse
    depths (chatter.lobes.depths_near); the coarse level's own error, measured on the scene's
    machine, stated beside it."""
    from analytical.tool_response import summed_count
    from chatter.lobes import depths_near, diagram
    from chatter.tool_input import from_base
    from common.errors import InputError
    from solvers.uncertainty import draws, prepare, tool_modes

    start = time.perf_counter()
    cutting = scene.cutting
    speeds = band_speeds(cutting)
    count = summed_count(scene.manipulator, options, scene.fidelity.modes)
    unit = draws(scene, samples)
    drawn = prepare(scene, pose, unit)  # every draw's machine and reach checked first
    own_machine = prepare(scene, pose, np.full((1, unit.shape[1]), 0.5))

    def cut_modes(prepared, modes, k):
        return from_base(modes.omega[k], scene.damping.ratios(modes.omega[k]), modes.phi[k],
                         prepared.poses.rotation[k], cutting.feed_direction)

    own = diagram(cut_modes(own_machine, tool_modes(scene, options, own_machine, count), 0),
                  cutting, speeds, estimate=False)
    sdm = own.coarse_depth is not None  # semi-discretization: draws at its coarse level
    near = own.coarse_depth if own.coarse_depth is not None else own.depth
    found = tool_modes(scene, options, drawn, count)
    depth = np.empty((samples, len(speeds)))
    pilot = time.perf_counter()
    for k in range(samples):
        modes = cut_modes(drawn, found, k)
        depth[k] = (depths_near(modes, cutting, speeds, near) if sdm
                    else diagram(modes, cutting, speeds, estimate=False).depth)
        if k == 0 and (time.perf_counter() - pilot) * samples > BAND_BUDGET_SECONDS:
            raise InputError(f"{samples} draws x {len(speeds)} speeds would take about "
                             f"{(time.perf_counter() - pilot) * samples:.0f} s, above the "
                             f"{BAND_BUDGET_SECONDS:g} s allowed")
    both = np.isfinite(own.depth) & np.isfinite(near)
    level = (float(np.max(np.abs(near[both] / own.depth[both] - 1.0)) * 100)
             if sdm and both.any() else None)
    q = np.quantile(depth, (0.025, 0.5, 0.975), axis=0, method="inverted_cdf")
    least = depth.min(axis=1)
    lq = np.quantile(least, (0.025, 0.5, 0.975), method="inverted_cdf")
    lo, hi = quantile_interval(samples, 0.025)
    ordered = np.concatenate([[-np.inf], np.sort(least), [np.inf]])
    return LobeBand(
        samples=samples, model=options.describe(), inputs=list(scene.uncertainty.names),
        spindle_rpm=[float(v) * 60 for v in speeds], nominal_depth_mm=mm_list(own.depth),
        q025_depth_mm=mm_list(q[0]), median_depth_mm=mm_list(q[1]), q975_depth_mm=mm_list(q[2]),
        least_nominal_mm=finite_mm(own.depth.min()), least_q025_mm=finite_mm(lq[0]),
        least_q025_interval_mm=[finite_mm(ordered[lo]), finite_mm(ordered[hi])],
        least_median_mm=finite_mm(lq[1]), least_q975_mm=finite_mm(lq[2]),
        level_error_percent=level, refused=None, seconds=time.perf_counter() - start)


def quantile_interval(n: int, p: float, confidence: float = 0.95) -> tuple[int, int]:
    """(l, u), 1-based order statistics of n draws that hold the p-quantile xi between them
    with at least `confidence`, distribution-free: the count B of draws below xi is
    binomial(n, p), X_(l) <= xi when B >= l and X_(u) > xi when B < u. l = 0: no draw bounds
    it from below (too few draws); u = n + 1: none from above."""
    from scipy.stats import binom

    tail = (1.0 - confidence) / 2.0
    lo = 0
    while lo < n and binom.cdf(lo, n, p) <= tail:  # P(B <= lo) <= tail: X_(lo + 1) <= xi
        lo += 1
    hi = 1
    while hi <= n and binom.cdf(hi - 1, n, p) < 1.0 - tail:  # P(B <= hi - 1) >= 1 - tail
        hi += 1
    return lo, hi


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
        band=None, seconds=time.perf_counter() - start)


def run(ctx: Context, cc: CaseContext) -> CaseLobes | None:
    scene = ctx.scene
    if scene.cutting is None or scene.fem.platform != "rigid":
        return None  # the scene asks no cut (or has no rigid platform to hold a tool)
    cc.step("stability lobes of the cut: the analytical model's and the FEM's tool modes")
    return case_lobes(scene, cc.geometry, ctx.cache, cc.case.pose)


STUDY = Study(Record(
    "lobes", "case", CaseLobes | None, None,
    Section("lobes", "Stability lobes of the cut: the analytical model against the FEM", None,
            asks="[cutting]"),
    (Table("least", ("model", "least_depth_mm", "least_rpm", "kind", "chatter_frequency_hz",
                     "best_rpm", "best_depth_mm", "error_percent", "fem_error_percent"),
           each="summary"),
     Table("band", ("model", "samples", "least_nominal_mm", "least_q025_mm",
                    "least_q025_interval_mm", "least_median_mm", "least_q975_mm",
                    "level_error_percent", "refused"), each="band"))),
    "case", run)
