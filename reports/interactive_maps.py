"""The report's interactive workspace charts (plotly), from results.json values only: the
frequency map of every layer, frequency against height, and the model against the FEM over the
validated poses; the twins of `workspace_figures` and `validation.error_maps`. And the least
dynamic stiffness at the tool over the same map (the dynamic_stiffness study), drawn the same
way; its static twin is `study_maps.dynamic_stiffness_map`."""
from __future__ import annotations

from typing import TypeVar

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from results import Workspace

from .interactive_charts import COLOURS, LAYOUT

T = TypeVar("T")


def finite_array(values) -> np.ndarray:
    """Floats, NaN where a value is None (an unreached pose)."""
    return np.array([np.nan if v is None else v for v in values], float)


def _reached(values: list[T] | None) -> list[T]:
    """A map pose's values, None only where the pose is unreachable (TypeError there, as
    reading None would raise)."""
    if values is None:
        raise TypeError("a map pose's values are None: the pose is unreachable")
    return values


def valid_layers(ws: Workspace) -> list[int]:
    """The map's layers with at least one reachable pose."""
    return [i for i, layer in enumerate(ws["frequencies_hz"])
            if any(az is not None and az[0] is not None for ring in layer for az in ring)]


def grid_points(layer: list[list[T]], held=lambda value: value is not None
                ) -> list[tuple[int, int]]:
    """(ring, azimuth) of every pose of a map layer ([ring][azimuth]) whose value is `held`,
    the level pose (ring 0, the same pose at every azimuth) once."""
    return [(r, a) for r, ring in enumerate(layer) for a, value in enumerate(ring)
            if held(value) and (r > 0 or a == 0)]


def map_points(ws: Workspace, iz: int) -> list[tuple[int, int]]:
    """(ring, azimuth) of every reachable pose of layer iz, the level pose (ring 0) once."""
    return grid_points(ws["frequencies_hz"][iz], lambda az: az is not None and az[0] is not None)


