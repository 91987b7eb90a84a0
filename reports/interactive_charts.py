"""The report's interactive charts (plotly), drawn from results.json values only.

Each function is the interactive twin of a static picture in `figures` or `real_machine` (the
workspace's are in `interactive_maps`), from the same record of results.json, with the same
marks (the paper's s, the chosen setting, the pairs, the scene's drive), so the HTML and the PDF
can never disagree; what the static picture cannot give, hover gives: every value at a point.
"""
from __future__ import annotations

import math

import numpy as np
import plotly.graph_objects as go
from matplotlib.colors import to_hex
from plotly.subplots import make_subplots

from results import Refinement, SpeedPoint

from .figures import (
    FEM_COLOUR,
    MODE_COLOURS,
    SETTING_COLOURS,
    limit_note,
    speed_curves,
    speed_point,
)

COLOURS = tuple(to_hex(c) for c in MODE_COLOURS)  # the static figures' mode colours
LAYOUT = dict(template="plotly_white", font=dict(size=12), margin=dict(l=60, r=20, t=50, b=50),
              hoverlabel=dict(align="left"))


def significant(value: float | None, digits: int = 6) -> float | None:
    """A value to `digits` significant digits (None kept): more than hover shows, and the
    page's JSON block the shorter for a chart of many points."""
    return None if value is None else float(f"{value:.{digits}g}")


def _axis(n: int) -> str:
    """The suffix of subplot n's axes (1-based, row by row): "" for the first."""
    return "" if n == 1 else str(n)


def vline(n: int, x: float, **style) -> dict:
    """A vertical line across subplot n at x (a shape takes data values on a log axis too;
    an annotation there takes log10 of them)."""
    return dict(type="line", xref=f"x{_axis(n)}", yref=f"y{_axis(n)} domain", x0=x, x1=x,
                y0=0, y1=1, line=dict(width=1, **style))


def hline(n: int, y: float, span: tuple[float, float] | None = None, **style) -> dict:
    """A horizontal line across subplot n at y; over the data values `span` of x where the x
    axis is logarithmic (plotly.js autoranges a log axis wrongly from a line across its
    domain)."""
    if span is None:
        return dict(type="line", xref=f"x{_axis(n)} domain", yref=f"y{_axis(n)}", x0=0, x1=1,
                    y0=y, y1=y, line=dict(width=1, **style))
    return dict(type="line", xref=f"x{_axis(n)}", yref=f"y{_axis(n)}", x0=span[0],
                x1=span[1], y0=y, y1=y, line=dict(width=1, **style))


def speed_vs_error(entries: dict[str, list[SpeedPoint]], chosen: tuple[str, ...],
                   paper_seconds: dict | None) -> go.Figure:
    """Time per pose against the worst |error| of f1-f6, per case: each setting a curve
    through its refinements; the chosen settings ringed; the paper's times as lines."""
    names = list(entries)
    fig = make_subplots(rows=1, cols=len(names), subplot_titles=names, shared_yaxes=True,
                        horizontal_spacing=0.05)
    seen: list[str] = []
    shapes = []
    for c, name in enumerate(names, start=1):
        for key, rows, label in speed_curves(entries[name]):  # as the PDF's curves
            if key not in seen:
                seen.append(key)
            colour = FEM_COLOUR if key == "fem" else SETTING_COLOURS[
                seen.index(key) % len(SETTING_COLOURS)]
            x, y = zip(*map(speed_point, rows))
            fig.add_trace(go.Scatter(
                x=x, y=y, mode="lines+markers", name=label, legendgroup=key, showlegend=c == 1,
                line=dict(color=colour, width=1), marker=dict(size=7),
                text=[e["setting"] for e in rows],
                customdata=[abs(e["worst_error_percent"]) for e in rows],
                hovertemplate=("%{text}<br>worst |error| of f1–f6: %{customdata:.3g} %<br>"
                               "time per pose: %{x:.3g} s<extra>" + name + "</extra>")),
                row=1, col=c)
        picked = [e for e in entries[name] if e["setting"] in chosen]
        fig.add_trace(go.Scatter(
            x=[speed_point(e)[0] for e in picked], y=[speed_point(e)[1] for e in picked],
            mode="markers", name="the run's settings", legendgroup="chosen",
            showlegend=c == 1, marker=dict(size=16, symbol="circle-open", color="black",
                                           line=dict(width=2)),
            text=[e["setting"] for e in picked],
            customdata=[abs(e["worst_error_percent"]) for e in picked],
            hovertemplate=("the run's setting: %{text}<br>worst |error| of f1–f6: "
                           "%{customdata:.3g} %<br>time per pose: %{x:.3g} s<extra>" + name
                           + "</extra>")), row=1, col=c)
        for model, t in (paper_seconds or {}).items():
            shapes.append(vline(c, t, color="#595959", dash="dash"))
            fig.add_annotation(x=math.log10(t), y=1, yref="paper",  # log axis: log10
                               xref="x" if c == 1 else f"x{c}", yanchor="top",
                               xanchor="right", text=f"paper: {model} {t:g} s", textangle=-90,
                               showarrow=False, font=dict(size=10, color="#4d4d4d"))
    fig.update_layout(shapes=shapes)
    fig.update_xaxes(type="log", title_text="time per pose (s)")
    fig.update_yaxes(type="log")  # every panel: shared axes only match axes of one type
    fig.update_yaxes(title_text="worst |error| of f1–f6 (%)", col=1)
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
    errors = []
    for c, beam in enumerate(beams, start=1):
        s = conv[beam]["elements"]
        f = np.asarray(conv[beam]["frequencies_hz"], float)
        n = min(f.shape[1], len(ref))
        for k in range(n):
            errors.append(100 * (f[:, k] / ref[k] - 1))
            fig.add_trace(go.Scatter(
                x=s, y=errors[-1], mode="lines+markers", name=f"f{k + 1}",
                legendgroup=f"f{k + 1}", showlegend=c == 1,
                line=dict(color=COLOURS[k % len(COLOURS)]), customdata=f[:, k],
                hovertemplate=(f"s = %{{x}}<br>f{k + 1} = %{{customdata:.3f}} Hz<br>error vs "
                               f"{reference_label}: %{{y:+.3f}} %<extra></extra>")),
                row=1, col=c)
    fig.update_layout(shapes=[line for c in range(1, len(beams) + 1) for line in (
        vline(c, paper_elements, color="#7f7f7f", dash="dot"), hline(c, 0.0, color="#4d4d4d"))])
    lo, hi = float(np.nanmin(errors)), float(np.nanmax(errors))
    if hi - lo > 40:  # s = 1 can be far off: the converged part readable, as the PDF's
        fig.update_yaxes(range=[max(lo, -15), min(hi, 25)])
    fig.update_xaxes(title_text="elements per leg s (–)")
    fig.update_yaxes(title_text=f"error vs {reference_label} (%)", col=1)
    fig.update_layout(**LAYOUT, height=400)
    return fig


