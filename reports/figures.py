"""The report's matplotlib figures (Agg), drawn from results.json values only.

Every function writes one PNG and returns nothing; the caller decides the file name. Widths are
sized for an A4 text column (about 170 mm).
"""
from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import Normalize  # noqa: E402

DPI = 150
WIDTH = 6.7  # inches: the A4 text column
MODE_COLOURS = plt.get_cmap("tab10").colors
PAPER_ANALYTICAL_S = 0.82  # the paper's time per pose, Section 3.3
PAPER_ANSYS_S = 6.16

plt.rcParams.update({
    "font.size": 8.5, "axes.titlesize": 9, "axes.labelsize": 8.5, "legend.fontsize": 7.5,
    "xtick.labelsize": 7.5, "ytick.labelsize": 7.5, "axes.grid": True, "grid.alpha": 0.3,
    "savefig.dpi": DPI, "figure.dpi": DPI, "axes.spines.top": False,
    "axes.spines.right": False,
})


def _save(fig, path: Path) -> None:
    fig.savefig(path, dpi=DPI, bbox_inches="tight", pad_inches=0.04)
    plt.close(fig)


def element_convergence(conv: dict, reference_hz, reference_label: str, path: Path,
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
    _save(fig, path)


def fem_refinement(ref: dict, path: Path, scene_size_m: float | None = None) -> None:
    """FEM frequencies vs mesh size h, one panel per mode, with the extrapolated h -> 0 limit."""
    h = np.asarray(ref["sizes_m"], float) * 1e3
    f = np.asarray(ref["frequencies_hz"], float)
    extrap = ref.get("extrapolated_hz")
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
        if extrap is not None and extrap[k] is not None:
            ax.plot([0], [extrap[k]], marker="*", ms=8, color="k", ls="none",
                    label="extrapolated (h → 0)")
            ax.axhline(extrap[k], color="0.4", lw=0.8, ls="--")
        if scene_size_m:
            ax.axvline(scene_size_m * 1e3, color="0.6", lw=0.8, ls=":")
        ax.set_xlim(-2, h.max() * 1.08)
        status = ref.get("status")
        note = ""
        if isinstance(status, list) and k < len(status) and status[k] != "ok":
            note = f" ({status[k]}: limit = finest)"
        ax.set_title(f"$f_{k + 1}$" + note, pad=2, fontsize=8 if note else 9)
        ax.ticklabel_format(axis="y", useOffset=False)
        if k % cols == 0:
            ax.set_ylabel("frequency (Hz)")
        if k >= n - cols:
            ax.set_xlabel("mesh size h (mm)")
    axes.flat[0].legend(frameon=False, loc="best")
    fig.subplots_adjust(left=0.09, right=0.99, top=0.94, bottom=0.1, hspace=0.42, wspace=0.32)
    _save(fig, path)


def mac_matrix(mac, pairs, path: Path, title: str = "") -> None:
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
            ax.add_patch(plt.Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, ec="#d62728",
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
    _save(fig, path)


def speed_vs_error(entries: dict[str, list[dict]], path: Path) -> None:
    """Time per pose (log) against the worst |error| of f1..f6, one panel per case."""
    names = list(entries)
    fig, axes = plt.subplots(1, len(names), figsize=(WIDTH, 3.2), sharey=True, squeeze=False)
    styles = {"EB": dict(marker="o", color="#1f77b4", label="analytical, Euler–Bernoulli"),
              "Timoshenko": dict(marker="s", color="#2ca02c", label="analytical, Timoshenko"),
              "fem": dict(marker="D", color="#d62728", label="FEM (3D solid), mesh h")}
    for ax, name in zip(axes[0], names):
        groups: dict[str, list[dict]] = {}
        for e in entries[name]:
            key = "fem" if e["model"] == "fem" else e["setting"].split(",")[0]
            groups.setdefault(key, []).append(e)
        for key, rows in groups.items():
            rows = sorted(rows, key=lambda e: e["seconds"])
            st = styles.get(key, dict(marker="^", color="0.3", label=key))
            x = [max(e["seconds"], 1e-6) for e in rows]
            y = [max(abs(e["worst_error_percent"]), 1e-3) for e in rows]
            ax.plot(x, y, ls="-", lw=0.8, ms=4, **st)
            for e, xi, yi in zip(rows, x, y):
                label = e["setting"].split(",")[-1].strip().replace(" ", "")
                ax.annotate(label, (xi, yi), xytext=(3, 3), textcoords="offset points",
                            fontsize=6, color=st["color"])
        for t, text in ((PAPER_ANALYTICAL_S, "paper: analytical 0.82 s"),
                        (PAPER_ANSYS_S, "paper: ANSYS 6.16 s")):
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
    fig.legend(handles, labels, loc="lower center", ncol=3, frameon=False,
               bbox_to_anchor=(0.5, -0.02))
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    _save(fig, path)


def _valid_layers(ws: dict) -> list[int]:
    f = ws["frequencies_hz"]
    return [i for i in range(len(ws["heights_mm"]))
            if any(v is not None for ring in f[i] for az in ring for v in (az or []))]


def _layer_array(ws: dict, iz: int, mode: int) -> np.ndarray:
    return np.array([[np.nan if (az is None or az[mode] is None) else az[mode]
                      for az in ring] for ring in ws["frequencies_hz"][iz]], float)


def workspace_polar(ws: dict, path: Path, layers: int = 3, modes: int = 3) -> list[float]:
    """f1..f3 on polar maps (angle: azimuth phi, radius: tilt theta) at a few heights.

    Returns the heights (mm) drawn.
    """
    valid = _valid_layers(ws)
    if not valid:
        raise ValueError("workspace map has no reachable layer")
    pick = sorted({valid[round(i * (len(valid) - 1) / max(layers - 1, 1))]
                   for i in range(min(layers, len(valid)))})
    phi = np.radians(np.asarray(ws["azimuths_deg"], float))
    # cell edges in azimuth (closed circle) and tilt
    dphi = (phi[1] - phi[0]) if len(phi) > 1 else 2 * math.pi
    phi_edges = np.concatenate([phi - dphi / 2, [phi[-1] + dphi / 2]])
    fig = plt.figure(figsize=(WIDTH, 1.65 * modes + 0.2))
    for k in range(modes):
        for c, iz in enumerate(pick):
            values = _layer_array(ws, iz, k)
            ax = fig.add_subplot(modes, len(pick), k * len(pick) + c + 1, projection="polar")
            tilts = np.asarray(ws["tilts_deg"][iz], float)
            dt = (tilts[1] - tilts[0]) if len(tilts) > 1 else 1.0
            t_edges = np.concatenate([[0.0], (tilts[:-1] + tilts[1:]) / 2,
                                      [tilts[-1] + dt / 2]]) if len(tilts) > 1 else [0, dt]
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
            cb.formatter.set_useOffset(False)
            cb.ax.set_title("Hz", fontsize=6, pad=2)
    fig.subplots_adjust(left=0.07, right=0.97, top=0.93, bottom=0.05, hspace=0.45,
                        wspace=0.45)
    _save(fig, path)
    return [ws["heights_mm"][iz] for iz in pick]


def workspace_height(ws: dict, path: Path, modes: int = 3) -> None:
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
    _save(fig, path)


def beam_mode(base: np.ndarray, platform: np.ndarray, stations, shape: np.ndarray,
              platform_radius: float, path: Path, title: str, scale_to: float,
              view=(22.0, -60.0)) -> None:
    """The beam model's leg axes, deformed (scaled) over undeformed, and the rigid platform.

    shape: (3 legs, n stations, 3) translations in base coordinates. The platform outline is
    moved by the rigid motion that best fits the three S-joint translations.
    """
    from mpl_toolkits.mplot3d import Axes3D  # noqa: F401  (registers the projection)

    stations = np.asarray(stations, float)
    amp = np.abs(shape).max()
    scale = scale_to / amp if amp > 0 else 0.0
    fig = plt.figure(figsize=(2.3, 2.1))
    ax = fig.add_subplot(projection="3d")
    centre = platform.mean(axis=0)
    normal = np.cross(platform[1] - platform[0], platform[2] - platform[0])
    normal /= np.linalg.norm(normal)
    e1 = (platform[0] - centre) / np.linalg.norm(platform[0] - centre)
    e2 = np.cross(normal, e1)
    t = np.linspace(0, 2 * math.pi, 73)
    disk = centre + platform_radius * (np.outer(np.cos(t), e1) + np.outer(np.sin(t), e2))
    tr, w = _rigid_fit(platform, shape[:, -1, :], centre)
    disk_u = disk + scale * (tr + np.cross(w, disk - centre))
    base_ring = np.linalg.norm(base[0, :2])
    ring = np.stack([base_ring * np.cos(t), base_ring * np.sin(t), 0 * t], axis=1)
    ax.plot(*ring.T, color="0.75", lw=0.6)
    ax.plot(*disk.T, color="0.65", lw=0.7, ls="--")
    ax.plot(*disk_u.T, color="#444444", lw=1.1)
    amp_leg = np.linalg.norm(shape, axis=2)
    cmap = plt.get_cmap("viridis")
    for i in range(3):
        axis = base[i] + np.outer(stations, platform[i] - base[i])
        ax.plot(*axis.T, color="0.65", lw=0.8, ls="--")
        moved = axis + scale * shape[i]
        for a in range(len(stations) - 1):
            level = 0.5 * (amp_leg[i, a] + amp_leg[i, a + 1]) / max(amp_leg.max(), 1e-30)
            ax.plot(*moved[a:a + 2].T, color=cmap(level), lw=2.6, solid_capstyle="round")
        ax.scatter(*base[i], color="k", s=6)
        ax.scatter(*moved[-1], color="k", s=6)
    pts = np.vstack([ring, disk, disk_u])
    mid = 0.5 * (pts.max(0) + pts.min(0))
    half = 0.5 * (pts.max(0) - pts.min(0)).max()
    ax.set_xlim(mid[0] - half, mid[0] + half)
    ax.set_ylim(mid[1] - half, mid[1] + half)
    ax.set_zlim(mid[2] - half, mid[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=view[0], azim=view[1])
    ax.set_axis_off()
    ax.text2D(0.02, 0.98, title, transform=ax.transAxes, fontsize=7.5, va="top")
    fig.subplots_adjust(0, 0, 1, 1)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    crop_png(path)


def crop_png(path: Path, margin: int = 6) -> None:
    """Trim the white border of a PNG in place (3D axes leave a lot of it)."""
    from PIL import Image

    with Image.open(path) as im:
        rgb = np.asarray(im.convert("RGB"))
    ink = np.any(rgb < 245, axis=2)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    if len(rows) == 0:
        return
    r0, r1 = max(rows[0] - margin, 0), min(rows[-1] + margin + 1, rgb.shape[0])
    c0, c1 = max(cols[0] - margin, 0), min(cols[-1] + margin + 1, rgb.shape[1])
    Image.fromarray(np.ascontiguousarray(rgb[r0:r1, c0:c1])).save(path)


def _rigid_fit(points: np.ndarray, disp: np.ndarray, centre: np.ndarray):
    """Least-squares small rigid motion u(x) = t + w x (x - c) through the given points."""
    rows = []
    for p in points:
        r = p - centre
        skew = np.array([[0, r[2], -r[1]], [-r[2], 0, r[0]], [r[1], -r[0], 0]])
        rows.append(np.hstack([np.eye(3), skew]))
    sol = np.linalg.lstsq(np.vstack(rows), np.asarray(disp).ravel(), rcond=None)[0]
    return sol[:3], sol[3:]
