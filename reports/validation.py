"""The report's fidelity and workspace-validation parts: what the scene asked, what the run
chose, and how the chosen model's error is spread over the workspace (tables, the error maps,
and the sentences quoted in the summary). Values from results.json only."""
from __future__ import annotations

import math
from pathlib import Path
from typing import cast

import numpy as np
from matplotlib.projections.polar import PolarAxes

from results import Results, ValidationPose, WorkspaceValidation

from .cells import Cells, cell, head
from .figures import WIDTH, plt, save
from .results import escape


def fidelity_table(results: Results, c: Cells) -> dict:
    f = "/fidelity"
    a, m = f"{f}/analytical", f"{f}/fem"
    fid = results["fidelity"]
    rows = [
        [c.text(literal="compared modes"), c.num(f"{f}/modes", None), c.text(literal="")],
        [c.text(literal="tolerance (%)"), c.num(f"{f}/tolerance_percent", 2),
         c.text(literal="largest |error| accepted on each mode, vs the converged FEM")],
        [c.text(literal="analytical model"), c.text(f"{a}/setting"),
         c.text(literal="chosen by measurement" if fid["analytical"]["chosen"]
                else "the scene's own [analytical], checked")],
        [c.text(literal="its worst error (%)"), c.num(f"{a}/worst_error_percent", 2),
         c.text(literal="over every case and the workspace study's worst pose")],
        [c.text(literal="its time per pose (ms)"), c.num(f"{a}/seconds_per_pose", 3, 1e3),
         c.text(literal="median of repeated runs on this machine")],
        *_batched_rows(fid["analytical"], a, c),
        [c.text(literal="FEM element size (mm)"), c.num(f"{m}/mesh_size_mm", 1),
         c.text(literal="chosen by measurement" if fid["fem"]["chosen"]
                else "the scene's own mesh_size_mm, checked")],
        [c.text(literal="FEM estimated error (%)"), c.num(f"{m}/estimated_error_percent", 3),
         c.text(literal="Richardson, worst over cases and modes")],
        [c.text(literal="tolerance met"), cell("yes" if fid["met"] else "NO", "text"),
         c.text(literal="")],
    ]
    return {"head": [head("", "value", "")], "rows": rows, "cls": "fidelity"}


def _batched_rows(choice, a: str, c: Cells) -> list:
    """The chosen solid legs as maps solve them, and the error that costs (issue 51)."""
    if not choice.get("batched"):
        return []
    q = f"{a}/batched"
    return [
        [c.text(literal="its map model: modes a leg part"), c.num(f"{q}/part_modes", None),
         c.text(literal="each part's interior reduced to its own modes (Craig-Bampton), "
                "as few as this machine needs")],
        [c.text(literal="its map model: coordinates a pose"), c.num(f"{q}/coordinates", None),
         c.text(literal="what a map, a minimum or a sample solves")],
        [c.text(literal="its per-pose model: coordinates"),
         c.num(f"{q}/coordinates_kept", None),
         c.text(literal="every station of every part kept (the cases above)")],
        [c.text(literal="its map model's own error (%)"), c.num(f"{q}/error_percent", 4),
         c.text(literal="against every station kept, at the cases, worst mode")],
        [c.text(literal="the same where it was chosen (%)"),
         c.num(f"{q}/check_error_percent", 4),
         c.text(literal="at the poses the reduction was chosen on (the level band's ends and "
                "middle, level and at full tilt)")],
    ]


def candidates_table(results: Results, c: Cells) -> dict:
    rows = []
    for k, cand in enumerate(results["fidelity"]["candidates"]):
        q = f"/fidelity/candidates/{k}"
        rows.append([c.text(f"{q}/setting"), c.num(f"{q}/worst_error_percent", 2),
                     c.num(f"{q}/seconds_per_pose", 3, 1e3)])
    return {"head": [head("analytical setting", "worst error (%)", "time per pose (ms)")],
            "rows": rows, "cls": "candidates"}


def percentile_table(results: Results, c: Cells) -> dict | None:
    wv = results["studies"]["workspace_validation"]
    if not wv or not wv["per_mode"]:
        return None
    n = max(len(s["p95"]) for s in wv["per_mode"].values())
    rows = []
    for label in wv["per_mode"]:
        q = f"/studies/workspace_validation/per_mode/{escape(label)}"
        for stat in ("median", "p95", "max"):
            rows.append([c.text(literal=label if stat == "median" else ""),
                         c.text(literal=stat)]
                        + [c.num(f"{q}/{stat}/{k}", 2) for k in range(n)])
    return {"head": [head("analytical model", "", *[f"f{k + 1}" for k in range(n)])],
            "rows": rows, "cls": "percentiles"}


