"""The report of a design study (`rps design --report DIR`, `make design`): design.html and
design.pdf with the Pareto front and the optimum's frequency map, from the study's JSON only
(`studies.design`; nothing is recomputed here)."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Mapping

import numpy as np
from jinja2 import Environment, FileSystemLoader, select_autoescape

from .figures import WIDTH, plt, save
from .table_words import words

TEMPLATES = Path(__file__).resolve().parent / "templates"


def front_figure(result: Mapping[str, Any], path: Path) -> None:
    """Moving mass against the least f_k of every design solved: refused ones left out, those
    failing a constraint hollow, the front joined, the optimum ringed, the target dashed."""
    mode = result["constraints"]["mode"]
    fig, ax = plt.subplots(figsize=(WIDTH * 0.62, 3.0))
    solved = [r for r in result["designs"] if not r.get("refused")]
    band = result["constraints"]["min_level_band_mm"]
    ok = [r for r in solved if r["level_band_mm"] >= band - 1e-9]
    short = [r for r in solved if r["level_band_mm"] < band - 1e-9]
    for group, face, edge in ((ok, "0.45", "0.45"), (short, "none", "0.6")):
        if group:
            ax.scatter([r["moving_mass_kg"] for r in group],
                       [r["min_frequency_hz"] for r in group], s=12, lw=0.7, facecolors=face,
                       edgecolors=edge)
    front = result["front"]
    ax.plot([r["moving_mass_kg"] for r in front], [r["min_frequency_hz"] for r in front],
            "-o", color="#1f77b4", ms=3.5, lw=1.2, label="Pareto front")
    target = result["constraints"]["min_frequency_hz"]
    if target:
        ax.axhline(target, color="#d62728", ls="--", lw=0.9, label=f"target {target:g} Hz")
    best = result["optimum"]
    if best:
        ax.plot(best["moving_mass_kg"], best["min_frequency_hz"], "o", mfc="none", mec="k",
                ms=10, mew=1.4, label="optimum")
    ax.set_xlabel("moving mass (kg)")
    ax.set_ylabel(f"least f{mode} over the workspace (Hz)")
    ax.legend(fontsize=7, loc="lower right")
    ax.grid(alpha=0.3)
    save(fig, path)


def map_figure(result: Mapping[str, Any], path: Path) -> None:
    """The optimum's f_k over its workspace's boundary (height x azimuth, at the largest
    reachable tilt), its worst pose marked."""
    grid = result["optimum_map"]
    hz = np.array([[np.nan if f is None else f for f in row] for row in grid["frequencies_hz"]])
    fig, ax = plt.subplots(figsize=(WIDTH * 0.62, 3.0))
    mesh = ax.pcolormesh(grid["azimuths_deg"], grid["heights_mm"], hz, shading="nearest",
                         cmap="viridis")
    fig.colorbar(mesh, ax=ax, label=f"f{result['constraints']['mode']} (Hz)")
    p = result["optimum"]["worst_pose"]
    ax.plot(p["azimuth_deg"] % 360.0, p["height_mm"], "r*", ms=11,
            label=f"least: {result['optimum']['min_frequency_hz']:.2f} Hz")
    ax.set_xlabel("tilt azimuth φ (deg)")
    ax.set_ylabel("platform height z (mm)")
    ax.set_title("at the largest reachable tilt", fontsize=8, loc="left")
    ax.legend(fontsize=7, loc="upper right")
    save(fig, path)


def render_design_report(result: Mapping[str, Any], directory: Path) -> list[Path]:
    """design.json, front.png, map.png, design.html and design.pdf into `directory`."""
    from .document import render_pdf

    directory = Path(directory)
    (directory / "design.json").write_text(json.dumps(result), encoding="utf-8")
    front_figure(result, directory / "front.png")
    figures = {"front": "front.png"}
    if result["optimum"] and result.get("optimum_map"):
        map_figure(result, directory / "map.png")
        figures["map"] = "map.png"
    env = Environment(loader=FileSystemLoader(TEMPLATES), autoescape=select_autoescape())
    env.filters["words"] = lambda key: words(key.rsplit(".", 1)[-1])  # a scene key in words
    css = (TEMPLATES / "report.css").read_text(encoding="utf-8")
    html = env.get_template("design.html.j2").render(r=result, figures=figures, css=css)
    (directory / "design.html").write_text(html, encoding="utf-8")
    render_pdf(html, directory, directory / "design.pdf")  # the report's own fonts
    return [directory / n for n in ("design.json", "design.html", "design.pdf")]
