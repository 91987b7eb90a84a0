"""The interactive charts of input uncertainty (issue 39): what drives each case's spread (the
Sobol' indices of every input, per output) and the 95 % band of f1 and of the least dynamic
stiffness along the workspace map's worst path. Their static twins
in report.pdf: `study_figures.sobol_bars`, `study_figures.path_band`."""
from __future__ import annotations

import plotly.graph_objects as go
from plotly.subplots import make_subplots

from .interactive_charts import FEM_COLOUR, LAYOUT, SETTING_COLOURS, significant
from .study_figures import input_label

BAND_COLOUR = "rgba(31, 119, 180, 0.18)"


def sobol_bars(record: dict, case: str) -> go.Figure | None:
    """Per output (f1.., least x..), each input's total Sobol' index (bars, with their 95 %
    sampling error) and first-order index (diamonds): the share of the output's variance the
    input explains with (total) and without (first) its interactions. None without indices."""
    rows = [r for r in record["sobol"] if r["total"] is not None]
    if not rows:
        return None
    outputs = list(dict.fromkeys(r["output"] for r in rows))
    keys = list(dict.fromkeys(r["key"] for r in rows))
    units = {i["key"]: i["unit"] for i in record["inputs"]}
    labels = {key: input_label(key, units.get(key, "")) for key in keys}  # in words, as the
    # static twin's legend
    fig = go.Figure()
    for k, key in enumerate(keys):
        mine = {r["output"]: r for r in rows if r["key"] == key}
        colour = SETTING_COLOURS[k % len(SETTING_COLOURS)]
        fig.add_trace(go.Bar(
            x=outputs, y=[significant(mine[o]["total"]) if o in mine else None for o in outputs],
            error_y=dict(type="data", array=[significant(mine[o]["total_error"] or 0.0)
                                             if o in mine else 0.0 for o in outputs]),
            name=labels[key], legendgroup=key, marker_color=colour, offsetgroup=str(k),
            hovertemplate=f"{labels[key]}<br>%{{x}}: total index %{{y:.3f}}<extra>{case}</extra>"))
        fig.add_trace(go.Scatter(
            x=outputs, y=[significant(mine[o]["first"]) if o in mine else None
                          for o in outputs],
            mode="markers", marker=dict(symbol="diamond", size=8, color="white",
                                        line=dict(color=colour, width=2)),
            name=f"{labels[key]}, first order", legendgroup=key, showlegend=False,
            offsetgroup=str(k),
            hovertemplate=f"{labels[key]}<br>%{{x}}: first-order index %{{y:.3f}}"
                          f"<extra>{case}</extra>"))
    fig.update_layout(**LAYOUT, barmode="group", scattermode="group", height=380,
                      yaxis=dict(title="Sobol' index (share of the variance)",
                                 range=[0, 1.05]),
                      legend=dict(orientation="h", y=-0.2))
    return fig


def path_band(record: dict) -> go.Figure | None:
    """Along the worst path (the pose of least nominal f1 on each layer, by height): the
    nominal f1 and its 95 % band; beside it the least dynamic stiffness at the tool (log) and
    its band where the scene asks for it. Hover: the pose."""
    poses = record["poses"]
    if not poses:
        return None
    stiffness = any(p["least_nominal_n_per_m"] is not None for p in poses)
    fig = make_subplots(rows=1, cols=2 if stiffness else 1, horizontal_spacing=0.1,
                        subplot_titles=["f1 (Hz)"] + (["least dynamic stiffness (N/m)"]
                                                      if stiffness else []))
    z = [significant(p["height_mm"]) for p in poses]
    pose = [[significant(p["tilt_deg"]), significant(p["azimuth_deg"])] for p in poses]
    where = "z = %{x:.1f} mm, θ = %{customdata[0]:.2f}°, φ = %{customdata[1]:.1f}°<br>"
    panels = [("f1", "_hz", "Hz", 1)] + ([("least", "_n_per_m", "N/m", 2)] if stiffness else [])
    for name, unit, shown, col in panels:
        nominal = "f1_nominal_hz" if name == "f1" else "least_nominal_n_per_m"
        low, high = (f"{name}_q025{unit}", f"{name}_q975{unit}")
        fig.add_trace(go.Scatter(x=z, y=[significant(p[high]) for p in poses], mode="lines",
                                 line=dict(width=0), showlegend=False, hoverinfo="skip"),
                      row=1, col=col)
        fig.add_trace(go.Scatter(
            x=z, y=[significant(p[low]) for p in poses], mode="lines", line=dict(width=0),
            fill="tonexty", fillcolor=BAND_COLOUR, name="95 % band", legendgroup="band",
            showlegend=col == 1, customdata=[[*c, significant(p[high])] for c, p
                                             in zip(pose, poses)],
            hovertemplate=where + f"95 %: %{{y:.4g}} .. %{{customdata[2]:.4g}} {shown}"
            "<extra>inputs</extra>"), row=1, col=col)
        fig.add_trace(go.Scatter(
            x=z, y=[significant(p[nominal]) for p in poses], mode="lines+markers",
            line=dict(color=FEM_COLOUR if col == 2 else SETTING_COLOURS[0], width=1.5),
            name="at the scene's values", legendgroup="nominal", showlegend=col == 1,
            customdata=pose, hovertemplate=where + f"%{{y:.4g}} {shown}"
            "<extra>scene's values</extra>"), row=1, col=col)
        fig.update_xaxes(title_text="height of the layer, z (mm)", row=1, col=col)
    if stiffness:
        fig.update_yaxes(type="log", row=1, col=2)
    fig.update_layout(**LAYOUT, height=360, legend=dict(orientation="h", y=-0.25))
    return fig