def fem_refinement(ref: Refinement, scene_size_mm: float | None) -> go.Figure:
    """FEM frequencies against mesh size h per mode, with the extrapolated h -> 0 limit."""
    h = np.asarray(ref["mesh_sizes_mm"], float)
    f = np.asarray(ref["frequencies_hz"], float)
    n = f.shape[1]
    cols = 3
    rows = -(-n // cols)
    notes = [limit_note(ref, k) for k in range(n)]
    fig = make_subplots(rows=rows, cols=cols, subplot_titles=[
        f"f{k + 1}" + (f" ({notes[k]})" if notes[k] else "") for k in range(n)],
        vertical_spacing=0.14, horizontal_spacing=0.09)
    shapes = []
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
            shapes.append(hline(k + 1, limit, color="#666666", dash="dash"))
        if scene_size_mm:
            shapes.append(vline(k + 1, scene_size_mm, color="#999999", dash="dot"))
    fig.update_layout(shapes=shapes)
    fig.update_xaxes(title_text="mesh size h (mm)", range=[-2, float(h.max()) * 1.08])
    fig.update_yaxes(title_text="frequency (Hz)", col=1)
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
    shapes = []
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
            shapes.append(hline(1, rigid["analytical_hz"][j], (min(k), max(k)), color=colour,
                                dash="dash"))
            knee = study["knee_n_per_um"][j]
            if knee is not None:
                fig.add_trace(go.Scatter(
                    x=[knee], y=[rigid["analytical_hz"][j] / np.sqrt(2.0)], mode="markers",
                    showlegend=False, marker=dict(symbol="x", size=9, color=colour),
                    hovertemplate=(f"knee of f{j + 1}: k_a = %{{x:.4g}} N/µm"
                                   "<extra></extra>")))
    scene = sweep[0]["actuator_n_per_um"] / sweep[0]["factor"]
    shapes.append(vline(1, scene, color="#4d4d4d", dash="dot"))
    fig.add_annotation(x=math.log10(scene), y=1, yref="paper", text=" the scene's",
                       xanchor="left", yanchor="top", showarrow=False)  # log axis: log10
    fig.update_layout(shapes=shapes)
    fig.update_xaxes(type="log", title_text="drive axial stiffness k_a (N/µm)")
    fig.update_yaxes(title_text="frequency (Hz)")
    fig.update_layout(**LAYOUT, height=440, title=dict(
        text=f"{study['case']}: lines the analytical model, circles the FEM, dashed the rigid "
             "drive, crosses the knees", font=dict(size=12)))
    return fig
