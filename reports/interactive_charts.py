"""The report's interactive charts (plotly), drawn from results.json values only.

Each function is the interactive twin of a static picture in `figures`, `workspace_figures`,
`validation` or `real_machine`, from the same record of results.json, with the same marks (the
paper's s, the chosen setting, the pairs, the scene's drive), so the HTML and the PDF can never
disagree; what the static picture cannot give, hover gives: every value at a point.
"""
from __future__ import annotations

import math

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
           "#7f7f7f", "#bcbd22", "#17becf")  # matplotlib's tab10, as the static figures
FEM_COLOUR = "#d62728"
SETTING_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2",
                   "#7f7f7f")  # the static speed figure's, red left to the FEM
LAYOUT = dict(template="plotly_white", font=dict(size=12), margin=dict(l=60, r=20, t=50, b=50),
              hoverlabel=dict(align="left"))


def _finite(values) -> np.ndarray:
    return np.array([np.nan if v is None else v for v in values], float)


def valid_layers(ws: dict) -> list[int]:
    """The map's layers with at least one reachable pose."""
    return [i for i, layer in enumerate(ws["frequencies_hz"])
            if any(az is not None and az[0] is not None for ring in layer for az in ring)]


def map_points(ws: dict, iz: int) -> list[tuple[int, int]]:
    """(ring, azimuth) of every reachable pose of layer iz, the level pose (ring 0) once."""
    layer = ws["frequencies_hz"][iz]
    return [(r, a) for r, ring in enumerate(layer) for a, az in enumerate(ring)
            if az is not None and az[0] is not None and (r > 0 or a == 0)]


