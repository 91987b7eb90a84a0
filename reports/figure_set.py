"""Which figures the report draws, from which results, into which files: every figure of
every case and study, and what the template needs to show them."""
from __future__ import annotations

from pathlib import Path
from typing import Callable, TypedDict

from common.errors import ComputeError
from common.paths import distinct_stems, file_stem, inside
from results import Case, Results

from . import figures, real_machine, validation, workspace_figures
from .beam_figure import beam_mode
from .figure_jobs import Job, Outcome, draw
from .results import (
    base_circle_points,
    has_paper,
    joint_points,
    leg_axis_shapes,
    main_cases,
    platform_centre,
    platform_motion,
)
from .study_figure_set import study_figure_set


class ReportError(ComputeError):
    """The report could not be rendered (one-line message)."""


class ModePicture(TypedDict):
    """One pair of modes as the template shows it (a picture None: not drawn)."""
    fem_mode: int
    analytical_mode: int
    f_fem: float
    f_an: float
    mac: float
    fem_png: Path | None
    beam_png: Path | None


class ModeFigures(TypedDict):
    pairs: list[ModePicture]
    fem_note: str | None  # why no FEM picture is drawn


def run_settings(results: Results) -> tuple[str, str]:
    """The speed-against-error labels of the settings the run used: its analytical model and
    its FEM mesh (ringed in both speed figures)."""
    fidelity = results["fidelity"]
    return fidelity["analytical"]["setting"], f"h = {fidelity['fem']['mesh_size_mm']:g} mm"


def reference(case: Case) -> tuple[list[float], str]:
    """The best FEM frequencies of a case and their name."""
    if case["fem_reference_hz"]:
        return case["fem_reference_hz"], "FEM limit h → 0"
    return case["fem"]["frequencies_hz"], "our FEM"


class _Plan:
    """The figures to draw, each with what to do with its outcome (default: a failure fails
    the report)."""

    def __init__(self) -> None:
        self.jobs: list[Job] = []
        self.then: list[Callable[[Outcome], None] | None] = []

    def add(self, draw_fn, outputs, *args, then=None, errors=(), **kwargs) -> None:
        outputs = tuple(outputs) if isinstance(outputs, (list, tuple)) else (outputs,)
        self.jobs.append(Job(draw_fn, outputs, args, kwargs, errors))
        self.then.append(then)

    def draw(self, cache_dir: Path | None, workers: int) -> None:
        for outcome, then in zip(draw(self.jobs, cache_dir, workers), self.then):
            if then is not None:
                then(outcome)
            elif outcome.error is not None:
                raise outcome.error


def make_figures(results: Results, results_path: Path, fig_dir: Path,
                 cache_dir: Path | None = None, workers: int = 1) -> dict:
    """Draw every figure into fig_dir (on `workers` processes, reusing the pictures of
    `cache_dir`: `figure_jobs`); return what the template needs to show them, the figures of
    the studies drawn as their tables under "studies" (`study_figure_set`)."""
    figs: dict = {"cases": {}, "notes": []}
    plan = _Plan()
    main = main_cases(results)
    stems = distinct_stems((case["name"] for case in results["cases"]), "case name")
    for i, case in enumerate(results["cases"]):
        name, stem = case["name"], stems[case["name"]]
        entry: dict = {"modes": {"pairs": [], "fem_note": None}}
        if case["element_convergence"]:
            ref, label = reference(case)
            path = inside(fig_dir, f"element_convergence_{stem}.png")
            plan.add(figures.element_convergence, path, case["element_convergence"], ref, label,
                     path)
            entry["element_convergence"] = (path, label)
        if case["fem_refinement"]:
            path = inside(fig_dir, f"fem_refinement_{stem}.png")
            plan.add(figures.fem_refinement, path, case["fem_refinement"], path,
                     case["fem"]["mesh_size_mm"])
            entry["fem_refinement"] = path
        if case in main:
            entry["mac"] = inside(fig_dir, f"mac_{stem}.png")
            plan.add(figures.mac_matrix, entry["mac"], case["mac_matrix"], case["pairs"],
                     entry["mac"])
            entry["modes"] = mode_figures(results, results_path, i, fig_dir, figs["notes"], plan)
        figs["cases"][name] = entry
    speed = {c["name"]: c["speed_vs_error"] for c in results["cases"] if c["speed_vs_error"]}
    if speed:
        figs["speed"] = inside(fig_dir, "speed_vs_error.png")
        plan.add(figures.speed_vs_error, figs["speed"], speed, figs["speed"],
                 paper=has_paper(results), chosen=run_settings(results))
    wv = results["studies"]["workspace_validation"]
    if wv and wv["worst_pose"]:
        figs["validation_map"] = inside(fig_dir, "workspace_validation.png")

        def validation_done(outcome):
            if outcome.error is not None:
                figs.pop("validation_map")
                figs["notes"].append(f"workspace validation map: {outcome.error}")
        plan.add(validation.error_maps, figs["validation_map"], wv,
                 figs["validation_map"], then=validation_done)
    ws = results["studies"]["workspace"]
    if ws:
        figs["workspace_polar"] = inside(fig_dir, "workspace_polar.png")
        figs["workspace_height"] = inside(fig_dir, "workspace_height.png")

        def polar_done(outcome):
            if outcome.error is not None:
                figs.pop("workspace_polar")
                figs["notes"].append(f"workspace map: {outcome.error}")
            else:
                figs["workspace_heights"] = outcome.value

        def height_done(outcome):
            if "workspace_polar" not in figs:  # no reachable layer: neither is shown
                figs.pop("workspace_height")
            elif outcome.error is not None:
                raise outcome.error
        plan.add(workspace_figures.workspace_polar, figs["workspace_polar"], ws,
                 figs["workspace_polar"], then=polar_done)
        plan.add(workspace_figures.workspace_height, figs["workspace_height"], ws,
                 figs["workspace_height"], then=height_done)
    m = results["scene"]["manipulator"]
    if m["leg"]["housing_length_mm"] > 0:  # an actuator leg: its profile drawn
        figs["leg_profile"] = inside(fig_dir, "leg_profile.png")
        plan.add(real_machine.leg_profile, figs["leg_profile"], m, figs["leg_profile"])
    figs["sweeps"] = {}
    for study in results["studies"]["lowest_modes"]:
        if study["sweep"]:
            path = inside(fig_dir, f"stiffness_sweep_{file_stem(study['case'], 'case name')}.png")
            plan.add(real_machine.stiffness_sweep, path, study, path)
            figs["sweeps"][study["case"]] = path
    figs["studies"] = study_figure_set(results, fig_dir, figs["notes"], plan)
    plan.draw(cache_dir, workers)
    for anchor in [a for a, shown in figs["studies"].items() if not shown]:
        del figs["studies"][anchor]  # every figure of the section failed (said in the notes)
    return figs


