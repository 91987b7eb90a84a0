"""Orchestration: results.json -> figures, report.html, report.pdf (all written atomically).

Everything is rendered into a staging directory beside the output directory, which is swapped
in whole only when the HTML and the PDF both exist (pipeline.outdir), so a failed or killed
render leaves the previous outputs (or nothing) and never a half-written report. Every number
printed in a table is looked up in results.json by a JSON pointer, which the table cell carries
as `data-src` (tests check them).
"""
from __future__ import annotations

import math
import time
from pathlib import Path

from jinja2 import Environment, FileSystemLoader, StrictUndefined

from . import figures, verdict
from .results import escape, joint_points, leg_axis_shapes, load_results, resolve

TEMPLATES = Path(__file__).resolve().parent / "templates"
PAPER_SECONDS = {"analytical": 0.82, "ansys": 6.16}
MINUS = "\u2212"
THIN = "\u2009"


class ReportError(RuntimeError):
    """The report could not be rendered (one-line message)."""


# ---------------------------------------------------------------- table cells
def _decimal(value: float, digits: int, signed: bool = False) -> str:
    text = f"{value:+.{digits}f}" if signed else f"{value:.{digits}f}"
    if text.lstrip("+-").strip("0.") == "":  # -0.00 -> 0.00
        text = f"{0.0:.{digits}f}"
    return text.replace("-", MINUS)


def _significant(value: float, figures_: int = 3) -> int:
    if value == 0 or not math.isfinite(value):
        return 2
    return max(0, figures_ - 1 - int(math.floor(math.log10(abs(value)))))


class Cells:
    """Table cells whose values come from the results document by JSON pointer."""

    def __init__(self, results: dict):
        self.results = results

    def num(self, pointer: str, digits: int | None = 2, scale: float = 1.0,
            signed: bool = False) -> dict:
        try:
            value = resolve(self.results, pointer)
        except (KeyError, IndexError, TypeError):
            value = None
        if value is None or isinstance(value, bool) or not isinstance(value, (int, float)):
            return _cell("–", "num missing")
        v = value * scale
        if isinstance(value, int) and digits is None and scale == 1:
            text = f"{value:,}".replace(",", THIN)
        else:
            d = _significant(v) if digits is None else digits
            text = _decimal(v, d, signed)
        return _cell(text, "num", pointer, None if scale == 1 else repr(scale))

    def text(self, pointer: str | None = None, literal: str | None = None,
             cls: str = "text") -> dict:
        if pointer is not None:
            try:
                value = resolve(self.results, pointer)
            except (KeyError, IndexError, TypeError):
                value = None
            if value is None:
                return _cell("–", cls)
            return _cell(str(value), cls, pointer)
        return _cell(literal or "", cls)


def _cell(text: str, cls: str = "text", src: str | None = None, scale: str | None = None,
          colspan: int | None = None, suffix: str = "") -> dict:
    return {"text": text, "cls": cls, "src": src, "scale": scale, "colspan": colspan,
            "suffix": suffix}


def _head(*labels, spans=None) -> list[dict]:
    spans = spans or [1] * len(labels)
    return [{"text": t, "colspan": s} for t, s in zip(labels, spans)]