def workspace_map(ws: dict, model: str, actuator: str) -> go.Figure:
    """f_k over every layer of the regular workspace: one polar panel per height (angle =
    azimuth, radius = tilt), a mode selector; hover: the pose, its actuators and joint
    angles, and every mode's frequency there."""
    layers = valid_layers(ws)
    modes = len(next(az for ring in ws["frequencies_hz"][layers[0]] for az in ring if az))
    cols = min(4, len(layers))
    rows = -(-len(layers) // cols)
    fig = make_subplots(rows=rows, cols=cols, specs=[[{"type": "polar"}] * cols] * rows,
                        subplot_titles=[f"z = {ws['heights_mm'][iz]:.0f} mm" for iz in layers],
                        horizontal_spacing=0.06, vertical_spacing=0.12)
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
                     *ws["frequencies_hz"][iz][r][a], *ws["actuation_mm"][iz][r][a],
                     *ws["s_joint_angles_deg"][iz][r][a], *ws["r_joint_angles_deg"][iz][r][a]]
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
                            line=dict(width=0))), row=n // cols + 1, col=n % cols + 1)
    for annotation, title in zip(fig.layout.annotations, titles[0]):
        annotation.text = title
    per_mode = len(layers)
    buttons = [dict(label=f"f{k + 1}", method="update", args=[
        {"visible": [j // per_mode == k for j in range(modes * per_mode)]},
        {f"annotations[{n}].text": title for n, title in enumerate(titles[k])}])
        for k in range(modes)]
    fig.update_layout(**LAYOUT, height=330 * rows + 60, updatemenus=[dict(
        type="buttons", direction="right", buttons=buttons, x=0, y=1.0 + 0.12 / rows,
        xanchor="left", yanchor="bottom", showactive=True)])
    fig.update_annotations(font=dict(size=12))
    fig.update_polars(radialaxis=dict(ticksuffix="°", tickfont=dict(size=9)),
                      angularaxis=dict(tickfont=dict(size=9)))
    return fig


def workspace_height(ws: dict) -> go.Figure:
    """f_k of the level platform against height, and each layer's range (bands)."""
    layers = valid_layers(ws)
    z = [ws["heights_mm"][iz] for iz in layers]
    modes = len(next(az for ring in ws["frequencies_hz"][layers[0]] for az in ring if az))
    fig = go.Figure()
    for k in range(modes):
        values = [np.array([ws["frequencies_hz"][iz][r][a][k] for r, a in map_points(ws, iz)],
                           float) for iz in layers]
        level = [float(ws["frequencies_hz"][iz][0][0][k]) for iz in layers]
        lo, hi = [float(v.min()) for v in values], [float(v.max()) for v in values]
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
    names = sorted(poses[0]["models"]) if poses else []

    def text(p: dict, k: int) -> str:
        fem = p["fem_limit_hz"][k]
        head = (f"z = {p['height_mm']:.1f} mm, θ = {p['tilt_deg']:.2f}°, "
                f"φ = {p['azimuth_deg']:.1f}° ({p['kind']})<br>"
                f"FEM limit f{k + 1} = " + ("–" if fem is None else f"{fem:.2f} Hz"))
        rows_ = [f"{'<b>' if n == label else ''}{n}: "
                 + ("–" if p["models"][n][k] is None else f"{p['models'][n][k]:+.3f} %")
                 + ("</b>" if n == label else "") for n in names if n in p["models"]]
        return head + "<br>error vs FEM limit:<br>" + "<br>".join(rows_)

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


def speed_vs_error(entries: dict[str, list[dict]], chosen: set[str],
                   paper_seconds: dict | None) -> go.Figure:
    """Time per pose against the worst |error| of f1-f6, per case: each setting a curve
    through its refinements; the chosen settings ringed; the paper's times as lines."""
    names = list(entries)
    fig = make_subplots(rows=1, cols=len(names), subplot_titles=names, shared_yaxes=True,
                        horizontal_spacing=0.05)
    seen: list[str] = []
    for c, name in enumerate(names, start=1):
        groups: dict[str, list[dict]] = {}
        for e in entries[name]:
            key = "fem" if e["model"] == "fem" else e["setting"].rsplit(",", 1)[0].strip()
            groups.setdefault(key, []).append(e)
        for key, rows in groups.items():
            if key not in seen:
                seen.append(key)
            colour = FEM_COLOUR if key == "fem" else SETTING_COLOURS[
                seen.index(key) % len(SETTING_COLOURS)]
            label = "FEM (3D solid)" if key == "fem" else key.replace("EB", "Euler–Bernoulli")
            fig.add_trace(go.Scatter(
                x=[max(e["seconds"], 1e-6) for e in rows],
                y=[max(abs(e["worst_error_percent"]), 1e-3) for e in rows],
                mode="lines+markers", name=label, legendgroup=key, showlegend=c == 1,
                line=dict(color=colour, width=1), marker=dict(size=7),
                text=[e["setting"] for e in rows],
                customdata=[abs(e["worst_error_percent"]) for e in rows],
                hovertemplate=("%{text}<br>worst |error| of f1–f6: %{customdata:.3g} %<br>"
                               "time per pose: %{x:.3g} s<extra>" + name + "</extra>")),
                row=1, col=c)
        picked = [e for e in entries[name] if e["setting"] in chosen]
        fig.add_trace(go.Scatter(
            x=[max(e["seconds"], 1e-6) for e in picked],
            y=[max(abs(e["worst_error_percent"]), 1e-3) for e in picked],
            mode="markers", name="chosen by the run", legendgroup="chosen",
            showlegend=c == 1, marker=dict(size=16, symbol="circle-open", color="black",
                                           line=dict(width=2)),
            text=[e["setting"] for e in picked],
            hovertemplate="chosen: %{text}<extra></extra>"), row=1, col=c)
        for model, t in (paper_seconds or {}).items():
            fig.add_vline(x=t, line=dict(color="#595959", dash="dash", width=1), row=1, col=c)
            fig.add_annotation(x=math.log10(t), y=1, yref="paper",  # log axis: log10
                               xref="x" if c == 1 else f"x{c}", yanchor="top",
                               xanchor="right", text=f"paper: {model} {t:g} s", textangle=-90,
                               showarrow=False, font=dict(size=10, color="#4d4d4d"))
    fig.update_xaxes(type="log", title_text="time per pose (s)")
    fig.update_yaxes(type="log", title_text="worst |error| of f1–f6 (%)", col=1)
    fig.update_layout(**LAYOUT, height=560, legend=dict(orientation="h", y=-0.18,
                                                        font=dict(size=10)))
    return fig


def element_convergence(conv: dict, reference_hz, reference_label: str,
                        paper_elements: int = 3) -> go.Figure:
    """Error of f1..f6 against elements per leg s, one panel per beam theory (Fig. 3)."""
    beams = [b for b in ("euler-bernoulli", "timoshenko") if b in conv]
    ref = np.asarray(reference_hz, float)
    fig = make_subplots(rows=1, cols=len(beams), shared_yaxes=True, subplot_titles=[
        "Euler–Bernoulli" if b == "euler-bernoulli" else "Timoshenko" for b in beams])
    for c, beam in enumerate(beams, start=1):
        s = conv[beam]["elements"]
        f = np.asarray(conv[beam]["frequencies_hz"], float)
        n = min(f.shape[1], len(ref))
        for k in range(n):
            fig.add_trace(go.Scatter(
                x=s, y=100 * (f[:, k] / ref[k] - 1), mode="lines+markers", name=f"f{k + 1}",
                legendgroup=f"f{k + 1}", showlegend=c == 1,
                line=dict(color=COLOURS[k % len(COLOURS)]), customdata=f[:, k],
                hovertemplate=(f"s = %{{x}}<br>f{k + 1} = %{{customdata:.3f}} Hz<br>error vs "
                               f"{reference_label}: %{{y:+.3f}} %<extra></extra>")),
                row=1, col=c)
        fig.add_vline(x=paper_elements, line=dict(color="#7f7f7f", dash="dot", width=1),
                      row=1, col=c)
    fig.update_xaxes(title_text="elements per leg s (–)")
    fig.update_yaxes(title_text=f"error vs {reference_label} (%)", col=1)
    fig.update_layout(**LAYOUT, height=400)
    return fig


def fem_refinement(ref: dict, scene_size_m: float | None) -> go.Figure:
    """FEM frequencies against mesh size h per mode, with the extrapolated h -> 0 limit."""
    h = np.asarray(ref["sizes_m"], float) * 1e3
    f = np.asarray(ref["frequencies_hz"], float)
    n = f.shape[1]
    cols = 3
    rows = -(-n // cols)
    fig = make_subplots(rows=rows, cols=cols, subplot_titles=[f"f{k + 1}" for k in range(n)],
                        vertical_spacing=0.14, horizontal_spacing=0.09)
    for k in range(n):
        row, col = k // cols + 1, k % cols + 1
        fig.add_trace(go.Scatter(
            x=h, y=f[:, k], mode="lines+markers", name="FEM", legendgroup="fem",
            showlegend=k == 0, line=dict(color=COLOURS[k % len(COLOURS)]),
            hovertemplate=f"h = %{{x:.3g}} mm<br>f{k + 1} = %{{y:.4f}} Hz<extra></extra>"),
            row=row, col=col)
        limit = ref["extrapolated_hz"][k]
        if limit is not None:
            fig.add_trace(go.Scatter(
                x=[0], y=[limit], mode="markers", name="extrapolated (h → 0)",
                legendgroup="limit", showlegend=k == 0,
                marker=dict(symbol="star", size=12, color="black"),
                hovertemplate=(f"f{k + 1} limit (h → 0) = %{{y:.4f}} Hz<br>status: "
                               f"{ref['status'][k]}<extra></extra>")), row=row, col=col)
            fig.add_hline(y=limit, line=dict(color="#666666", dash="dash", width=1),
                          row=row, col=col)
        if scene_size_m:
            fig.add_vline(x=scene_size_m * 1e3, line=dict(color="#999999", dash="dot",
                                                          width=1), row=row, col=col)
    fig.update_xaxes(title_text="mesh size h (mm)", rangemode="tozero")
    fig.update_yaxes(title_text="frequency (Hz)", col=1, tickformat=".2f")
    fig.update_layout(**LAYOUT, height=300 * rows + 60)
    return fig


def mac_matrix(mac, pairs) -> go.Figure:
    """MAC(analytical mode i, FEM mode j) as a heat map, the chosen pairs outlined in red."""
    m = np.asarray(mac, float)
    fig = go.Figure(go.Heatmap(
        z=m, x=list(range(1, m.shape[1] + 1)), y=list(range(1, m.shape[0] + 1)),
        zmin=0, zmax=1, colorscale="Blues", text=np.round(m, 2), texttemplate="%{text:.2f}",
        colorbar=dict(title=dict(text="MAC (–)")),
        hovertemplate="analytical mode %{y}, FEM mode %{x}: MAC = %{z:.4f}<extra></extra>"))
    for p in pairs:
        i, j = p["analytical_mode"], p["fem_mode"]
        if i <= m.shape[0] and j <= m.shape[1]:
            fig.add_shape(type="rect", x0=j - 0.5, x1=j + 0.5, y0=i - 0.5, y1=i + 0.5,
                          line=dict(color=FEM_COLOUR, width=2))
    fig.update_yaxes(autorange="reversed", title_text="analytical mode (–)", dtick=1)
    fig.update_xaxes(title_text="FEM mode (–)", dtick=1, side="bottom")
    fig.update_layout(**LAYOUT, height=420, width=500)
    return fig


def stiffness_sweep(study: dict) -> go.Figure:
    """f1.. of both models against the drive's stiffness (log): lines the analytical model,
    circles the FEM, dashed the rigid drive, crosses the knees, dotted the scene's value."""
    sweep = study["sweep"]
    k = [p["actuator_n_per_um"] for p in sweep]
    n = len(sweep[0]["analytical_hz"])
    fig = go.Figure()
    for j in range(n):
        colour = COLOURS[j % len(COLOURS)]
        fig.add_trace(go.Scatter(
            x=k, y=[p["analytical_hz"][j] for p in sweep], mode="lines", name=f"f{j + 1}",
            legendgroup=f"f{j + 1}", line=dict(color=colour),
            hovertemplate=(f"k_a = %{{x:.4g}} N/µm<br>f{j + 1}, analytical: %{{y:.2f}} Hz"
                           "<extra></extra>")))
        fig.add_trace(go.Scatter(
            x=k, y=[p["fem_hz"][j] for p in sweep], mode="markers", legendgroup=f"f{j + 1}",
            showlegend=False, marker=dict(color=colour, symbol="circle-open", size=8),
            hovertemplate=(f"k_a = %{{x:.4g}} N/µm<br>f{j + 1}, FEM: %{{y:.2f}} Hz"
                           "<extra></extra>")))
        rigid = study["rigid_drive"]
        if rigid:
            fig.add_hline(y=rigid["analytical_hz"][j], line=dict(color=colour, dash="dash",
                                                                 width=1))
            knee = study["knee_n_per_um"][j]
            if knee is not None:
                fig.add_trace(go.Scatter(
                    x=[knee], y=[rigid["analytical_hz"][j] / np.sqrt(2.0)], mode="markers",
                    showlegend=False, marker=dict(symbol="x", size=9, color=colour),
                    hovertemplate=(f"knee of f{j + 1}: k_a = %{{x:.4g}} N/µm"
                                   "<extra></extra>")))
    scene = sweep[0]["actuator_n_per_um"] / sweep[0]["factor"]
    fig.add_vline(x=scene, line=dict(color="#4d4d4d", dash="dot", width=1),
                  annotation_text="the scene's")
    fig.update_xaxes(type="log", title_text="drive axial stiffness k_a (N/µm)")
    fig.update_yaxes(title_text="frequency (Hz)")
    fig.update_layout(**LAYOUT, height=440, title=dict(
        text=f"{study['case']}: lines the analytical model, circles the FEM, dashed the rigid "
             "drive, crosses the knees", font=dict(size=12)))
    return fig