def mode_figures(results: Results, results_path: Path, i: int, fig_dir: Path,
                 notes: list[str], plan: _Plan) -> ModeFigures:
    """FEM solid (pyvista) and beam model (matplotlib) pictures of the paired modes."""
    from . import render3d

    case = results["cases"][i]
    name, fem = case["name"], case["fem"]
    stem = file_stem(name, "case name")
    pairs = sorted(case["pairs"], key=lambda p: p["fem_mode"])
    out = ModeFigures(pairs=[], fem_note=None)
    base, platform = joint_points(case)
    centre = platform_centre(case)
    size = max(float(max(base.max(0) - base.min(0))), float(platform[:, 2].max()))
    m = results["scene"]["manipulator"]
    radius = m["platform_radius_mm"] * 1e-3
    feet = base_circle_points(m)  # a 3-PRS's rails start there
    fem_paths: dict[int, Path] = {}
    if fem["vtu"]:
        modes = [p["fem_mode"] for p in pairs]
        fem_paths = {k: inside(fig_dir, f"mode_{stem}_fem_{k}.png") for k in modes}
        plate = render3d.Platform(platform, centre, radius, m["platform_thickness_mm"] * 1e-3,
                                  {k: platform_motion(fem, k) for k in modes})
        labels = {k: f"FEM mode {k}: {fem['frequencies_hz'][k - 1]:.2f} Hz" for k in modes}

        def rendered(outcome):
            if outcome.error is not None:
                raise ReportError(f"{name}: {outcome.error}") from None
            file_hz = outcome.value
            if file_hz and any(abs(file_hz[k - 1] / fem["frequencies_hz"][k - 1] - 1) > 1e-6
                               for k in modes if k - 1 < len(file_hz)):
                notes.append(f"{name}: the frequencies stored in {fem['vtu']} differ from "
                             f"results.json (mode file from another run?)")
        plan.add(render3d.render_modes, list(fem_paths.values()),
                 (results_path.parent / fem["vtu"]).resolve(), modes, labels, fem_paths,
                 platform=plate, then=rendered, errors=(render3d.RenderError,))
    else:
        out["fem_note"] = "results.json names no FEM mode file (fem.vtu) for this case."
    stations, shapes = leg_axis_shapes(case)
    for p in pairs:
        k, j = p["fem_mode"], p["analytical_mode"]
        item = ModePicture(fem_mode=k, analytical_mode=j, f_fem=p["f_fem_hz"],
                           f_an=p["f_analytical_hz"], mac=p["mac"], fem_png=fem_paths.get(k),
                           beam_png=None)
        if j <= shapes.shape[-1]:
            item["beam_png"] = inside(fig_dir, f"mode_{stem}_beam_{j}.png")
            plan.add(beam_mode, item["beam_png"], base, platform, centre, stations,
                     shapes[..., j - 1], platform_motion(case["analytical"], j), radius,
                     item["beam_png"], f"beam model mode {j}: {p['f_analytical_hz']:.2f} Hz",
                     0.1 * size, feet=feet)
        out["pairs"].append(item)
    return out