# ---------------------------------------------------------------- tables
def scene_tables(results: dict, c: Cells) -> dict:
    scene = results["scene"]
    m = scene.get("manipulator", {})
    rows = []
    labels = [
        ("base_radius_mm", "base radius r1", "mm", 1), ("platform_radius_mm",
                                                         "platform radius r2", "mm", 1),
        ("leg_diameter_mm", "leg diameter d", "mm", 1),
        ("platform_thickness_mm", "platform thickness h", "mm", 1),
        ("youngs_modulus_gpa", "Young's modulus E", "GPa", 1),
        ("shear_modulus_gpa", "shear modulus G", "GPa", 1),
        ("poisson_ratio", "Poisson's ratio ν", "–", 3),
        ("density_kg_m3", "density ρ", "kg/m³", 0),
        ("s_joint_max_deg", "S-joint limit α_max", "deg", 1),
        ("r_joint_max_deg", "R-joint limit β_max", "deg", 1),
    ]
    for key, label, unit, digits in labels:
        if key in m:
            rows.append([c.text(literal=label), c.num(f"/scene/manipulator/{key}", digits),
                         c.text(literal=unit, cls="unit")])
    for i, _ in enumerate(m.get("leg_angles_deg", [])):
        rows.append([c.text(literal=f"leg {i + 1} angle on the base"),
                     c.num(f"/scene/manipulator/leg_angles_deg/{i}", 1),
                     c.text(literal="deg", cls="unit")])
    for i, label in enumerate(("actuator minimum L_min", "actuator maximum L_max")):
        if m.get("actuator_range_mm"):
            rows.append([c.text(literal=label), c.num(f"/scene/manipulator/actuator_range_mm/{i}",
                                                      0), c.text(literal="mm", cls="unit")])
    if "platform_shape" in m:
        rows.append([c.text(literal="platform shape"),
                     c.text("/scene/manipulator/platform_shape"), c.text(literal="")])
    manipulator = {"head": [_head("parameter", "value", "unit")], "rows": rows,
                   "cls": "params"}

    fid = []
    an, fe = scene.get("analytical", {}), scene.get("fem", {})
    for key, label in (("elements", "elements per leg s"), ("modes", "modes compared")):
        if key in an:
            fid.append([c.text(literal=f"analytical: {label}"),
                        c.num(f"/scene/analytical/{key}", None)])
    for key, label in (("beam", "beam theory"), ("platform_inertia", "platform inertia")):
        if key in an:
            fid.append([c.text(literal=f"analytical: {label}"), c.text(f"/scene/analytical/{key}")])
    if "mesh_size_mm" in fe:
        fid.append([c.text(literal="FEM: mesh size h (mm)"),
                    c.num("/scene/fem/mesh_size_mm", 1)])
    for i, _ in enumerate(fe.get("refinement_mm") or []):
        fid.append([c.text(literal=f"FEM: refinement size {i + 1} (mm)"),
                    c.num(f"/scene/fem/refinement_mm/{i}", 1)])
    for key, label in (("platform", "platform"), ("coupling", "joint coupling")):
        if key in fe:
            fid.append([c.text(literal=f"FEM: {label}"), c.text(f"/scene/fem/{key}")])
    fidelity = {"head": [_head("setting", "value")], "rows": fid, "cls": "params"}

    calibrated = {"head": [_head("parameter", "value", "why")], "cls": "calibrated",
                  "rows": [[c.text(f"/scene/calibrated/{i}/name"),
                            c.text(f"/scene/calibrated/{i}/value", cls="text nowrap"),
                            c.text(f"/scene/calibrated/{i}/reason", cls="text reason")]
                           for i, _ in enumerate(scene.get("calibrated") or [])]}

    poses_rows, joints_rows = [], []
    for i, case in enumerate(results["cases"]):
        p = f"/cases/{i}/pose"
        poses_rows.append([c.text(f"/cases/{i}/name"), c.num(f"{p}/height_mm", 1),
                           c.text(f"{p}/height_origin"), c.num(f"{p}/azimuth_deg", 1),
                           c.num(f"{p}/tilt_deg", 1)]
                          + [c.num(f"{p}/centre_mm/{k}", 1) for k in range(3)]
                          + [c.num(f"{p}/leg_lengths_mm/{k}", 1) for k in range(3)])
        joints_rows.append([c.text(f"/cases/{i}/name")]
                           + [c.num(f"{p}/s_joint_angles_deg/{k}", 2) for k in range(3)]
                           + [c.num(f"{p}/r_joint_angles_deg/{k}", 2) for k in range(3)])
    poses = {"cls": "poses", "rows": poses_rows, "head": [
        _head("case", "height z", "", "azimuth φ", "tilt θ", "platform centre o (mm)",
              "leg lengths L_i (mm)", spans=[1, 1, 1, 1, 1, 3, 3]),
        _head("", "(mm)", "origin", "(deg)", "(deg)", "x", "y", "z", "L1", "L2", "L3")]}
    joints = {"cls": "joints", "rows": joints_rows, "head": [
        _head("case", "S-joint angles α_i (deg)", "R-joint angles β_i (deg)", spans=[1, 3, 3]),
        _head("", "α1", "α2", "α3", "β1", "β2", "β3")]}

    env = results["environment"]
    env_rows = [[c.text(literal=label), c.text(f"/environment/{key}")]
                for key, label in (("date", "date of the run"), ("python", "Python"),
                                   ("platform", "platform"), ("machine", "machine"))
                if key in env]
    if "cpu_count" in env:
        env_rows.append([c.text(literal="CPU cores"), c.text("/environment/cpu_count")])
    for name, version in (env.get("versions") or {}).items():
        env_rows.append([c.text(literal=name),
                         c.text(f"/environment/versions/{escape(name)}") if version
                         else c.text(literal="not installed")])
    environment = {"head": [_head("item", "value")], "rows": env_rows, "cls": "params env"}
    return {"manipulator": manipulator, "fidelity": fidelity, "calibrated": calibrated,
            "poses": poses, "joints": joints, "environment": environment}


