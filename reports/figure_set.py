"""Which figures the report draws, from which results, into which files: every figure of
every case and study, and what the template needs to show them."""
from __future__ import annotations

from pathlib import Path

from . import figures, validation, workspace_figures
from .beam_figure import beam_mode
from .results import joint_points, leg_axis_shapes, platform_centre, platform_motion


class ReportError(RuntimeError):
    """The report could not be rendered (one-line message)."""


def has_paper(results: dict) -> bool:
    """Do the results carry the paper's data (any case with its rows)?"""
    return any(c["paper"] for c in results["cases"])


def main_cases(results: dict) -> list[dict]:
    """The cases with paper rows (all cases if none has them): the report's main subject."""
    return [c for c in results["cases"] if c["paper"]] or results["cases"]


def reference(case: dict) -> tuple[list[float], str]:
    """The best FEM frequencies of a case and their name."""
    if case["fem_reference_hz"]:
        return case["fem_reference_hz"], "FEM limit h → 0"
    return case["fem"]["frequencies_hz"], "our FEM"


def make_figures(results: dict, results_path: Path, fig_dir: Path) -> dict:
    """Draw every figure into fig_dir; return what the template needs to show them."""
    figs: dict = {"cases": {}, "notes": []}
    main = main_cases(results)
    for i, case in enumerate(results["cases"]):
        name = case["name"]
        entry: dict = {"modes": {"pairs": [], "fem_note": None}}
        if case["element_convergence"]:
            ref, label = reference(case)
            path = fig_dir / f"element_convergence_{name}.png"
            figures.element_convergence(case["element_convergence"], ref, label, path)
            entry["element_convergence"] = (path, label)
        if case["fem_refinement"]:
            path = fig_dir / f"fem_refinement_{name}.png"
            figures.fem_refinement(case["fem_refinement"], path, case["fem"]["mesh_size_m"])
            entry["fem_refinement"] = path
        if case in main:
            entry["mac"] = fig_dir / f"mac_{name}.png"
            figures.mac_matrix(case["mac_matrix"], case["pairs"], entry["mac"])
            entry["modes"] = mode_figures(results, results_path, i, fig_dir, figs["notes"])
        figs["cases"][name] = entry
    speed = {c["name"]: c["speed_vs_error"] for c in results["cases"] if c["speed_vs_error"]}
    if speed:
        figs["speed"] = fig_dir / "speed_vs_error.png"
        figures.speed_vs_error(speed, figs["speed"], paper=has_paper(results))
    wv = results["studies"]["workspace_validation"]
    if wv and wv["worst_pose"]:
        figs["validation_map"] = fig_dir / "workspace_validation.png"
        try:
            validation.error_maps(results, figs["validation_map"])
        except ValueError as exc:
            figs.pop("validation_map")
            figs["notes"].append(f"workspace validation map: {exc}")
    ws = results["studies"]["workspace"]
    if ws:
        figs["workspace_polar"] = fig_dir / "workspace_polar.png"
        try:
            figs["workspace_heights"] = workspace_figures.workspace_polar(
                ws, figs["workspace_polar"])
        except ValueError as exc:
            figs.pop("workspace_polar")
            figs["notes"].append(f"workspace map: {exc}")
        else:
            figs["workspace_height"] = fig_dir / "workspace_height.png"
            workspace_figures.workspace_height(ws, figs["workspace_height"])
    return figs


def mode_figures(results: dict, results_path: Path, i: int, fig_dir: Path,
                 notes: list[str]) -> dict:
    """FEM solid (pyvista) and beam model (matplotlib) pictures of the paired modes."""
    from . import render3d

    case = results["cases"][i]
    name, fem = case["name"], case["fem"]
    pairs = sorted(case["pairs"], key=lambda p: p["fem_mode"])
    out = {"pairs": [], "fem_note": None}
    base, platform = joint_points(case)
    centre = platform_centre(case)
    size = max(float(max(base.max(0) - base.min(0))), float(platform[:, 2].max()))
    m = results["scene"]["manipulator"]
    radius = m["platform_radius_mm"] * 1e-3
    fem_paths = {}
    if fem["vtu"]:
        modes = [p["fem_mode"] for p in pairs]
        fem_paths = {k: fig_dir / f"mode_{name}_fem_{k}.png" for k in modes}
        plate = render3d.Platform(platform, centre, radius, m["platform_thickness_mm"] * 1e-3,
                                  {k: platform_motion(fem, k) for k in modes})
        labels = {k: f"FEM mode {k}: {fem['frequencies_hz'][k - 1]:.2f} Hz" for k in modes}
        try:
            file_hz = render3d.render_modes((results_path.parent / fem["vtu"]).resolve(),
                                            modes, labels, fem_paths, platform=plate)
        except render3d.RenderError as exc:
            raise ReportError(f"{name}: {exc}") from None
        if file_hz and any(abs(file_hz[k - 1] / fem["frequencies_hz"][k - 1] - 1) > 1e-6
                           for k in modes if k - 1 < len(file_hz)):
            notes.append(f"{name}: the frequencies stored in {fem['vtu']} differ from "
                         f"results.json (mode file from another run?)")
    else:
        out["fem_note"] = "results.json names no FEM mode file (fem.vtu) for this case."
    stations, shapes = leg_axis_shapes(case)
    for p in pairs:
        k, j = p["fem_mode"], p["analytical_mode"]
        item = {"fem_mode": k, "analytical_mode": j, "f_fem": p["f_fem_hz"],
                "f_an": p["f_analytical_hz"], "mac": p["mac"], "fem_png": fem_paths.get(k),
                "beam_png": None}
        if j <= shapes.shape[-1]:
            item["beam_png"] = fig_dir / f"mode_{name}_beam_{j}.png"
            beam_mode(base, platform, centre, stations, shapes[..., j - 1],
                      platform_motion(case["analytical"], j), radius, item["beam_png"],
                      f"beam model mode {j}: {p['f_analytical_hz']:.2f} Hz", 0.1 * size)
        out["pairs"].append(item)
    return out
