"""The report's interactive workspace charts (plotly), from results.json values only: the
frequency map of every layer, frequency against height, and the model against the FEM over the
validated poses; the twins of `workspace_figures` and `validation.error_maps`. And the least
dynamic stiffness at the tool over the same map (the dynamic_stiffness study), drawn the same
way; it has no static twin (report.pdf shows that study as its table)."""
from __future__ import annotations

import math
from typing import TypeVar

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from results import Workspace

from .interactive_charts import COLOURS, LAYOUT, significant

T = TypeVar("T")


def _finite(values) -> np.ndarray:
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
            values = _finite([d[3 + k] for d in data])
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
        values = [_finite([_reached(ws["frequencies_hz"][iz][r][a])[k]
                           for r, a in map_points(ws, iz)])
                  for iz in layers]  # NaN: a family lost at a pose, as the PDF skips it
        level = [float(_finite([_reached(ws["frequencies_hz"][iz][0][0])[k]])[0])
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
    errs = np.array([np.abs(_finite(p["models"][label])) for p in poses])
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




DIRECTIONS = ("x", "y", "z")  # the tool's directions, as the records key them
LEAST_COLOUR = "#d62728"  # the least pose's star: outside Viridis


def _compact(value: float) -> str:
    """A value to three significant digits, its exponent short: 2e5, 1.79e5, 83.7."""
    mantissa, _, exponent = f"{value:.3g}".partition("e")
    return mantissa + (f"e{int(exponent)}" if exponent else "")


def _log_ticks(lo: float, hi: float) -> tuple[list[float], list[str]]:
    """Colour-bar ticks of a log10 colour between 10**lo and 10**hi, as log10 and labels: the
    powers of ten (every few over many decades) where at least three fall inside, else
    1, 2, 5 x 10^n, else every digit x 10^n; with fewer than three even then, the two ends
    and the digits not crowding them."""
    def labelled(values: list[float]) -> tuple[list[float], list[str]]:
        return [math.log10(v) for v in values], [_compact(v) for v in values]

    def inside(values) -> list[float]:
        return [v for v in values if lo - 1e-9 <= math.log10(v) <= hi + 1e-9]

    exponents = range(math.floor(lo), math.ceil(hi) + 1)
    values = inside(10.0 ** e for e in exponents[::max(1, math.ceil((hi - lo) / 6))])
    for digits in ((1, 2, 5), range(1, 10)):
        if len(values) >= 3:
            return labelled(values)
        values = inside(m * 10.0 ** e for e in exponents for m in digits)
    if len(values) >= 3:
        return labelled(values)
    gap = 0.15 * (hi - lo)
    return labelled(sorted({10.0 ** lo, 10.0 ** hi,
                            *(v for v in values if lo + gap < math.log10(v) < hi - gap)}))


def stiffness_layers(ds: dict) -> list[int]:
    """The dynamic-stiffness map's layers with a stiffness in at least one direction."""
    return [i for i in range(len(ds["heights_mm"]))
            if any(v is not None for d in DIRECTIONS if d in ds["stiffness_n_per_m"]
                   for ring in ds["stiffness_n_per_m"][d][i] for v in ring)]


def dynamic_stiffness_map(ds: dict) -> go.Figure | None:
    """The least dynamic stiffness at the tool, 1 / max |H_dd|, over every layer of the map:
    one polar panel per height (angle = azimuth, radius = tilt), a direction selector, colour
    log10 of the stiffness on one scale per direction (N/m); the least pose of each direction
    starred. Hover: the pose, the stiffness, the frequency of its peak and the mode dominating
    it. A pose where the tool does not move along d (or not reached) has no point. None when
    no layer has a stiffness."""
    layers = stiffness_layers(ds)
    directions = [d for d in DIRECTIONS if d in ds["stiffness_n_per_m"] and any(
        v is not None for iz in layers for ring in ds["stiffness_n_per_m"][d][iz] for v in ring)]
    if not directions:
        return None
    heights = [f"z = {ds['heights_mm'][iz]:.0f} mm" for iz in layers]
    fig, rows = polar_panels(heights)
    owner: list[int] = []
    titles: list[list[str]] = []
    template = ("z = %{customdata[0]:.1f} mm, θ = %{customdata[1]:.2f}°, φ = "
                "%{customdata[2]:.1f}°<br><b>k_{d} = %{customdata[3]:.4g} N/m</b><br>"
                "peak of |H_{d}{d}| at %{customdata[4]:.2f} Hz, mode %{customdata[5]}")
    for k, d in enumerate(directions):
        k_grid, f_grid, m_grid = (ds[key][d] for key in ("stiffness_n_per_m", "peak_hz", "mode"))
        data = [[[*(significant(v) for v in (ds["heights_mm"][iz], ds["tilts_deg"][iz][r],
                                              ds["azimuths_deg"][a], k_grid[iz][r][a],
                                              f_grid[iz][r][a])), m_grid[iz][r][a]]
                 for r, a in grid_points(k_grid[iz])] for iz in layers]
        values = [np.round(np.log10(_finite([p[3] for p in points])), 4) for points in data]
        lo = float(np.nanmin(np.concatenate(values)))
        hi = float(np.nanmax(np.concatenate(values)))
        ticks, labels = _log_ticks(lo, hi)
        scale = next(n for n, points in enumerate(data) if points)  # the panel with the bar
        titles.append([])
        for n, (iz, points) in enumerate(zip(layers, data)):
            shown = [v for v in values[n] if np.isfinite(v)]
            titles[k].append(f"{heights[n]}: " + (  # the unit on the colour bar
                f"{_compact(10 ** min(shown))}–{_compact(10 ** max(shown))}" if shown else "–"))
            fig.add_trace(go.Scatterpolar(
                r=[p[1] for p in points], theta=[p[2] for p in points], mode="markers",
                customdata=points, hovertemplate=template.replace("{d}", d)
                + "<extra>analytical</extra>", visible=k == 0,
                name=f"k_{d}, {heights[n]}", showlegend=False,
                marker=dict(color=values[n], colorscale="Viridis", cmin=lo,
                            cmax=max(hi, lo + 1e-6), size=7, line=dict(width=0),
                            showscale=n == scale, colorbar=dict(
                                title=dict(text=f"k_{d} (N/m)", side="right"),
                                tickvals=ticks, ticktext=labels, thickness=12))),
                **panel(n, heights))
            owner.append(k)
        for row in ds["least"]:
            if row["direction"] != d:
                continue
            n = min(range(len(layers)),
                    key=lambda i: abs(ds["heights_mm"][layers[i]] - row["height_mm"]))
            fig.add_trace(go.Scatterpolar(
                r=[row["tilt_deg"]], theta=[row["azimuth_deg"]], mode="markers",
                customdata=[[row["height_mm"], row["tilt_deg"], row["azimuth_deg"],
                             row["stiffness_n_per_m"], row["frequency_hz"], row["mode"]]],
                hovertemplate="<b>the least over the map</b><br>" + template.replace("{d}", d)
                + "<extra>least</extra>", visible=k == 0, name=f"least k_{d}",
                showlegend=False, marker=dict(symbol="star", size=16, color=LEAST_COLOUR,
                                              line=dict(width=1, color="white"))),
                **panel(n, heights))
            owner.append(k)
    switched_panels(fig, rows, [f"k_{d}" for d in directions], owner, titles)
    return fig