def comparison_table(results: dict, i: int, c: Cells) -> dict:
    """The Table I reproduction of case i (paper rows where the case has them)."""
    case = results["cases"][i]
    paper = case.get("paper") or {}
    has_paper = bool(paper)
    has_ref = any("fem_estimated_error_percent" in p for p in case["pairs"])
    has_vs_ref = any("error_vs_reference_percent" in p for p in case["pairs"])
    head = ["FEM mode", "model mode"]
    if has_paper:
        head += ["paper FEA (Hz)", "paper theory (Hz)", "paper error (%)"]
    head += ["our FEM (Hz)"]
    if has_ref:
        head += ["FEM est. error (%)"]
    head += ["our analytical (Hz)", "error vs FEM (%)"]
    if has_vs_ref:
        head += ["error vs FEM limit (%)"]
    head += ["MAC"]
    rows = []
    order = sorted(range(len(case["pairs"])), key=lambda j: case["pairs"][j]["fem_mode"])
    for j in order:
        pair = case["pairs"][j]
        k = pair["fem_mode"] - 1
        q = f"/cases/{i}/pairs/{j}"
        mark = "†" if pair.get("repeated") else ""
        first = c.num(f"{q}/fem_mode", None)
        first["suffix"] = mark
        row = [first, c.num(f"{q}/analytical_mode", None)]
        if has_paper:
            row += [c.num(f"/cases/{i}/paper/fea_hz/{k}", 2),
                    c.num(f"/cases/{i}/paper/theory_hz/{k}", 2),
                    c.num(f"/cases/{i}/paper/error_percent/{k}", 2, signed=True)]
        row += [c.num(f"{q}/f_fem_hz", 2)]
        if has_ref:
            row += [c.num(f"{q}/fem_estimated_error_percent", 3)]
        row += [c.num(f"{q}/f_analytical_hz", 2), c.num(f"{q}/error_percent", 2, signed=True)]
        if has_vs_ref:
            row += [c.num(f"{q}/error_vs_reference_percent", 2, signed=True)]
        row += [c.num(f"{q}/mac", 3)]
        rows.append(row)
    return {"head": [_head(*head)], "rows": rows, "cls": "compare",
            "repeated": any(p.get("repeated") for p in case["pairs"])}


def variants_table(results: dict, i: int, c: Cells) -> dict | None:
    case = results["cases"][i]
    models = case.get("models") or {}
    if not models:
        return None
    labels = list(models)
    head1 = _head("FEM", "our FEM", *labels, spans=[1, 1] + [2] * len(labels))
    head2 = _head("mode", "(Hz)", *(["(Hz)", "error (%)"] * len(labels)))
    rows = []
    order = sorted(range(len(case["pairs"])), key=lambda j: case["pairs"][j]["fem_mode"])
    for j in order:
        mode = case["pairs"][j]["fem_mode"]
        row = [c.num(f"/cases/{i}/pairs/{j}/fem_mode", None),
               c.num(f"/cases/{i}/pairs/{j}/f_fem_hz", 2)]
        for label in labels:
            mp = models[label].get("pairs") or []
            jj = next((n for n, p in enumerate(mp) if p["fem_mode"] == mode), None)
            q = f"/cases/{i}/models/{escape(label)}/pairs/{jj}"
            if jj is None:
                row += [c.text(literal="–", cls="num missing")] * 2
            else:
                row += [c.num(f"{q}/f_analytical_hz", 2),
                        c.num(f"{q}/error_percent", 2, signed=True)]
        rows.append(row)
    return {"head": [head1, head2], "rows": rows, "cls": "variants"}


