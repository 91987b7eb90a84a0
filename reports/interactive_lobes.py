"""The interactive charts of milling stability (issue 52): each case's lobes, the analytical
model's against the FEM's, and the least critical depth over the workspace map (polar panels
per layer, as the dynamic-stiffness map). Their static twins in report.pdf:
`cut_figures.case_lobes`, `study_maps.stability_map`."""
from __future__ import annotations

import plotly.graph_objects as go

from .interactive_charts import FEM_COLOUR, LAYOUT, SETTING_COLOURS, significant
from .interactive_maps import finite_array, grid_points, panel, polar_panels

LEAST_COLOUR = "#d62728"
BAND_COLOUR = "#1f77b4"
BAND_FILL = "rgba(31, 119, 180, 0.18)"


def case_lobes(record: dict, case: str) -> go.Figure | None:
    """Critical depth (mm) against spindle speed (rpm): the analytical model's lobes (line),
    the FEM's at the run's mesh (dashed) and one size coarser (dotted); hover: depth, chatter
    frequency and kind, and the analytical model's error against the FEM. None without a
    finite depth."""
    rpm = record["spindle_rpm"]
    curves = (("analytical", dict(color=SETTING_COLOURS[0], width=1.6)),
              ("fem", dict(color=FEM_COLOUR, width=1.4, dash="dash")),
              ("fem_coarse", dict(color=FEM_COLOUR, width=1.0, dash="dot")))
    if not any(v is not None for key, _ in curves for v in record[key]["critical_depth_mm"]):
        return None
    fig = go.Figure()
    for key, line in curves:
        c = record[key]
        extra = [significant(e, 4) for e in record["error_percent"]] if key == "analytical" \
            else [significant(e, 4) for e in record["fem_error_percent"]]
        label = "error against the FEM" if key == "analytical" else "FEM two-mesh error"
        data = [[significant(d, 5), significant(f, 5), k or "-", e]
                for d, f, k, e in zip(c["critical_depth_mm"], c["chatter_frequency_hz"],
                                      c["kind"], extra, strict=True)]
        fig.add_trace(go.Scatter(
            x=rpm, y=finite_array(c["critical_depth_mm"]), mode="lines", name=c["model"],
            line=line, customdata=data,
            hovertemplate="%{x:.0f} rpm: <b>%{customdata[0]} mm</b><br>chatter at "
            "%{customdata[1]} Hz (%{customdata[2]})<br>" + label + " %{customdata[3]} %"
            "<extra>" + c["model"] + "</extra>"))
    band = record.get("band")
    if band and not band["refused"]:
        add_band(fig, band)
    fig.update_layout(**LAYOUT, height=360, title=f"Stability lobes, {case}",
                      xaxis_title="spindle speed (rpm)",
                      yaxis_title="critical axial depth (mm), stable below")
    return fig


def add_band(fig: go.Figure, band: dict) -> None:
    """The critical depth's 95 % band over the scene's [uncertainty] (shaded, from the 2.5 %
    to the 97.5 % quantile of the draws) under the lobes; a speed where a quantile is stable
    up to the ceiling leaves a gap."""
    rpm = band["spindle_rpm"]
    name = f"95 % of {band['samples']} machines drawn from [uncertainty]"
    fig.add_trace(go.Scatter(x=rpm, y=finite_array(band["q025_depth_mm"]), mode="lines",
                             line=dict(width=0, color=BAND_COLOUR), showlegend=False,
                             hoverinfo="skip", name=name))
    fig.add_trace(go.Scatter(
        x=rpm, y=finite_array(band["q975_depth_mm"]), mode="lines", fill="tonexty",
        fillcolor=BAND_FILL, line=dict(width=0, color=BAND_COLOUR), name=name,
        customdata=[[significant(a, 4), significant(m, 4), significant(b, 4)]
                    for a, m, b in zip(band["q025_depth_mm"], band["median_depth_mm"],
                                       band["q975_depth_mm"], strict=True)],
        hovertemplate="%{x:.0f} rpm: 2.5 % of the machines chatter below "
        "<b>%{customdata[0]} mm</b><br>median %{customdata[1]} mm, 97.5 % "
        "%{customdata[2]} mm<extra>" + band["model"] + "</extra>"))


def stability_map(sm: dict) -> go.Figure | None:
    """The least critical depth over the speeds at every reachable pose of the map: one polar
    panel per height (angle = azimuth, radius = tilt), colour the depth (mm); the least pose
    starred. Hover: the pose, the least depth and its speed, the best speed and its depth, the
    chatter frequency at the least. None when no pose has a depth."""
    layers = [i for i, layer in enumerate(sm["least_depth_mm"])
              if any(v is not None for ring in layer for v in ring)]
    if not layers:
        return None
    titles = [f"z = {sm['heights_mm'][iz]:.0f} mm" for iz in layers]
    fig, _ = polar_panels(titles)
    values = [v for iz in layers for ring in sm["least_depth_mm"][iz] for v in ring
              if v is not None]
    lo, hi = min(values), max(values)
    template = ("z = %{customdata[0]:.1f} mm, θ = %{customdata[1]:.2f}°, φ = "
                "%{customdata[2]:.1f}°<br><b>least depth %{customdata[3]} mm</b> at "
                "%{customdata[4]:.0f} rpm (chatter %{customdata[5]} Hz)<br>best speed "
                "%{customdata[6]:.0f} rpm: %{customdata[7]} mm")
    for n, iz in enumerate(layers):
        grid = sm["least_depth_mm"][iz]
        points = [[significant(sm["heights_mm"][iz]), significant(sm["tilts_deg"][iz][r]),
                   significant(sm["azimuths_deg"][a]), significant(grid[r][a], 4),
                   sm["least_rpm"][iz][r][a], significant(sm["chatter_frequency_hz"][iz][r][a],
                                                          4),
                   sm["best_rpm"][iz][r][a], significant(sm["best_depth_mm"][iz][r][a], 4)]
                  for r, a in grid_points(grid)]
        fig.add_trace(go.Scatterpolar(
            r=[p[1] for p in points], theta=[p[2] for p in points], mode="markers",
            customdata=points, hovertemplate=template + "<extra>analytical</extra>",
            showlegend=False, name=titles[n],
            marker=dict(color=[p[3] for p in points], colorscale="Viridis", cmin=lo,
                        cmax=max(hi, lo * (1 + 1e-6)), size=8, line=dict(width=0),
                        showscale=n == 0, colorbar=dict(
                            title=dict(text="least depth (mm)", side="right"),
                            thickness=12))), **panel(n, titles))
    for row in sm["least"]:
        n = min(range(len(layers)),
                key=lambda i: abs(sm["heights_mm"][layers[i]] - row["height_mm"]))
        fig.add_trace(go.Scatterpolar(
            r=[row["tilt_deg"]], theta=[row["azimuth_deg"]], mode="markers",
            hovertemplate=f"<b>the least over the map: {row['depth_mm']:.4g} mm</b> at "
            f"{row['spindle_rpm']:.0f} rpm ({row['kind']}, chatter "
            f"{row['chatter_frequency_hz']:.4g} Hz)<extra>least</extra>", showlegend=False,
            marker=dict(symbol="star", size=16, color=LEAST_COLOUR,
                        line=dict(width=1, color="white"))), **panel(n, titles))
    fig.update_layout(**LAYOUT, height=330 * ((len(layers) + 3) // 4) + 40)
    return fig
