"""The charts of a test campaign's pages (reports/campaign_pages.py): the MAC matrix, the
machine with the test nodes, the fit before and after, the singular values and the keys'
correlation, as plotly figures drawn from the campaign's JSON dicts only."""
from __future__ import annotations

import json
import math
from typing import Any, Mapping, Sequence

import numpy as np
import plotly.graph_objects as go
import plotly.io

# as interactive_charts.LAYOUT (not imported from there: it brings matplotlib in)
LAYOUT = dict(template="plotly_white", font=dict(size=12), margin=dict(l=60, r=20, t=50, b=50),
              hoverlabel=dict(align="left"))
PAIR_COLOUR = "#d62728"  # the pairs outlined, as the report's MAC matrix
BODY_COLOURS = {"platform": "#1f77b4", "leg 1": "#ff7f0e", "leg 2": "#2ca02c", "leg 3": "#9467bd"}
OTHER_COLOURS = ("#8c564b", "#e377c2", "#17becf", "#bcbd22")

def num(x: Any, fmt: str = "{:.2f}") -> str:
    """A number as printed; "–" for null or not finite."""
    if x is None or isinstance(x, bool):
        return "–" if x is None else str(x)
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x)
    return fmt.format(v) if math.isfinite(v) else "–"


def at_mode(values: Sequence | None, mode: int) -> Any:
    """values[mode - 1] (modes are numbered from 1), None where absent."""
    return values[mode - 1] if values and 1 <= mode <= len(values) else None


def _array(rows: Any) -> np.ndarray:
    """A matrix of floats, NaN for null."""
    m = [[np.nan if v is None else float(v) for v in row] for row in rows or []]
    return np.array(m, dtype=float) if m and m[0] else np.zeros((0, 0))


def _texts(m: np.ndarray) -> list[list[str]]:
    """A matrix's values as printed in its cells ("" for null)."""
    return [[num(v, "{:.2f}").replace("–", "") for v in row] for row in m.tolist()]


def _finish(fig: go.Figure, **layout: Any) -> dict:
    fig.update_layout(**{**LAYOUT, **layout})
    return {"figure": json.loads(plotly.io.to_json(fig, validate=False))}


# --- the charts ---------------------------------------------------------------------------

def mac_chart(pose: Mapping[str, Any]) -> dict | None:
    """MAC(test mode i, model mode j) as a heat map, test modes down, the pairs outlined."""
    m = _array(pose["mac"])
    if m.size == 0:
        return None
    rows, cols = m.shape
    hz = [[[at_mode(pose["test_hz"], i + 1), at_mode(pose["model_hz"], j + 1)] for j in range(cols)]
          for i in range(rows)]
    fig = go.Figure(go.Heatmap(
        z=m.tolist(), x=list(range(1, cols + 1)), y=list(range(1, rows + 1)), zmin=0, zmax=1,
        colorscale="Blues", text=_texts(m), texttemplate="%{text}", customdata=hz,
        colorbar=dict(title=dict(text="MAC (–)")),
        hovertemplate=("test mode %{y} (%{customdata[0]:.2f} Hz)<br>model mode %{x} "
                       "(%{customdata[1]:.2f} Hz)<br>MAC = %{z:.3f}<extra></extra>")))
    for p in pose["pairs"]:
        i, j = p["test_mode"], p["model_mode"]
        if 1 <= i <= rows and 1 <= j <= cols:
            fig.add_shape(type="rect", x0=j - 0.5, x1=j + 0.5, y0=i - 0.5, y1=i + 0.5,
                          line=dict(color=PAIR_COLOUR, width=2))
    fig.update_yaxes(autorange="reversed", title_text="test mode (–)", dtick=1)
    fig.update_xaxes(title_text="model mode (–)", dtick=1)
    return _finish(fig, height=max(360, 40 * rows + 140), width=max(460, 40 * cols + 220))


def _unit(v: np.ndarray) -> np.ndarray | None:
    n = float(np.linalg.norm(v))
    return v / n if n > 1e-12 and math.isfinite(n) else None


def platform_ring(machine: Mapping[str, Any], points: int = 73) -> np.ndarray:
    """The platform's rim: a circle of its radius about its centre, in the plane normal to
    platform_normal (starting towards the first platform joint)."""
    centre = np.asarray(machine["platform_centre_mm"], float)
    normal = _unit(np.asarray(machine["platform_normal"], float))
    normal = np.array([0.0, 0.0, 1.0]) if normal is None else normal
    joints = np.asarray(machine["platform_joints_mm"], float).reshape(-1, 3)
    d = joints[0] - centre if len(joints) else np.zeros(3)
    e1 = _unit(d - normal * float(d @ normal))
    if e1 is None:  # no joint off the centre: any direction in the plane
        e1 = np.cross(normal, np.eye(3)[int(np.argmin(np.abs(normal)))])
        e1 /= np.linalg.norm(e1)
    t = np.linspace(0.0, 2 * math.pi, points)
    return centre + float(machine["platform_radius_mm"]) * (
        np.outer(np.cos(t), e1) + np.outer(np.sin(t), np.cross(normal, e1)))


def _xyz(p: Any) -> str:
    return "(" + ", ".join(num(v, "{:.1f}") for v in p) + ") mm"