def _refinement_error_max(ref: dict) -> tuple[str, float] | None:
    """(key, scale to per cent) of the per-size worst estimated error, whichever is present."""
    if ref.get("estimated_error_percent_max"):
        return "estimated_error_percent_max", 1.0
    if ref.get("max_relative_error"):
        return "max_relative_error", 100.0
    return None


def refinement_table(results: dict, i: int, c: Cells) -> dict | None:
    ref = results["cases"][i].get("fem_refinement")
    if not ref or not ref.get("sizes_m"):
        return None
    n = len(ref["frequencies_hz"][0])
    q = f"/cases/{i}/fem_refinement"
    eff = bool(ref.get("effective_sizes_m"))
    head = ["h (mm)"] + (["h eff. (mm)"] if eff else []) + ["dofs", "time (s)"]
    head += [f"f{k + 1} (Hz)" for k in range(n)]
    err = _refinement_error_max(ref)
    if err:
        head.append("est. error max (%)")
    lead = len(head) - n - (1 if err else 0)
    rows = []
    for r, _ in enumerate(ref["sizes_m"]):
        row = [c.num(f"{q}/sizes_m/{r}", 1, scale=1000.0)]
        if eff:
            row.append(c.num(f"{q}/effective_sizes_m/{r}", 1, scale=1000.0))
        row += [c.num(f"{q}/dofs/{r}", None) if ref.get("dofs") else c.text(literal="–"),
                c.num(f"{q}/seconds/{r}", 1) if ref.get("seconds") else c.text(literal="–")]
        row += [c.num(f"{q}/frequencies_hz/{r}/{k}", 2) for k in range(n)]
        if err:
            row.append(c.num(f"{q}/{err[0]}/{r}", 3, scale=err[1]))
        rows.append(row)

    def extra(label: str, cells: list[dict]) -> list[dict]:
        row = [c.text(literal=label, cls="text label")] + [c.text(literal="")] * (lead - 1)
        return row + cells + ([c.text(literal="")] if err else [])

    if ref.get("extrapolated_hz"):
        rows.append(extra("h → 0", [c.num(f"{q}/extrapolated_hz/{k}", 2) for k in range(n)]))
    order = ref.get("observed_order")
    if isinstance(order, list):
        rows.append(extra("order p", [c.num(f"{q}/observed_order/{k}", 2) for k in range(n)]))
    status = ref.get("status")
    if isinstance(status, list) and any(x != "ok" for x in status):
        rows.append(extra("status", [c.text(f"{q}/status/{k}", cls="text small")
                                     for k in range(n)]))
    return {"head": [_head(*head)], "rows": rows, "cls": "refinement",
            "order": None if isinstance(order, list) or order is None
            else c.num(f"{q}/observed_order", 2)}


def fem_variants_table(results: dict, i: int, c: Cells) -> dict | None:
    variants = results["cases"][i].get("fem_variants") or {}
    if not variants:
        return None
    n = len(results["cases"][i]["fem"]["frequencies_hz"])
    rows = []
    for label, v in variants.items():
        q = f"/cases/{i}/fem_variants/{escape(label)}"
        if "error" in v:
            rows.append({"label": label, "error": c.text(f"{q}/error"), "cells": None})
            continue
        cells = [c.text(literal=f"{label}: f (Hz)")]
        cells += [c.num(f"{q}/frequencies_hz/{k}", 2) for k in range(n)]
        rows.append({"label": label, "error": None, "cells": cells})
        if v.get("shift_percent"):
            cells = [c.text(literal="shift vs our FEM (%)", cls="text sub")]
            cells += [c.num(f"{q}/shift_percent/{k}", 2, signed=True) for k in range(n)]
            rows.append({"label": label, "error": None, "cells": cells})
    return {"head": [_head("FEM idealisation", *[f"f{k + 1}" for k in range(n)])],
            "rows": rows, "cls": "femvariants", "width": n + 1}


