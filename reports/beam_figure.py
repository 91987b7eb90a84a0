"""The beam model's mode-shape pictures (matplotlib 3D): leg axes and the rigid platform,
deformed over undeformed, from the shapes and platform motion results.json carries."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .figures import DPI, plt


def beam_mode(base: np.ndarray, platform: np.ndarray, centre: np.ndarray, stations,
              shape: np.ndarray, motion: tuple[np.ndarray, np.ndarray], platform_radius: float,
              path: Path, title: str, scale_to: float, view=(22.0, -60.0),
              feet: np.ndarray | None = None) -> None:
    """The leg axes B_i -> A_i deformed by `shape` (legs, stations, 3), and the platform disk
    about its centre o moved by the model's own platform motion (translation of o, rotation);
    displacements scaled so the largest leg displacement is drawn `scale_to` long. `feet`:
    the base circle's points (a 3-PRS's rails run from them to the sliders at `base`)."""
    from mpl_toolkits.mplot3d import Axes3D  # noqa: F401  (registers the projection)

    stations = np.asarray(stations, float)
    amp = np.abs(shape).max()
    scale = scale_to / amp if amp > 0 else 0.0
    fig = plt.figure(figsize=(2.3, 2.1))
    ax = fig.add_subplot(projection="3d")
    normal = np.cross(platform[1] - platform[0], platform[2] - platform[0])
    normal /= np.linalg.norm(normal)
    e1 = (platform[0] - centre) / np.linalg.norm(platform[0] - centre)
    e2 = np.cross(normal, e1)
    t = np.linspace(0, 2 * math.pi, 73)
    disk = centre + platform_radius * (np.outer(np.cos(t), e1) + np.outer(np.sin(t), e2))
    translation, rotation = motion
    disk_u = disk + scale * (translation + np.cross(rotation, disk - centre))
    feet = base if feet is None else np.asarray(feet, float)
    base_ring = np.linalg.norm(feet[0, :2])
    ring = np.stack([base_ring * np.cos(t), base_ring * np.sin(t), 0 * t], axis=1)
    ax.plot(*ring.T, color="0.75", lw=0.6)
    for foot, joint in zip(feet, base):
        if np.linalg.norm(joint - foot) > 1e-9:  # a 3-PRS: the rail to the slider
            ax.plot(*np.stack([foot, joint]).T, color="0.45", lw=1.4)
    ax.plot(*disk.T, color="0.65", lw=0.7, ls="--")
    ax.plot(*disk_u.T, color="#444444", lw=1.1)
    amp_leg = np.linalg.norm(shape, axis=2)
    cmap = plt.get_cmap("viridis")
    for i in range(len(base)):
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
