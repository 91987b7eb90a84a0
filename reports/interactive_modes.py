"""The report's interactive mode shapes: every paired mode of a case, the FEM solid and the beam
model side by side in one plotly figure of two 3D scenes, turnable, with a mode selector and
the motion animated (templates/report.js moves the vertices along the mode, +- its scaled
amplitude, so a mode's data is stored once, not once per animation frame).

The same data and scale rule as the static pictures (`render3d`, `beam_figure`): the FEM's
surface and displacement fields from the mode file results.json names, the platform disk moved
by the FEM's own platform motion when the file has no platform solid, the beam model's leg
axes and rigid platform from results.json; the largest displacement drawn as 10 % of the
manipulator's size.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from results import Case, Manipulator

from .render3d import Platform, _covers_platform, _platform_disk, read_modes
from .results import (
    base_circle_points,
    joint_points,
    leg_axis_shapes,
    platform_centre,
    platform_motion,
)

SCALE_FRACTION = 0.1  # the largest displacement drawn as this fraction of the model's size
DIGITS = 5  # decimals of metres kept (10 µm): far below a pixel of a 0.5 m machine


def _round(a) -> list:
    return np.round(np.asarray(a, float), DIGITS).tolist()


def _with_breaks(lines: list[np.ndarray]) -> np.ndarray:
    """Polylines joined into one (n, 3) array, NaN rows between them (one plotly trace)."""
    out = []
    for line in lines:
        out.extend([line, np.full((1, 3), np.nan)])
    return np.concatenate(out[:-1])


def _disk_ring(joints: np.ndarray, centre: np.ndarray, radius: float) -> np.ndarray:
    normal = np.cross(joints[1] - joints[0], joints[2] - joints[0])
    normal /= np.linalg.norm(normal)
    e1 = (joints[0] - centre) / np.linalg.norm(joints[0] - centre)
    e2 = np.cross(normal, e1)
    t = np.linspace(0, 2 * math.pi, 49)
    return centre + radius * (np.outer(np.cos(t), e1) + np.outer(np.sin(t), e2))


def _rigid(points: np.ndarray, centre: np.ndarray, motion) -> np.ndarray:
    translation, rotation = motion
    return translation + np.cross(rotation, points - centre)


def _xyz(points: np.ndarray) -> dict:
    """x, y, z lists, NaN as null (plotly's line break)."""
    return {c: [None if math.isnan(v) else v for v in _round(points[:, i])]
            for i, c in enumerate("xyz")}


def mode_viewer(case: Case, manipulator: Manipulator, results_path: Path) -> dict | None:
    """The viewer of a results.json case record: {"figure": the plotly figure (mode 1 drawn
    at its largest excursion), "modes": per paired mode its label and per animated trace its
    displacement, "traces": which traces move, "base": their undeformed vertices}; None when
    the case has no FEM mode file or no pairs."""
    fem = case["fem"]
    pairs = sorted(case["pairs"], key=lambda p: p["fem_mode"])
    if not fem["vtu"] or not pairs:
        return None
    mesh, arrays, _ = read_modes((results_path.parent / fem["vtu"]).resolve())
    surface = mesh.extract_surface(nonlinear_subdivision=1, algorithm="dataset_surface")
    surface = surface.triangulate()
    points = np.asarray(surface.points, float)
    faces = surface.faces.reshape(-1, 4)[:, 1:]
    size = float(max(np.ptp(points, axis=0)))
    base, joints = joint_points(case)
    centre = platform_centre(case)
    radius = manipulator["platform_radius_mm"] * 1e-3
    plate = Platform(joints, centre, radius, manipulator["platform_thickness_mm"] * 1e-3, {})
    disk = None if _covers_platform(surface, plate) else _platform_disk(plate)
    stations, shapes = leg_axis_shapes(case)
    beam_size = max(float(max(base.max(0) - base.min(0))), float(joints[:, 2].max()))
    axes = [b + np.outer(stations, a - b) for b, a in zip(base, joints)]
    ring = _disk_ring(joints, centre, radius)
    legs0, ring0 = _with_breaks(axes), ring

    modes, animated = [], []
    for p in pairs:
        k, j = p["fem_mode"], p["analytical_mode"]
        if k not in arrays or j > shapes.shape[-1]:
            continue
        u = np.asarray(surface.point_data[arrays[k]], float)
        amp = float(np.linalg.norm(u, axis=1).max())
        scale = SCALE_FRACTION * size / amp if amp > 0 else 0.0
        shape = shapes[..., j - 1]
        beam_amp = float(np.abs(shape).max())
        beam_scale = SCALE_FRACTION * beam_size / beam_amp if beam_amp > 0 else 0.0
        moves = {"solid": scale * u,
                 "legs": beam_scale * _with_breaks(list(shape)),
                 "ring": beam_scale * _rigid(ring, centre, platform_motion(case["analytical"], j))}
        if disk is not None:
            moves["disk"] = scale * _rigid(np.asarray(disk.points), centre,
                                           platform_motion(fem, k))
        magnitude = np.linalg.norm(u, axis=1) / max(amp, 1e-300)
        modes.append({
            "label": (f"FEM mode {k}: {p['f_fem_hz']:.2f} Hz · beam mode {j}: "
                      f"{p['f_analytical_hz']:.2f} Hz · MAC {p['mac']:.3f}"),
            "fem_mode": k, "analytical_mode": j,
            "intensity": np.round(magnitude, 3).tolist(),
            "moves": {name: _xyz(np.nan_to_num(m)) for name, m in moves.items()}})
        animated.append(moves)
    if not modes:
        return None

    first = animated[0]
    fig = make_subplots(rows=1, cols=2, specs=[[{"type": "scene"}, {"type": "scene"}]],
                        subplot_titles=["FEM (3D solid)", "beam model"],
                        horizontal_spacing=0.02)
    index: dict[str, int] = {}
    starts = {"solid": points, "legs": legs0, "ring": ring0}
    fig.add_trace(go.Mesh3d(**_xyz(points), i=faces[:, 0], j=faces[:, 1], k=faces[:, 2],
                            color="#bbbbbb", opacity=0.15, hoverinfo="skip", name="undeformed",
                            flatshading=True), row=1, col=1)
    index["solid"] = 1
    fig.add_trace(go.Mesh3d(**_xyz(points + first["solid"]), i=faces[:, 0], j=faces[:, 1],
                            k=faces[:, 2], intensity=modes[0]["intensity"],
                            colorscale="Viridis", cmin=0, cmax=1, showscale=False,
                            hoverinfo="skip", name="FEM mode", flatshading=False),
                  row=1, col=1)
    if disk is not None:
        disk_points = np.asarray(disk.points, float)
        disk_faces = disk.faces.reshape(-1, 4)[:, 1:]
        starts["disk"] = disk_points
        fig.add_trace(go.Mesh3d(**_xyz(disk_points), i=disk_faces[:, 0], j=disk_faces[:, 1],
                                k=disk_faces[:, 2], color="#bbbbbb", opacity=0.15,
                                hoverinfo="skip"), row=1, col=1)
        index["disk"] = len(fig.data)
        fig.add_trace(go.Mesh3d(**_xyz(disk_points + first["disk"]), i=disk_faces[:, 0],
                                j=disk_faces[:, 1], k=disk_faces[:, 2], color="#8a8fa0",
                                hoverinfo="skip"), row=1, col=1)
    feet = base_circle_points(manipulator)  # a 3-PRS's rails start there
    t = np.linspace(0, 2 * math.pi, 73)
    circle = np.linalg.norm(feet[0, :2]) * np.stack([np.cos(t), np.sin(t), 0 * t], axis=1)
    rails = [np.stack([f, b]) for f, b in zip(feet, base) if np.linalg.norm(b - f) > 1e-9]
    fig.add_trace(go.Scatter3d(**_xyz(circle), mode="lines", hoverinfo="skip",
                               line=dict(color="#bfbfbf", width=2)), row=1, col=2)
    if rails:  # a 3-PRS: the rails from the base circle to the sliders, as the PDF draws
        fig.add_trace(go.Scatter3d(**_xyz(_with_breaks(rails)), mode="lines",
                                   hoverinfo="skip", line=dict(color="#737373", width=4)),
                      row=1, col=2)
    for line in (legs0, ring0):
        fig.add_trace(go.Scatter3d(**_xyz(line), mode="lines", hoverinfo="skip",
                                   line=dict(color="#a6a6a6", width=2, dash="dash")),
                      row=1, col=2)
    index["legs"] = len(fig.data)
    fig.add_trace(go.Scatter3d(**_xyz(legs0 + np.nan_to_num(first["legs"])), mode="lines",
                               hoverinfo="skip", line=dict(color="#31688e", width=7)),
                  row=1, col=2)
    index["ring"] = len(fig.data)
    fig.add_trace(go.Scatter3d(**_xyz(ring0 + first["ring"]), mode="lines", hoverinfo="skip",
                               line=dict(color="#444444", width=4)), row=1, col=2)
    eye = dict(x=1.6 * math.cos(math.radians(-60)), y=1.6 * math.sin(math.radians(-60)), z=0.8)
    scene = dict(aspectmode="data", camera=dict(eye=eye), xaxis_visible=False,
                 yaxis_visible=False, zaxis_visible=False)
    fig.update_layout(template="plotly_white", height=460, showlegend=False,
                      margin=dict(l=0, r=0, t=40, b=0), scene=scene, scene2=scene,
                      title=dict(text=modes[0]["label"], font=dict(size=13), x=0.5))
    return {"figure": fig, "modes": modes, "traces": index,
            "base": {name: _xyz(starts[name]) for name in index}}