def speed_table(results: dict, c: Cells) -> dict | None:
    with_data = [(i, case) for i, case in enumerate(results["cases"]) if case.get("speed_vs_error")]
    if not with_data:
        return None
    settings: list[tuple[str, str]] = []
    for _, case in with_data:
        for e in case["speed_vs_error"]:
            key = (e["model"], e["setting"])
            if key not in settings:
                settings.append(key)
    head1 = _head("model", "setting", *[case["name"] for _, case in with_data],
                  spans=[1, 1] + [2] * len(with_data))
    head2 = _head("", "", *(["time (s)", "worst error (%)"] * len(with_data)))
    rows = []
    for model, setting in settings:
        row = [c.text(literal=model), c.text(literal=setting)]
        for i, case in with_data:
            j = next((n for n, e in enumerate(case["speed_vs_error"])
                      if (e["model"], e["setting"]) == (model, setting)), None)
            if j is None:
                row += [c.text(literal="–", cls="num missing")] * 2
            else:
                row += [c.num(f"/cases/{i}/speed_vs_error/{j}/seconds", None),
                        c.num(f"/cases/{i}/speed_vs_error/{j}/worst_error_percent", 2)]
        rows.append(row)
    return {"head": [head1, head2], "rows": rows, "cls": "speed"}


def conventions_table(results: dict, c: Cells) -> dict | None:
    conv = results["studies"].get("case2_conventions")
    if not conv:
        return None
    n = max((len(e.get("frequencies_hz") or []) for e in conv), default=0)
    rows = []
    best = min((e["worst_percent"] for e in conv if e.get("worst_percent") is not None),
               default=None)
    for j, e in enumerate(conv):
        q = f"/studies/case2_conventions/{j}"
        row = [c.text(f"{q}/reading", cls="text reading"), c.num(f"{q}/azimuth_deg", 1),
               c.num(f"{q}/tilt_deg", 1)]
        if e.get("frequencies_hz") is None:
            row += [c.text(literal=e.get("note", "not reachable"), cls="text note")]
            row[-1]["colspan"] = n + 1
        else:
            row += [c.num(f"{q}/deviation_percent/{k}", 2, signed=True) for k in range(n)]
            row.append(c.num(f"{q}/worst_percent", 2))
            if e["worst_percent"] == best:
                row[-1]["cls"] += " best"
        rows.append(row)
    head = _head("reading of (φ, θ) = (10°, −12°)", "azimuth φ (deg)", "tilt θ (deg)",
                 *[f"f{k + 1} dev. (%)" for k in range(n)], "worst (%)")
    return {"head": [head], "rows": rows, "cls": "conventions"}


def calibration_table(results: dict, c: Cells) -> dict | None:
    cal = results["studies"].get("height_calibration")
    if not cal:
        return None
    q = "/studies/height_calibration"
    rows = [[c.text(literal="height recomputed from the code"),
             c.num(f"{q}/computed_height_mm", 1), c.text(literal="mm", cls="unit")],
            [c.text(literal="height in the scene"), c.num(f"{q}/scene_height_mm", 1),
             c.text(literal="mm", cls="unit")],
            [c.text(literal="worst deviation from the paper's Case 1 theory row"),
             c.num(f"{q}/worst_deviation_percent", 2), c.text(literal="%", cls="unit")]]
    for k, _ in enumerate(cal.get("deviation_percent") or []):
        rows.append([c.text(literal=f"deviation of f{k + 1}", cls="text sub"),
                     c.num(f"{q}/deviation_percent/{k}", 2, signed=True),
                     c.text(literal="%", cls="unit")])
    return {"head": [_head("", "value", "unit")], "rows": rows, "cls": "params"}


