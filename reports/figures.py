"""The report's matplotlib figures of convergence, pairing and speed (Agg), drawn from
results.json values only, and the style every figure shares.

Every function writes one PNG; the caller decides the file name. Widths are sized for an A4
text column (about 170 mm).
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Sequence, cast

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402

from results import ElementConvergences, Pair, Refinement, SpeedPoint  # noqa: E402

DPI = 150
WIDTH = 6.7  # inches: the A4 text column
# tab10 is a ListedColormap, its colours a tuple of RGB triples
MODE_COLOURS = cast("tuple[tuple[float, float, float], ...]",
                    cast(ListedColormap, plt.get_cmap("tab10")).colors)
SETTING_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2",
                   "#7f7f7f")  # the speed figures' settings (tab10 without its red)
FEM_COLOUR = "#d62728"  # the FEM's, in the speed figures and boxes of the MAC
PAPER_SECONDS = {"analytical": 0.82, "ANSYS": 6.16}  # the paper's time per pose, Section 3.3

plt.rcParams.update({
    "font.size": 8.5, "axes.titlesize": 9, "axes.labelsize": 8.5, "legend.fontsize": 7.5,
    "xtick.labelsize": 7.5, "ytick.labelsize": 7.5, "axes.grid": True, "grid.alpha": 0.3,
    "savefig.dpi": DPI, "figure.dpi": DPI, "axes.spines.top": False,
    "axes.spines.right": False,
})


def save(fig, path: Path) -> None:
    fig.savefig(path, dpi=DPI, bbox_inches="tight", pad_inches=0.04)
    plt.close(fig)


def element_convergence(conv: ElementConvergences, reference_hz: Sequence[float],
                        reference_label: str, path: Path,
                        paper_elements: int = 3) -> None:
    """Error of f1..f6 vs elements per leg s, one panel per beam theory (the paper's Fig. 3)."""
    beams = [b for b in ("euler-bernoulli", "timoshenko") if b in conv]
    ref = np.asarray(reference_hz, float)
    fig, axes = plt.subplots(1, len(beams), figsize=(WIDTH, 2.6), sharey=True, squeeze=False)
    for ax, beam in zip(axes[0], beams):
        s = np.asarray(conv[beam]["elements"])
        f = np.asarray(conv[beam]["frequencies_hz"], float)
        n = min(f.shape[1], len(ref))
        err = 100 * (f[:, :n] / ref[:n] - 1)
        for k in range(n):
            ax.plot(s, err[:, k], marker="o", ms=3, lw=1.2, color=MODE_COLOURS[k],
                    label=f"$f_{k + 1}$")
        ax.axhline(0, color="0.3", lw=0.8)
        ax.axvline(paper_elements, color="0.5", lw=0.8, ls=":")
        ax.set_xticks(s)
        ax.set_xlabel("elements per leg s (–)")
        ax.set_title("Euler–Bernoulli" if beam == "euler-bernoulli" else "Timoshenko")
    axes[0, 0].set_ylabel(f"error vs {reference_label} (%)")
    axes[0, -1].legend(ncol=2, loc="upper right", frameon=False)
    lo, hi = axes[0, 0].get_ylim()
    if hi - lo > 40:  # s = 1 can be far off: keep the converged part readable
        axes[0, 0].set_ylim(max(lo, -15), min(hi, 25))
    save(fig, path)


def fem_refinement(ref: Refinement, path: Path, scene_size_mm: float | None = None) -> None:
    """FEM frequencies vs mesh size h, one panel per mode, with the extrapolated h -> 0 limit."""
    h = np.asarray(ref["mesh_sizes_mm"], float)
    f = np.asarray(ref["frequencies_hz"], float)
    extrap = ref["extrapolated_hz"]
    n = f.shape[1]
    cols = 3
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(WIDTH, 1.9 * rows + 0.2), squeeze=False)
    for k in range(rows * cols):
        ax = axes.flat[k]
        if k >= n:
            ax.set_visible(False)
            continue
        ax.plot(h, f[:, k], marker="o", ms=3.5, color=MODE_COLOURS[k], lw=1.2, label="FEM")
        if extrap[k] is not None:
            ax.plot([0], [extrap[k]], marker="*", ms=8, color="k", ls="none",
                    label="extrapolated (h → 0)")
            ax.axhline(extrap[k], color="0.4", lw=0.8, ls="--")
        if scene_size_mm:
            ax.axvline(scene_size_mm, color="0.6", lw=0.8, ls=":")
        ax.set_xlim(-2, h.max() * 1.08)
        note = limit_note(ref, k)
        ax.set_title(f"$f_{k + 1}$" + (f" ({note})" if note else ""), pad=2,
                     fontsize=7 if note else 9)
        ax.ticklabel_format(axis="y", useOffset=False)
        if k % cols == 0:
            ax.set_ylabel("frequency (Hz)")
        if k >= n - cols:
            ax.set_xlabel("mesh size h (mm)")
    axes.flat[0].legend(frameon=False, loc="best")
    fig.subplots_adjust(left=0.09, right=0.99, top=0.94, bottom=0.1, hspace=0.42, wspace=0.32)
    save(fig, path)


