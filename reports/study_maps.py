"""The static twins (matplotlib, Agg) of the interactive polar maps of two studies report.pdf
otherwise shows as tables only: the least dynamic stiffness at the tool over the workspace
map and the cut's least critical depth over it. Drawn as `workspace_figures` draws the
frequency map (angle: azimuth φ, radius: tilt θ, one cell per pose), from results.json values
only; the least over the map starred."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping, Sequence, cast

import numpy as np
from matplotlib.colors import LogNorm, Normalize
from matplotlib.projections.polar import PolarAxes
from matplotlib.ticker import (
    FuncFormatter,
    LogLocator,
    NullFormatter,
    NullLocator,
    ScalarFormatter,
)

from .figures import WIDTH, plt, save
from .workspace_figures import cell_edges

DIRECTIONS = ("x", "y", "z")
LEAST_COLOUR = "#d62728"  # the least pose's star: outside viridis
MOST_LAYERS = 4  # the stability map's panels


def _layer(grid: Sequence[Sequence[float | None]]) -> np.ma.MaskedArray:
    """A layer's [ring][azimuth] values, masked where None (a pose not reached)."""
    values = np.array([[np.nan if v is None else v for v in ring] for ring in grid], float)
    return np.ma.masked_invalid(values)


def _held(grid) -> bool:
    return any(v is not None for ring in grid for v in ring)


def _polar(fig, n: int, count: int) -> PolarAxes:
    ax = cast(PolarAxes, fig.add_subplot(1, count, n + 1, projection="polar"))
    ax.tick_params(labelsize=5.5, pad=-2)
    ax.set_rlabel_position(100)
    ax.yaxis.set_major_locator(plt.MaxNLocator(3))
    ax.set_xticks(np.radians([0, 90, 180, 270]), ["0°", "90°", "180°", "270°"])
    ax.grid(alpha=0.4)
    return ax


def _mesh(ax: PolarAxes, record: Mapping[str, Any], iz: int, values, norm):
    phi_edges, t_edges = cell_edges(record["azimuths_deg"], record["tilts_deg"][iz])
    P, T = np.meshgrid(phi_edges, t_edges)
    mesh = ax.pcolormesh(P, T, values, cmap="viridis", norm=norm, shading="flat")
    ax.set_ylim(0, t_edges[-1])
    return mesh


def _star(ax: PolarAxes, tilt_deg: float, azimuth_deg: float) -> None:
    ax.plot([np.radians(azimuth_deg)], [tilt_deg], marker="*", ms=11, color=LEAST_COLOUR,
            mec="white", mew=0.6, ls="none", zorder=5)


def _nearest(heights: Sequence[float], layers: Sequence[int], height: float) -> int:
    """The layer (of `layers`) whose height is nearest `height`."""
    return min(layers, key=lambda iz: abs(heights[iz] - height))


def _compact(value: float, _=None) -> str:
    """A value to three significant digits, its exponent short: 2e5, 1.79e5, 83.7."""
    mantissa, _e, exponent = f"{value:.3g}".partition("e")
    return mantissa + (f"e{int(exponent)}" if exponent else "")


def _log_bar(fig, mesh, ax, label: str, lo: float, hi: float) -> None:
    """A colour bar of a log colour: 1, 2, 5 x 10^n over a wide range, else four ticks
    spread evenly (in log) between the ends; labels short (1.2e5)."""
    cb = fig.colorbar(mesh, ax=ax, fraction=0.05, pad=0.1, shrink=0.85)
    cb.ax.yaxis.set_minor_locator(NullLocator())
    if hi / lo >= 10:
        cb.ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    else:
        cb.set_ticks(np.geomspace(lo, hi, 4))
    cb.ax.yaxis.set_major_formatter(FuncFormatter(_compact))
    cb.ax.yaxis.set_minor_formatter(NullFormatter())
    cb.ax.tick_params(which="both", labelsize=5.5)
    cb.ax.set_title(label, fontsize=6, pad=2)


def _point(record: Mapping[str, Any]) -> str:
    return "(" + ", ".join(f"{v:g}" for v in record["point_mm"]) + ") mm"


# ---- the least dynamic stiffness --------------------------------------------------------

def stiffness_panels(ds: Mapping[str, Any]) -> list[tuple[str, int]]:
    """(direction, layer) of each panel: per direction with a stiffness, the layer holding its
    least over the map (the record's row), else its first layer with a stiffness."""
    grids = ds["stiffness_n_per_m"]
    out = []
    for d in DIRECTIONS:
        layers = [iz for iz in range(len(ds["heights_mm"]))
                  if d in grids and _held(grids[d][iz])]
        if not layers:
            continue
        row = next((r for r in ds["least"] if r["direction"] == d), None)
        out.append((d, layers[0] if row is None
                    else _nearest(ds["heights_mm"], layers, row["height_mm"])))
    return out


