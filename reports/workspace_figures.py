"""The report's workspace maps (the paper's Fig. 6): the first frequencies over the regular
workspace, drawn from results.json values only."""
from __future__ import annotations

import math
from pathlib import Path
from typing import cast

import numpy as np
from matplotlib.colors import Normalize
from matplotlib.projections.polar import PolarAxes
from matplotlib.ticker import ScalarFormatter

from common.errors import InputError
from results import Workspace

from .figures import MODE_COLOURS, WIDTH, plt, save


def _valid_layers(ws: Workspace) -> list[int]:
    f = ws["frequencies_hz"]
    return [i for i in range(len(ws["heights_mm"]))
            if any(v is not None for ring in f[i] for az in ring for v in (az or []))]


def _layer_array(ws: Workspace, iz: int, mode: int) -> np.ndarray:
    return np.array([[np.nan if (az is None or az[mode] is None) else az[mode]
                      for az in ring] for ring in ws["frequencies_hz"][iz]], float)


def cell_edges(azimuths_deg, tilts_deg) -> tuple[np.ndarray, np.ndarray]:
    """A layer's cell edges for a polar map: in azimuth (rad, the closed circle) and in tilt
    (deg, the level pose a disc about the centre, the outer ring as wide as its neighbour)."""
    phi = np.radians(np.asarray(azimuths_deg, float))
    dphi = (phi[1] - phi[0]) if len(phi) > 1 else 2 * math.pi
    phi_edges = np.concatenate([phi - dphi / 2, [phi[-1] + dphi / 2]])
    tilts = np.asarray(tilts_deg, float)
    if len(tilts) < 2:
        return phi_edges, np.array([0.0, 1.0])
    return phi_edges, np.concatenate([[0.0], (tilts[:-1] + tilts[1:]) / 2,
                                      [tilts[-1] + (tilts[-1] - tilts[-2]) / 2]])


def workspace_polar(ws: Workspace, path: Path, layers: int = 3, modes: int = 3) -> list[float]:
    """f1..f3 on polar maps (angle: azimuth phi, radius: tilt theta) at a few heights.

    Returns the heights (mm) drawn.
    """
    valid = _valid_layers(ws)
    if not valid:
        raise InputError("workspace map has no reachable layer")
    pick = sorted({valid[round(i * (len(valid) - 1) / max(layers - 1, 1))]
                   for i in range(min(layers, len(valid)))})
    fig = plt.figure(figsize=(WIDTH, 1.5 * modes + 0.2))
    for k in range(modes):
        for c, iz in enumerate(pick):
            values = _layer_array(ws, iz, k)
            ax = cast(PolarAxes, fig.add_subplot(modes, len(pick), k * len(pick) + c + 1,
                                                 projection="polar"))  # a polar projection's
            phi_edges, t_edges = cell_edges(ws["azimuths_deg"], ws["tilts_deg"][iz])
            P, T = np.meshgrid(phi_edges, t_edges)
            lo, hi = np.nanmin(values), np.nanmax(values)
            if hi - lo < 1e-6 * max(abs(hi), 1.0):
                lo, hi = lo - 0.5, hi + 0.5
            mesh = ax.pcolormesh(P, T, values, cmap="viridis", norm=Normalize(lo, hi),
                                 shading="flat")
            ax.set_ylim(0, t_edges[-1])
            ax.tick_params(labelsize=5.5, pad=-1)
            ax.set_rlabel_position(100)
            ax.yaxis.set_major_locator(plt.MaxNLocator(3))
            ax.set_xticks(np.radians([0, 90, 180, 270]), ["0°", "90°", "180°", "270°"])
            ax.grid(alpha=0.4)
            if k == 0:
                ax.set_title(f"z = {ws['heights_mm'][iz]:.0f} mm", pad=12)
            if c == 0:
                ax.text(-0.42, 0.5, f"$f_{k + 1}$", transform=ax.transAxes, fontsize=10,
                        va="center")
            cb = fig.colorbar(mesh, ax=ax, fraction=0.05, pad=0.12, shrink=0.85)
            cb.ax.tick_params(labelsize=5.5)
            # a colorbar of a linear norm formats its ticks with a ScalarFormatter
            cast(ScalarFormatter, cb.formatter).set_useOffset(False)
            cb.ax.set_title("Hz", fontsize=6, pad=2)
    fig.subplots_adjust(left=0.07, right=0.97, top=0.93, bottom=0.05, hspace=0.45,
                        wspace=0.45)
    save(fig, path)
    return [ws["heights_mm"][iz] for iz in pick]


def workspace_height(ws: Workspace, path: Path, modes: int = 3) -> None:
    """f1..f3 vs platform height: level platform (theta = 0) and the range over each layer."""
    valid = _valid_layers(ws)
    z = np.asarray(ws["heights_mm"], float)[valid]
    fig, ax = plt.subplots(figsize=(WIDTH * 0.6, 2.4))
    for k in range(modes):
        arr = [_layer_array(ws, iz, k) for iz in valid]
        level = [np.nanmean(a[0]) for a in arr]
        lo = [np.nanmin(a) for a in arr]
        hi = [np.nanmax(a) for a in arr]
        ax.fill_between(z, lo, hi, color=MODE_COLOURS[k], alpha=0.18, lw=0)
        ax.plot(z, level, marker="o", ms=3, color=MODE_COLOURS[k], lw=(2.6, 1.2, 1.2)[k % 3],
                ls=("-", "--", "-")[k % 3], label=f"$f_{k + 1}$, level platform")
    ax.set_xlabel("platform height z (mm)")
    ax.set_ylabel("frequency (Hz)")
    ax.legend(frameon=False, fontsize=7)
    ax.text(0.99, 0.97, "bands: range over the regular workspace layer", ha="right", va="top",
            fontsize=6.5, color="0.35", transform=ax.transAxes)
    save(fig, path)