# ---------------------------------------------------------------- figures
def _reference(case: dict) -> tuple[list[float], str]:
    if case.get("fem_reference_hz"):
        return case["fem_reference_hz"], "FEM limit h → 0"
    return case["fem"]["frequencies_hz"], "our FEM"


def main_cases(results: dict) -> list[dict]:
    """The cases with paper rows (all cases if none has them): the report's main subject."""
    return [c for c in results["cases"] if c.get("paper")] or results["cases"]


def make_figures(results: dict, results_path: Path, fig_dir: Path) -> dict:
    """Draw every figure into fig_dir; return what the template needs to show them."""
    from . import render3d

    figs: dict = {"cases": {}, "notes": []}
    scene = results["scene"]
    for i, case in enumerate(results["cases"]):
        name = case["name"]
        entry: dict = {}
        if case.get("element_convergence"):
            ref, label = _reference(case)
            path = fig_dir / f"element_convergence_{name}.png"
            figures.element_convergence(case["element_convergence"], ref, label, path)
            entry["element_convergence"] = (path, label)
        if case.get("fem_refinement") and case["fem_refinement"].get("sizes_m"):
            path = fig_dir / f"fem_refinement_{name}.png"
            figures.fem_refinement(case["fem_refinement"], path, case["fem"].get("mesh_size_m"))
            entry["fem_refinement"] = path
        if case.get("mac_matrix") and case in main_cases(results):
            path = fig_dir / f"mac_{name}.png"
            figures.mac_matrix(case["mac_matrix"], case["pairs"], path)
            entry["mac"] = path
        if case in main_cases(results):
            entry["modes"] = _mode_figures(results, results_path, i, fig_dir, render3d, figs)
        else:
            entry["modes"] = {"pairs": [], "fem_note": None, "beam_note": None}
        figs["cases"][name] = entry
    speed = {c["name"]: c["speed_vs_error"] for c in results["cases"] if c.get("speed_vs_error")}
    if speed:
        figs["speed"] = fig_dir / "speed_vs_error.png"
        figures.speed_vs_error(speed, figs["speed"])
    ws = results["studies"].get("workspace")
    if ws and ws.get("frequencies_hz"):
        figs["workspace_polar"] = fig_dir / "workspace_polar.png"
        try:
            figs["workspace_heights"] = figures.workspace_polar(ws, figs["workspace_polar"])
        except ValueError as exc:
            figs.pop("workspace_polar")
            figs["notes"].append(f"workspace map: {exc}")
        else:
            figs["workspace_height"] = fig_dir / "workspace_height.png"
            figures.workspace_height(ws, figs["workspace_height"])
    return figs