def worst_pose_table(results: Results, c: Cells) -> dict | None:
    wv = results["studies"]["workspace_validation"]
    if not wv or not wv["worst_pose"]:
        return None
    q = "/studies/workspace_validation/worst_pose"
    n = len(wv["worst_pose"]["error_percent"])
    rows = [[c.text(literal="error vs FEM limit (%)")]
            + [c.num(f"{q}/error_percent/{k}", 2, signed=True) for k in range(n)],
            [c.text(literal="FEM estimated error (%)")]
            + [c.num(f"{q}/fem_estimated_error_percent/{k}", 2) for k in range(n)]]
    return {"head": [head("", *[f"f{k + 1}" for k in range(n)])], "rows": rows,
            "cls": "worstpose"}


def sentences(results: Results) -> list[str]:
    """The summary's sentences on the fidelity and the workspace (numbers from the results)."""
    fid = results["fidelity"]
    out = [("The scene's tolerance is met: " if fid["met"] else
            "The scene's tolerance is NOT met, so no agreement is claimed: ") + fid["reason"]]
    wv = results["studies"]["workspace_validation"]
    stats = wv["per_mode"].get(wv["default_model"]) if wv else None
    p95 = max((v for v in stats["p95"] if v is not None), default=None) if stats else None
    if wv and wv["worst_pose"] and p95 is not None:
        w = wv["worst_pose"]
        lo, hi = (w["slenderness"] or [math.nan, math.nan])
        beam_ends = wv["models"].get(wv["default_model"], {}).get("joint_ends", "beam") == "beam"
        why = (" (the joint ends, stiffer in the solid than in a beam, are a large part of such "
               "legs)" if beam_ends else "")
        out.append(
            f"Over {len(wv['poses'])} poses of the workspace, {wv['default_model']} stays "
            f"within {p95:.2f} % of the FEM limit at the 95th percentile (worst mode); its worst "
            f"pose is z = {w['height_mm']:.0f} mm, tilt = {w['tilt_deg']:.1f}° "
            f"({w['kind']}), {w['worst_error_percent']:.2f} %, where the legs are "
            f"{lo:.1f}–{hi:.1f} diameters long{why}.")
    return out


def error_maps(wv: WorkspaceValidation, path: Path) -> None:
    """|error| of the default model per mode over the workspace poses: polar maps (angle =
    azimuth, radius = tilt, every height), and the worst error against leg slenderness, from
    the workspace-validation study `wv` of results.json."""
    label = wv["default_model"]
    poses = [p for p in wv["poses"] if p["models"] and label in p["models"]]
    errs = np.array([[np.nan if e is None else abs(e) for e in (p["models"] or {})[label]]
                     for p in poses], float)  # poses: each with its models
    n = errs.shape[1]
    phi = np.radians([p["azimuth_deg"] for p in poses])
    tilt = np.array([p["tilt_deg"] for p in poses])
    top = np.nanmax(errs) if np.isfinite(errs).any() else 1.0
    cols = min(n, 3) + 1
    rows_ = math.ceil(n / 3)
    fig = plt.figure(figsize=(WIDTH, 2.2 * rows_ + 0.3))
    for k in range(n):
        polar = cast(PolarAxes, fig.add_subplot(rows_, cols, (k // 3) * cols + k % 3 + 1,
                                                projection="polar"))  # a polar projection's
        sc = polar.scatter(phi, tilt, c=errs[:, k], s=9, cmap="viridis", vmin=0, vmax=top)
        polar.set_title(f"f{k + 1}", fontsize=8)
        polar.tick_params(labelsize=5)
        polar.set_rlabel_position(90)
    cax = fig.add_axes((0.05, 0.03, 0.6, 0.02))
    fig.colorbar(sc, cax=cax, orientation="horizontal").set_label("|error vs FEM limit| (%)",
                                                                 fontsize=7)
    ax = fig.add_subplot(1, cols, cols)
    slender = np.array([shortest_leg(p) for p in poses])
    ax.scatter(slender, np.nanmax(errs, axis=1), s=8, color="0.2")
    ax.set_xlabel("shortest leg / diameter", fontsize=7)
    ax.set_ylabel("worst |error| (%)", fontsize=7)
    ax.tick_params(labelsize=6)
    fig.subplots_adjust(left=0.04, right=0.98, top=0.93, bottom=0.14, wspace=0.45)
    save(fig, path)


def shortest_leg(pose: ValidationPose) -> float:
    """The shortest leg of a solved validation pose, in leg diameters."""
    slenderness = pose["slenderness"]
    if slenderness is None:  # indexing None would raise the same
        raise TypeError("a solved validation pose without its legs' slenderness")
    return slenderness[0]
