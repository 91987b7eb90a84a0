"""The interactive charts of the dynamic compliance at the tool (issue 38): the least dynamic
stiffness over the workspace map (polar panels per layer, as the workspace map's, one button
per direction) and each case's receptance against the solid's direct response. Their static twins
in report.pdf: `study_maps.dynamic_stiffness_map`, `cut_figures.tool_response`."""
from __future__ import annotations

import math

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from .interactive_charts import FEM_COLOUR, LAYOUT, SETTING_COLOURS, significant
from .interactive_maps import finite_array, grid_points, panel, polar_panels, switched_panels

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
        values = [np.round(np.log10(finite_array([p[3] for p in points])), 4) for points in data]
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


def tool_response(record: dict, case: str) -> go.Figure | None:
    """|H_xx|, |H_yy|, |H_zz| of the tool point (m/N, log) against frequency, one panel per
    direction: the analytical model's (line) and the FEM's modal sum (dashed), circles the
    solid's direct response at each of its peaks, all three at the study's check damping (one
    Rayleigh damping; hover: the three models there and the analytical model's errors). Its
    static twin: `cut_figures.tool_response`. None when the record has no
    curve."""
    curves = record["curves"]
    f = curves["frequency_hz"]
    directions = [d for d in ("x", "y", "z")
                  if d in curves["analytical_m_per_n"] or d in curves["fem_m_per_n"]]
    if not f or not directions:
        return None
    fig = make_subplots(rows=1, cols=len(directions), horizontal_spacing=0.07,
                        subplot_titles=[f"|H_{d}{d}|" for d in directions])
    models = (("analytical_m_per_n", "analytical model", "analytical",
               dict(color=SETTING_COLOURS[0], width=1.5)),
              ("fem_m_per_n", "FEM, modal sum", "fem", dict(color=FEM_COLOUR, width=1.5,
                                                           dash="dash")))
    first = next((d for d in directions if any(p["direction"] == d for p in record["peaks"])),
                 None)  # the panel whose circles the legend names
    for c, d in enumerate(directions, start=1):
        for key, label, group, line in models:
            if d not in curves[key]:
                continue
            fig.add_trace(go.Scatter(
                x=[significant(v) for v in f], y=[significant(v) for v in curves[key][d]],
                mode="lines", name=label, legendgroup=group,
                showlegend=c == 1, line=line,
                hovertemplate=(f"f = %{{x:.2f}} Hz<br>|H_{d}{d}| = %{{y:.4e}} m/N"
                               f"<extra>{label}</extra>")), row=1, col=c)
        peaks = [p for p in record["peaks"] if p["direction"] == d]
        if not peaks:
            continue
        fig.add_trace(go.Scatter(
            x=[p["fem_direct_hz"] for p in peaks], y=[p["fem_direct_m_per_n"] for p in peaks],
            mode="markers", name="FEM, direct response (peaks)", legendgroup="direct",
            showlegend=d == first,
            marker=dict(symbol="circle-open", size=11, color="black", line=dict(width=2)),
            customdata=[[p["fem_mode"], p["fem_modal_hz"], p["fem_modal_m_per_n"],
                         p["fem_modal_magnitude_error_percent"], p["analytical_hz"],
                         p["frequency_error_percent"], p["analytical_m_per_n"],
                         p["magnitude_error_percent"]] for p in peaks],
            hovertemplate=(f"FEM mode %{{customdata[0]}}, the check's Rayleigh damping:<br>"
                           f"the solid's direct response: %{{x:.3f}} Hz, |H_{d}{d}| = "
                           "%{y:.4e} m/N<br>"
                           "FEM modal sum: %{customdata[1]:.3f} Hz, %{customdata[2]:.4e} m/N "
                           "(%{customdata[3]:+.3f} %)<br>analytical: %{customdata[4]:.3f} Hz "
                           "(%{customdata[5]:+.3f} %), %{customdata[6]:.4e} m/N "
                           "(%{customdata[7]:+.3f} %)<extra>" + case + "</extra>")),
            row=1, col=c)
    fig.update_xaxes(title_text="frequency (Hz)")
    fig.update_yaxes(type="log", exponentformat="power")
    fig.update_yaxes(title_text="receptance |H_dd| (m/N)", col=1)
    fig.update_layout(**LAYOUT, height=420, legend=dict(orientation="h", y=-0.2), title=dict(
        text=f"{case}: the tool point's receptance ({record['check_damping'].split(' (')[0]})",
        font=dict(size=12)))
    return fig