def _mode_figures(results: dict, results_path: Path, i: int, fig_dir: Path, render3d,
                  figs: dict) -> dict:
    """FEM solid (pyvista) and beam model (matplotlib) pictures of the paired modes."""
    case = results["cases"][i]
    name = case["name"]
    pairs = sorted(case["pairs"], key=lambda p: p["fem_mode"])
    fem_hz = case["fem"]["frequencies_hz"]
    out = {"pairs": [], "fem_note": None, "beam_note": None}
    base, platform = joint_points(case)
    size = max(float(max(base.max(0) - base.min(0))), float(platform[:, 2].max()))
    vtu = case["fem"].get("vtu")
    fem_paths = {}
    if vtu:
        path = (results_path.parent / vtu).resolve()
        modes = [p["fem_mode"] for p in pairs]
        labels = {k: f"FEM mode {k}: {fem_hz[k - 1]:.2f} Hz" for k in modes}
        fem_paths = {k: fig_dir / f"mode_{name}_fem_{k}.png" for k in modes}
        try:
            m = results["scene"].get("manipulator", {})
            plate = (platform, m.get("platform_radius_mm", 200.0) * 1e-3,
                     m.get("platform_thickness_mm", 20.0) * 1e-3)
            file_hz = render3d.render_modes(path, modes, labels, fem_paths, platform=plate)
        except render3d.RenderError as exc:
            raise ReportError(f"{name}: {exc}") from None
        if file_hz and any(abs(file_hz[k - 1] / fem_hz[k - 1] - 1) > 1e-6
                           for k in modes if k - 1 < len(file_hz)):
            figs["notes"].append(f"{name}: the frequencies stored in {vtu} differ from "
                                 f"results.json (mode file from another run?)")
    else:
        out["fem_note"] = "results.json names no FEM mode file (fem.vtu) for this case."
    shapes = leg_axis_shapes(case)
    if shapes is None:
        out["beam_note"] = ("results.json carries no beam-model shapes "
                            "(analytical.leg_axis_shapes) for this case.")
    radius = results["scene"].get("manipulator", {}).get("platform_radius_mm", 200.0) * 1e-3
    for p in pairs:
        k, j = p["fem_mode"], p["analytical_mode"]
        item = {"fem_mode": k, "analytical_mode": j, "f_fem": fem_hz[k - 1] if k - 1 < len(
            fem_hz) else p["f_fem_hz"], "f_an": p["f_analytical_hz"], "mac": p["mac"],
            "fem_png": fem_paths.get(k), "beam_png": None}
        if shapes is not None and j - 1 < shapes[1].shape[-1]:
            stations, arr = shapes
            png = fig_dir / f"mode_{name}_beam_{j}.png"
            figures.beam_mode(base, platform, stations, arr[..., j - 1], radius, png,
                              f"beam model mode {j}: {p['f_analytical_hz']:.2f} Hz",
                              0.1 * size)
            item["beam_png"] = png
        out["pairs"].append(item)
    return out


# ---------------------------------------------------------------- document
def context(results: dict, results_path: Path, figs: dict, fig_dir: Path) -> dict:
    c = Cells(results)
    rel = lambda p: None if p is None else f"figures/{Path(p).name}"  # noqa: E731
    cases = []
    for i, case in enumerate(results["cases"]):
        f = figs["cases"][case["name"]]
        modes = f["modes"]
        cases.append({
            "index": i, "case": case, "name": case["name"],
            "description": case.get("description") or case["name"],
            "paper": bool(case.get("paper")),
            "verdict": verdict.case_verdict(case),
            "compare": comparison_table(results, i, c),
            "variants": variants_table(results, i, c),
            "fem_variants": fem_variants_table(results, i, c),
            "refinement": refinement_table(results, i, c),
            "fig_element": rel(f.get("element_convergence", (None,))[0]),
            "fig_element_ref": f.get("element_convergence", (None, None))[1],
            "fig_refinement": rel(f.get("fem_refinement")),
            "fig_mac": rel(f.get("mac")),
            "mode_pairs": [dict(m, fem_png=rel(m["fem_png"]), beam_png=rel(m["beam_png"]))
                           for m in modes["pairs"]],
            "fem_note": modes["fem_note"], "beam_note": modes["beam_note"],
        })
    main = [x for x in cases if x["paper"]] or cases
    other = [x for x in cases if x not in main]
    ws = results["studies"].get("workspace")
    return {
        "results": results, "scene": results["scene"], "env": results["environment"],
        "profile": results.get("profile"), "fixture_note": results.get("fixture_note"),
        "results_name": results_path.name,
        "headline": verdict.headline(results),
        "cases": cases, "main_cases": main, "other_cases": other,
        "tables": scene_tables(results, c),
        "speed_table": speed_table(results, c),
        "conventions": conventions_table(results, c),
        "calibration": calibration_table(results, c),
        "calibration_settings": (results["studies"].get("height_calibration") or {}).get(
            "settings"),
        "fig_speed": rel(figs.get("speed")),
        "fig_ws_polar": rel(figs.get("workspace_polar")),
        "fig_ws_height": rel(figs.get("workspace_height")),
        "ws_heights": figs.get("workspace_heights"),
        "ws_settings": ws.get("settings") if ws else None,
        "notes": figs["notes"],
        "paper_seconds": PAPER_SECONDS,
        "generated": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
    }