def dynamic_stiffness_map(ds: Mapping[str, Any], path: Path) -> None:
    """The least dynamic stiffness at the tool, 1 / max |H_dd| (N/m, log colour), one polar
    panel per direction at the layer holding its least over the map, that least starred."""
    panels = stiffness_panels(ds)
    if not panels:
        raise ValueError("the dynamic-stiffness map has no stiffness")
    fig = plt.figure(figsize=(WIDTH, 2.5))
    for n, (d, iz) in enumerate(panels):
        ax = _polar(fig, n, len(panels))
        values = _layer(ds["stiffness_n_per_m"][d][iz])
        lo, hi = float(values.min()), float(values.max())
        hi = hi if hi > lo * (1 + 1e-9) else lo * 1.01
        mesh = _mesh(ax, ds, iz, values, LogNorm(lo, hi))
        for row in ds["least"]:  # the panel's layer is the row's
            if row["direction"] == d:
                _star(ax, row["tilt_deg"], row["azimuth_deg"])
        ax.set_title(f"along {d}, z = {ds['heights_mm'][iz]:.0f} mm", pad=12)
        _log_bar(fig, mesh, ax, f"$k_{d}$ (N/m)", lo, hi)
    fig.subplots_adjust(left=0.03, right=0.95, top=0.84, bottom=0.06, wspace=0.55)
    save(fig, path)


def stiffness_caption(ds: Mapping[str, Any]) -> str:
    shown = "; ".join(f"along {d} at z = {ds['heights_mm'][iz]:.0f} mm"
                      for d, iz in stiffness_panels(ds))
    return (f"The least dynamic stiffness at the tool point {_point(ds)}, "
            "1 / max |H_dd| (N/m, colour on a log scale of each panel's own range), over the "
            f"layer of the workspace map holding its least ({shown}): angle = azimuth φ (deg), "
            "radius = tilt θ (deg); star: the least over the map. The analytical model "
            f"({ds['analytical']}, {ds['modes_summed']} modes summed, {ds['lines']} lines), "
            f"damping {ds['damping']}; a blank cell: a pose not reached, or where the tool "
            "does not move along the direction. Every layer: report.html's chart.")


# ---- the least critical depth -----------------------------------------------------------

def stability_layers(sm: Mapping[str, Any]) -> list[int]:
    """The layers the map draws: those with a depth, at most MOST_LAYERS spread evenly over
    them, the one holding the least over the map always among them."""
    layers = [iz for iz, grid in enumerate(sm["least_depth_mm"]) if _held(grid)]
    if len(layers) <= MOST_LAYERS:
        return layers
    pick = [layers[round(i * (len(layers) - 1) / (MOST_LAYERS - 1))] for i in range(MOST_LAYERS)]
    if sm["least"]:
        least = _nearest(sm["heights_mm"], layers, sm["least"][0]["height_mm"])
        if least not in pick:
            pick[min(range(MOST_LAYERS), key=lambda i: abs(pick[i] - least))] = least
    return sorted(set(pick))


def stability_map(sm: Mapping[str, Any], path: Path) -> None:
    """The least critical depth over the speeds (mm) at every reachable pose, one polar panel
    per drawn layer on one colour scale; the least over the map starred."""
    layers = stability_layers(sm)
    if not layers:
        raise ValueError("the stability map has no depth")
    grids = {iz: _layer(sm["least_depth_mm"][iz]) for iz in layers}
    lo = min(float(g.min()) for g in grids.values())
    hi = max(float(g.max()) for g in grids.values())
    norm = Normalize(lo, hi if hi - lo > 1e-9 * max(abs(hi), 1.0) else lo + 1e-3)
    fig = plt.figure(figsize=(WIDTH, 2.4))
    fig.subplots_adjust(left=0.03, right=0.86, wspace=0.45)
    meshes, axes = [], []
    for n, iz in enumerate(layers):
        ax = _polar(fig, n, len(layers))
        meshes.append(_mesh(ax, sm, iz, grids[iz], norm))
        ax.set_title(f"z = {sm['heights_mm'][iz]:.0f} mm", pad=12)
        for row in sm["least"]:
            if _nearest(sm["heights_mm"], layers, row["height_mm"]) == iz:
                _star(ax, row["tilt_deg"], row["azimuth_deg"])
        axes.append(ax)
    cb = fig.colorbar(meshes[0], ax=axes, fraction=0.03, pad=0.06, shrink=0.8)
    cb.ax.tick_params(labelsize=6)
    cast(ScalarFormatter, cb.formatter).set_useOffset(False)
    cb.set_label("least critical depth (mm)", fontsize=7)
    save(fig, path)


def stability_caption(sm: Mapping[str, Any]) -> str:
    lo, hi = sm["spindle_rpm_range"]
    layers = stability_layers(sm)
    held = sum(_held(grid) for grid in sm["least_depth_mm"])
    heights = ", ".join(f"{sm['heights_mm'][iz]:.0f}" for iz in layers)
    which = (f"at the heights z = {heights} mm" if len(layers) == held else
             f"at {len(layers)} of the {held} heights with a depth, z = {heights} mm (every "
             "layer: report.html's chart)")
    least = ""
    if sm["least"]:
        row = sm["least"][0]
        least = (f"; star: the least over the map, {row['depth_mm']:.3g} mm at "
                 f"{row['spindle_rpm']:.0f} rpm")
    return (f"The least critical depth (mm) of the scene's cut over {sm['speeds']} spindle "
            f"speeds from {lo:.0f} to {hi:.0f} rpm ({sm['method']}) at every pose of the "
            f"workspace map, {which}: angle = azimuth φ (deg), radius = tilt θ (deg), colour "
            f"= depth on one scale{least}; a blank cell: a pose not reached, or stable up to "
            f"the search's ceiling. The analytical model ({sm['analytical']}), damping "
            f"{sm['damping']}, tool point {_point(sm)}.")