def limit_note(ref: Refinement, k: int) -> str:
    """What the star of mode k is when the extrapolation did not run as usual: the finest
    mesh's value, or an extrapolation at the order theory bounds it to."""
    status, order = ref["status"][k], ref["observed_order"][k]
    if status == "ok":
        return ""
    if ref["extrapolated_hz"][k] == ref["frequencies_hz"][-1][k]:
        return f"{status}, limit = finest"
    if status == "order bounded by theory" and order is not None:
        return f"p = {order:.3g} (theory)"
    return status


def mac_matrix(mac: list[list[float]], pairs: list[Pair], path: Path, title: str = ""
               ) -> None:
    """Heat map of MAC(analytical mode i, FEM mode j), the chosen pairs outlined."""
    m = np.asarray(mac, float)
    fig, ax = plt.subplots(figsize=(3.1, 2.7))
    im = ax.imshow(m, cmap="Blues", vmin=0, vmax=1, origin="upper")
    for i in range(m.shape[0]):
        for j in range(m.shape[1]):
            ax.text(j, i, f"{m[i, j]:.2f}", ha="center", va="center", fontsize=6.5,
                    color="white" if m[i, j] > 0.6 else "0.2")
    for p in pairs:
        i, j = p["analytical_mode"] - 1, p["fem_mode"] - 1
        if i < m.shape[0] and j < m.shape[1]:
            ax.add_patch(plt.Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, ec=FEM_COLOUR,
                                       lw=1.2))
    ax.set_xticks(range(m.shape[1]), [str(j + 1) for j in range(m.shape[1])])
    ax.set_yticks(range(m.shape[0]), [str(i + 1) for i in range(m.shape[0])])
    ax.set_xlabel("FEM mode (–)")
    ax.set_ylabel("analytical mode (–)")
    ax.grid(False)
    if title:
        ax.set_title(title)
    cb = fig.colorbar(im, ax=ax, fraction=0.046, pad=0.04)
    cb.set_label("MAC (–)")
    save(fig, path)


def speed_curves(entries: list[SpeedPoint]) -> list[tuple[str, list[SpeedPoint], str]]:
    """One case's speed-against-error entries as curves: (setting without its refinement, or
    "fem"; its entries in order; their legend label with the refinements listed)."""
    groups: dict[str, list[SpeedPoint]] = {}
    for e in entries:
        key = "fem" if e["model"] == "fem" else e["setting"].rsplit(",", 1)[0].strip()
        groups.setdefault(key, []).append(e)
    curves = []
    for key, rows in groups.items():
        steps = ", ".join(e["setting"].rsplit(",", 1)[-1].split("=", 1)[-1]
                          .replace("mm", "").strip() for e in rows)
        label = (f"FEM (3D solid), h = {steps} mm" if key == "fem" else
                 f"{key.replace('EB', 'Euler–Bernoulli')}, s = {steps}")
        curves.append((key, rows, label))
    return curves


def speed_point(e: SpeedPoint) -> tuple[float, float]:
    """(time per pose, worst |error|) of an entry as the log axes draw it (floored)."""
    return max(e["seconds"], 1e-6), max(abs(e["worst_error_percent"]), 1e-3)


def speed_vs_error(entries: dict[str, list[SpeedPoint]], path: Path, paper: bool,
                   chosen: tuple[str, ...] = ()) -> None:
    """Time per pose (log) against the worst |error| of f1..f6, one panel per case, the
    settings the run used (`chosen`) ringed; with the paper's times per pose when the results
    carry the paper's data (`paper`)."""
    names = list(entries)
    fig, axes = plt.subplots(1, len(names), figsize=(WIDTH, 4.0), sharey=True, squeeze=False)
    # Each setting is a curve through its refinements (s elements, or the FEM's mesh h), named
    # in the legend with its refinements in the order of the points: labels on the points
    # would overlap where two curves run close (Cowper's and Hutchinson's shear coefficients).
    markers = "osv^p<>h"
    colours = SETTING_COLOURS
    fem_style = dict(marker="D", color=FEM_COLOUR)
    seen: list[str] = []
    for ax, name in zip(axes[0], names):
        for key, rows, label in speed_curves(entries[name]):
            if key not in seen:
                seen.append(key)
            k = seen.index(key)
            st = dict(fem_style) if key == "fem" else dict(marker=markers[k % len(markers)],
                                                            color=colours[k % len(colours)])
            ax.plot(*zip(*map(speed_point, rows)), ls="-", lw=0.8, ms=4, label=label, **st)
        picked = [e for e in entries[name] if e["setting"] in chosen]
        if picked:
            ax.plot(*zip(*map(speed_point, picked)), "o", ms=10,
                    mfc="none", mec="black", mew=1.3, ls="none",
                    label="the run's settings" if name == names[0] else None)
        for model, t in (PAPER_SECONDS.items() if paper else ()):
            text = f"paper: {model} {t:g} s"
            ax.axvline(t, color="0.35", lw=0.9, ls="--")
            ax.text(t, 1.0, text, rotation=90, va="top", ha="right", fontsize=6.5,
                    color="0.3", transform=ax.get_xaxis_transform())
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.set_xlabel("time per pose (s)")
        ax.set_title(name)
    axes[0, 0].set_ylabel("worst |error| of f1–f6 (%)")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=2, frameon=False, fontsize=6.5,
               title="each curve: one setting, refined as listed", title_fontsize=6.5,
               bbox_to_anchor=(0.5, -0.02))
    fig.tight_layout(rect=(0, 0.2, 1, 1))
    save(fig, path)