def _align(ctx) -> None:
    """Give every table the alignment of its columns (from the first body row)."""
    def visit(obj):
        if isinstance(obj, dict):
            if "rows" in obj and "head" in obj:
                first = next((r for r in obj["rows"] if isinstance(r, list)), None)
                if first is None:
                    first = next((r["cells"] for r in obj["rows"]
                                  if isinstance(r, dict) and r.get("cells")), [])
                align = ["right" if "num" in c["cls"] else "left" for c in first]
                if len(obj["rows"]) <= 16:  # short tables stay on one page with caption
                    obj["cls"] = obj.get("cls", "") + " keep-table"
                for row in obj["head"]:
                    col = 0
                    for h in row:
                        span = h.get("colspan") or 1
                        h["cls"] = "group" if span > 1 else (
                            align[col] if col < len(align) else "")
                        col += span
            for v in obj.values():
                visit(v)
        elif isinstance(obj, list):
            for v in obj:
                visit(v)
    visit({k: v for k, v in ctx.items() if k not in ("results", "scene", "env")})


def render_html(ctx: dict) -> str:
    _align(ctx)
    env = Environment(loader=FileSystemLoader(TEMPLATES), autoescape=True,
                      undefined=StrictUndefined, trim_blocks=True, lstrip_blocks=True)
    env.globals["css"] = (TEMPLATES / "report.css").read_text(encoding="utf-8")
    return env.get_template("report.html.j2").render(**ctx)


def render_pdf(html: str, base: Path, target: Path) -> None:
    import logging

    from weasyprint import HTML

    logging.getLogger("weasyprint").setLevel(logging.ERROR)
    logging.getLogger("fontTools").setLevel(logging.ERROR)
    HTML(string=html, base_url=str(base)).write_pdf(str(target))


def build_report(results_json_path, out_dir) -> tuple[Path, Path]:
    """Write out_dir/report.html, out_dir/report.pdf and out_dir/figures/ from a results file.

    The new out_dir is built whole beside it (its other files copied, then the report
    rendered) and swapped in as one step (pipeline.outdir): never a temporary folder inside
    out_dir, never a report of one run beside the figures of another. ValueError (naming the
    path) for a missing or malformed results file, ReportError when a picture or the PDF
    cannot be rendered; either way out_dir is left as it was.
    """
    from common.worker import stoppable
    from pipeline.outdir import staged_output

    results_path = Path(results_json_path)
    out = Path(out_dir)
    load_results(results_path)  # a bad results file is refused before out_dir is locked
    with staged_output(out, keep=lambda name: name not in REPORT_ENTRIES
                       and not name.startswith(LEGACY_TEMPORARIES)) as stage:
        stoppable(render_report, results_path, stage)  # Ctrl-C / SIGTERM stop it at once
    return out / "report.html", out / "report.pdf"


REPORT_ENTRIES = ("report.html", "report.pdf", "figures")
LEGACY_TEMPORARIES = (".report-", ".figures-old-")  # left inside out/ by earlier versions


def render_report(results_json_path, directory) -> tuple[Path, Path]:
    """Render report.html, report.pdf and figures/ into `directory`, a staging directory that
    the caller swaps in whole (nothing here is visible until then)."""
    results_path = Path(results_json_path)
    target = Path(directory)
    results = load_results(results_path)
    fig_dir = target / "figures"
    fig_dir.mkdir()
    try:
        figs = make_figures(results, results_path, fig_dir)
        html = render_html(context(results, results_path, figs, fig_dir))
    except (ReportError, ValueError):
        raise
    except (KeyError, IndexError, TypeError) as exc:
        raise ValueError(f"{results_path}: unexpected content "
                         f"({type(exc).__name__}: {exc})") from None
    except Exception as exc:  # noqa: BLE001
        raise ReportError(f"report rendering failed ({type(exc).__name__}: "
                          f"{' '.join(str(exc).split())})") from None
    (target / "report.html").write_text(html, encoding="utf-8")
    try:
        render_pdf(html, target, target / "report.pdf")
    except Exception as exc:  # noqa: BLE001  (weasyprint raises anything)
        raise ReportError(f"PDF rendering failed ({type(exc).__name__}: "
                          f"{' '.join(str(exc).split())})") from None
    return target / "report.html", target / "report.pdf"