def machine_chart(pose: Mapping[str, Any]) -> dict:
    """The machine at the pose (legs from base joint to platform joint, the platform's disk,
    the base joints) and the test nodes coloured by the body they are on."""
    m = pose["machine"]
    base = np.asarray(m["base_joints_mm"], float).reshape(-1, 3)
    top = np.asarray(m["platform_joints_mm"], float).reshape(-1, 3)
    diameter = num(m["leg_diameter_mm"], "{:g}")
    fig = go.Figure()
    for k, (b, t) in enumerate(zip(base, top), start=1):
        label = f"leg {k} (Ø {diameter} mm)"
        fig.add_trace(go.Scatter3d(
            x=[b[0], t[0]], y=[b[1], t[1]], z=[b[2], t[2]], mode="lines", name="legs",
            legendgroup="legs", showlegend=k == 1, line=dict(color="#7f7f7f", width=14),
            text=[f"{label}<br>base joint {_xyz(b)}", f"{label}<br>platform joint {_xyz(t)}"],
            hovertemplate="%{text}<extra></extra>"))
    ring = platform_ring(m)
    centre = np.asarray(m["platform_centre_mm"], float)
    disk = np.vstack([centre, ring[:-1]])
    n = len(ring) - 1
    fig.add_trace(go.Mesh3d(
        x=disk[:, 0], y=disk[:, 1], z=disk[:, 2], i=[0] * n, j=list(range(1, n + 1)),
        k=[i % n + 1 for i in range(1, n + 1)], color="#9ecae1", opacity=0.35,
        name="platform", hoverinfo="skip", showlegend=False))
    fig.add_trace(go.Scatter3d(
        x=ring[:, 0], y=ring[:, 1], z=ring[:, 2], mode="lines", name="platform",
        line=dict(color="#4a6f8f", width=4), hoverinfo="skip"))
    fig.add_trace(go.Scatter3d(
        x=base[:, 0], y=base[:, 1], z=base[:, 2], mode="markers", name="base joints",
        marker=dict(size=6, color="black", symbol="diamond"),
        text=[f"base joint {k}: {_xyz(b)}" for k, b in enumerate(base, start=1)],
        hovertemplate="%{text}<extra></extra>"))
    bodies = list(dict.fromkeys(str(nd["body"]) for nd in pose["nodes"]))
    for n, body in enumerate(bodies):
        nodes = [nd for nd in pose["nodes"] if str(nd["body"]) == body]
        xyz = np.asarray([nd["xyz_mm"] for nd in nodes], float).reshape(-1, 3)
        fig.add_trace(go.Scatter3d(
            x=xyz[:, 0], y=xyz[:, 1], z=xyz[:, 2], mode="markers", name=f"nodes: {body}",
            marker=dict(size=5, line=dict(color="black", width=1), color=BODY_COLOURS.get(
                body, OTHER_COLOURS[n % len(OTHER_COLOURS)])),
            text=[f"node {nd['id']} on {body}<br>{_xyz(nd['xyz_mm'])}<br>measured: "
                  f"{', '.join(map(str, nd['directions'])) or 'none'}<br>"
                  f"{num(nd['distance_mm'], '{:.1f}')} mm from the body" for nd in nodes],
            hovertemplate="%{text}<extra></extra>"))
    return _finish(fig, height=560, margin=dict(l=0, r=0, t=30, b=0), legend=dict(x=0, y=1),
                   scene=dict(aspectmode="data", **{f"{a}axis": dict(
                       title=f"{a} (mm)", showbackground=False) for a in "xyz"}))


def fit_chart(fit: Mapping[str, Any]) -> dict:
    """The error of each test mode of a pose before and after the fit, grouped bars."""
    modes = fit["modes"]
    x = [f"mode {m['test_mode']}" for m in modes]
    fig = go.Figure()
    for when, colour in (("before", "#bdbdbd"), ("after", "#1f77b4")):
        fig.add_trace(go.Bar(
            x=x, y=[m[f"error_{when}_percent"] for m in modes], name=when,
            marker_color=colour,
            customdata=[[m["test_hz"], m[f"{when}_hz"]] for m in modes],
            hovertemplate=(f"%{{x}} (test %{{customdata[0]:.2f}} Hz)<br>model {when}: "
                           "%{customdata[1]:.2f} Hz<br>error %{y:+.2f} %<extra></extra>")))
    fig.add_hline(y=0, line=dict(color="#4d4d4d", width=1))
    fig.update_yaxes(title_text="error of the model vs the test (%)")
    fig.update_xaxes(title_text="test mode")
    return _finish(fig, barmode="group", height=320, legend=dict(orientation="h", y=1.12))


def singular_chart(values: Sequence[Any]) -> dict | None:
    """The singular values of the fit's sensitivity, largest first, on a log axis when all
    are positive."""
    s = [np.nan if v is None else float(v) for v in values]
    if not s:
        return None
    fig = go.Figure(go.Bar(x=list(range(1, len(s) + 1)), y=s, marker_color="#2a5d8f",
                           hovertemplate="σ%{x} = %{y:.4g}<extra></extra>"))
    fig.update_yaxes(type="log" if all(v > 0 for v in s) else "linear",
                     title_text="singular value (–)")
    fig.update_xaxes(title_text="index (–)", dtick=1)
    return _finish(fig, height=340)


def correlation_chart(matrix: Any, keys: list[str]) -> dict | None:
    """The parameters' correlation (-1..1) as a heat map."""
    c = _array(matrix)
    if c.size == 0:
        return None
    labels = keys if len(keys) == c.shape[0] == c.shape[1] else [
        f"p{i}" for i in range(1, c.shape[0] + 1)]
    fig = go.Figure(go.Heatmap(
        z=c.tolist(), x=labels, y=labels, zmin=-1, zmax=1, zmid=0, colorscale="RdBu_r",
        text=_texts(c), texttemplate="%{text}",
        colorbar=dict(title=dict(text="correlation (–)")),
        hovertemplate="%{y}<br>%{x}<br>correlation %{z:+.3f}<extra></extra>"))
    fig.update_yaxes(autorange="reversed")
    return _finish(fig, height=max(360, 45 * len(labels) + 220),
                   margin=dict(l=220, r=20, t=30, b=200))


# --- the tables ---------------------------------------------------------------------------