def polar_panels(titles: list[str]) -> tuple[go.Figure, int]:
    """A figure of one polar panel per title (a map layer), four a row; and its rows."""
    cols = min(4, len(titles))
    rows = -(-len(titles) // cols)
    fig = make_subplots(rows=rows, cols=cols, specs=[[{"type": "polar"}] * cols] * rows,
                        subplot_titles=titles, horizontal_spacing=0.06, vertical_spacing=0.12)
    return fig, rows


def panel(n: int, titles: list[str]) -> dict:
    """The row and column of polar panel n (0-based) of `polar_panels(titles)`."""
    cols = min(4, len(titles))
    return dict(row=n // cols + 1, col=n % cols + 1)


def switched_panels(fig: go.Figure, rows: int, labels: list[str], owner: list[int],
                    titles: list[list[str]]) -> None:
    """Lay out a figure of `polar_panels` whose traces are shown one choice at a time: a
    button per label, trace j shown under button owner[j], choice k's panel titles
    titles[k] (the first choice shown)."""
    for annotation, title in zip(fig.layout.annotations, titles[0]):
        annotation.text = title
    buttons = [dict(label=label, method="update", args=[
        {"visible": [o == k for o in owner]},
        {f"annotations[{n}].text": title for n, title in enumerate(titles[k])}])
        for k, label in enumerate(labels)]
    fig.update_layout(**LAYOUT, height=330 * rows + 60, updatemenus=[dict(
        type="buttons", direction="right", buttons=buttons, x=0, y=1.0 + 0.12 / rows,
        xanchor="left", yanchor="bottom", showactive=True)])
    fig.update_annotations(font=dict(size=12))
    fig.update_polars(radialaxis=dict(ticksuffix="°", tickfont=dict(size=9)),
                      angularaxis=dict(tickfont=dict(size=9)))


def workspace_map(ws: Workspace, model: str, actuator: str) -> go.Figure:
    """f_k over every layer of the regular workspace: one polar panel per height (angle =
    azimuth, radius = tilt), a mode selector; hover: the pose, its actuators and joint
    angles, and every mode's frequency there."""
    layers = valid_layers(ws)
    modes = len(next(az for ring in ws["frequencies_hz"][layers[0]] for az in ring if az))
    heights = [f"z = {ws['heights_mm'][iz]:.0f} mm" for iz in layers]
    fig, rows = polar_panels(heights)
    unit = "leg lengths" if actuator == "leg length" else "slider travels"
    lines = [f"f{k + 1} = %{{customdata[{3 + k}]:.2f}} Hz" for k in range(modes)]
    titles: list[list[str]] = [[] for _ in range(modes)]
    for k in range(modes):
        lines_k = list(lines)
        lines_k[k] = f"<b>{lines_k[k]}</b>"
        template = ("z = %{customdata[0]:.1f} mm, θ = %{customdata[1]:.2f}°, "
                    "φ = %{customdata[2]:.1f}°<br>" + "<br>".join(lines_k)
                    + f"<br>{unit} (mm): " + ", ".join(
                        f"%{{customdata[{3 + modes + i}]:.1f}}" for i in range(3))
                    + "<br>S-joint angles (°): " + ", ".join(
                        f"%{{customdata[{6 + modes + i}]:.1f}}" for i in range(3))
                    + "<br>R-joint angles (°): " + ", ".join(
                        f"%{{customdata[{9 + modes + i}]:.1f}}" for i in range(3))
                    + f"<extra>{model}</extra>")
        for n, iz in enumerate(layers):
            points = map_points(ws, iz)
            data = [[ws["heights_mm"][iz], ws["tilts_deg"][iz][r], ws["azimuths_deg"][a],
                     *_reached(ws["frequencies_hz"][iz][r][a]),
                     *_reached(ws["actuation_mm"][iz][r][a]),
                     *_reached(ws["s_joint_angles_deg"][iz][r][a]),
                     *_reached(ws["r_joint_angles_deg"][iz][r][a])]
                    for r, a in points]
            values = finite_array([d[3 + k] for d in data])
            lo, hi = float(np.nanmin(values)), float(np.nanmax(values))
            titles[k].append(f"z = {ws['heights_mm'][iz]:.0f} mm: f{k + 1} "
                             f"{lo:.1f}–{hi:.1f} Hz")
            fig.add_trace(go.Scatterpolar(
                r=[d[1] for d in data], theta=[d[2] for d in data], mode="markers",
                customdata=data, hovertemplate=template, visible=k == 0,
                name=f"f{k + 1}, z = {ws['heights_mm'][iz]:.0f} mm", showlegend=False,
                marker=dict(color=values, colorscale="Viridis", cmin=lo,
                            cmax=max(hi, lo + 1e-6 * max(abs(lo), 1.0)), size=7,
                            line=dict(width=0))), **panel(n, heights))
    switched_panels(fig, rows, [f"f{k + 1}" for k in range(modes)],
                    [k for k in range(modes) for _ in layers], titles)
    return fig


def workspace_height(ws: Workspace) -> go.Figure:
    """f_k of the level platform against height, and each layer's range (bands)."""
    layers = valid_layers(ws)
    z = [ws["heights_mm"][iz] for iz in layers]
    modes = len(next(az for ring in ws["frequencies_hz"][layers[0]] for az in ring if az))
    fig = go.Figure()
    for k in range(modes):
        values = [finite_array([_reached(ws["frequencies_hz"][iz][r][a])[k]
                           for r, a in map_points(ws, iz)])
                  for iz in layers]  # NaN: a family lost at a pose, as the PDF skips it
        level = [float(finite_array([_reached(ws["frequencies_hz"][iz][0][0])[k]])[0])
                 for iz in layers]
        lo, hi = [float(np.nanmin(v)) for v in values], [float(np.nanmax(v)) for v in values]
        colour = COLOURS[k % len(COLOURS)]
        fig.add_trace(go.Scatter(x=z, y=lo, mode="lines", line=dict(width=0, color=colour),
                                 hoverinfo="skip", showlegend=False))
        fig.add_trace(go.Scatter(x=z, y=hi, mode="lines", line=dict(width=0, color=colour),
                                 fill="tonexty", opacity=0.2, hoverinfo="skip",
                                 showlegend=False))
        fig.add_trace(go.Scatter(
            x=z, y=level, mode="lines+markers", name=f"f{k + 1}, level platform",
            line=dict(color=colour), customdata=np.stack([lo, hi], axis=1),
            hovertemplate=(f"z = %{{x:.1f}} mm<br>f{k + 1}, level: %{{y:.2f}} Hz<br>"
                           "layer range: %{customdata[0]:.2f} to %{customdata[1]:.2f} Hz"
                           "<extra></extra>")))
    fig.update_layout(**LAYOUT, height=380, xaxis_title="platform height z (mm)",
                      yaxis_title="frequency (Hz)")
    return fig


def validation_map(wv: dict) -> go.Figure:
    """|error| of the run's model per mode over the validated poses (angle = azimuth, radius =
    tilt, every height), and each pose's worst |error| against its shortest leg in
    diameters; hover: the pose, the FEM limit and every model's error there."""
    label = wv["default_model"]
    poses = [p for p in wv["poses"] if p["models"] and label in p["models"]]
    errs = np.array([np.abs(finite_array(p["models"][label])) for p in poses])
    modes = errs.shape[1]
    cols = 4
    rows = -(-modes // 3)
    polar: list[dict | None] = [{"type": "polar"}] * 3
    specs = [polar + [{"type": "xy"} if r == 0 else None] for r in range(rows)]
    fig = make_subplots(rows=rows, cols=cols, specs=specs, horizontal_spacing=0.07,
                        subplot_titles=[f"f{k + 1}" for k in range(3)]
                        + ["worst |error| per pose"] + [f"f{k + 1}" for k in range(3, modes)])
    top = float(np.nanmax(errs)) if np.isfinite(errs).any() else 1.0
    names = list(poses[0]["models"]) if poses else []  # the candidates in the run's order

    def text(p: dict, k: int) -> str:
        fem = p["fem_limit_hz"][k]
        head = (f"z = {p['height_mm']:.1f} mm, θ = {p['tilt_deg']:.2f}°, "
                f"φ = {p['azimuth_deg']:.1f}° ({p['kind']})<br>"
                f"FEM limit f{k + 1} = " + ("–" if fem is None else f"{fem:.2f} Hz"))
        def row(n: str) -> str:
            e = p["models"][n][k]  # the paired mode's error: f = f_FEM (1 + e / 100)
            value = "–" if e is None else (
                f"{e:+.3f} %" if fem is None else f"{fem * (1 + e / 100):.2f} Hz ({e:+.3f} %)")
            return f"<b>{n}: {value}</b>" if n == label else f"{n}: {value}"
        return (head + "<br>each model's paired f" + str(k + 1) + " (error vs FEM limit):<br>"
                + "<br>".join(row(n) for n in names if n in p["models"]))

    for k in range(modes):
        fig.add_trace(go.Scatterpolar(
            r=[p["tilt_deg"] for p in poses], theta=[p["azimuth_deg"] for p in poses],
            mode="markers", text=[text(p, k) for p in poses], hoverinfo="text",
            name=f"f{k + 1}", showlegend=False,
            marker=dict(color=errs[:, k], coloraxis="coloraxis", size=7)),
            row=k // 3 + 1, col=k % 3 + 1)
    worst = np.nanmax(errs, axis=1)
    fig.add_trace(go.Scatter(
        x=[p["slenderness"][0] for p in poses], y=worst, mode="markers", showlegend=False,
        marker=dict(color="#333333", size=6),
        text=[f"z = {p['height_mm']:.1f} mm, θ = {p['tilt_deg']:.2f}°, "
              f"φ = {p['azimuth_deg']:.1f}°" for p in poses],
        hovertemplate="%{text}<br>shortest leg / diameter: %{x:.2f}<br>worst |error|: "
                      "%{y:.3f} %<extra></extra>"), row=1, col=cols)
    fig.update_xaxes(title_text="shortest leg / diameter", row=1, col=cols)
    fig.update_yaxes(title_text="worst |error| (%)", row=1, col=cols)
    fig.update_layout(**LAYOUT, height=320 * rows + 80, coloraxis=dict(
        colorscale="Viridis", cmin=0, cmax=top, colorbar=dict(
            title=dict(text="|error vs FEM limit| (%)", side="right"), orientation="h",
            x=0.35, y=-0.12, len=0.6, thickness=12)))
    fig.update_polars(radialaxis=dict(ticksuffix="°", tickfont=dict(size=9)),
                      angularaxis=dict(tickfont=dict(size=9)))
    return fig
