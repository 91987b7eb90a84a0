"""A test campaign's pages: correlation.html (test modes against the model's, pose by pose) and
identification.html (the parameters fitted to them), each one self-contained file that works
offline (plotly.js inlined once, the charts drawn by templates/report.js from one JSON block).
Drawn from the campaign's JSON dicts only: nothing is recomputed, no solver imported. A dict
missing a key the page needs raises a CampaignDataError (a KeyError, and a ValueError) naming
the key and where it is missing, before anything is drawn; a null value is printed "–"."""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np
import plotly.graph_objects as go
import plotly.io
from jinja2 import Environment, FileSystemLoader, StrictUndefined
from markupsafe import Markup

from common.atomic import write_text_atomic
from common.errors import InputError
from results.campaign_records import SCHEMA, Correlation, Identification
from results.declare import check_type

TEMPLATES = Path(__file__).resolve().parent / "templates"
# as interactive_charts.LAYOUT (not imported from there: it brings matplotlib in)
LAYOUT = dict(template="plotly_white", font=dict(size=12), margin=dict(l=60, r=20, t=50, b=50),
              hoverlabel=dict(align="left"))
PAIR_COLOUR = "#d62728"  # the pairs outlined, as the report's MAC matrix
BODY_COLOURS = {"platform": "#1f77b4", "leg 1": "#ff7f0e", "leg 2": "#2ca02c", "leg 3": "#9467bd"}
OTHER_COLOURS = ("#8c564b", "#e377c2", "#17becf", "#bcbd22")

class CampaignDataError(KeyError, ValueError):
    """A campaign dict the page cannot be drawn from: a key missing (where, which), a part of
    the wrong kind, or a schema this page does not know."""

    def __str__(self) -> str:  # KeyError would print the message in quotes
        return str(self.args[0])


def check(data: Any, kind: Any, where: str) -> None:
    """Raise CampaignDataError naming the first field of the record type `kind` (results.
    campaign_records, the one declaration of these files) that `data` lacks or holds wrongly,
    or a schema this page does not read."""
    if isinstance(data, Mapping) and data.get("schema") != SCHEMA:
        raise CampaignDataError(f"{where}: schema {data.get('schema')!r}, this page reads "
                                f"{SCHEMA}")
    try:
        check_type(kind, data, where)
    except InputError as exc:
        raise CampaignDataError(str(exc)) from None


def num(x: Any, fmt: str = "{:.2f}") -> str:
    """A number as printed; "–" for null or not finite."""
    if x is None or isinstance(x, bool):
        return "–" if x is None else str(x)
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x)
    return fmt.format(v) if math.isfinite(v) else "–"


def _cell(text: Any, cls: str = "num") -> dict:
    return {"text": text, "cls": cls}


def _at(values: Sequence | None, mode: int) -> Any:
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
    hz = [[[_at(pose["test_hz"], i + 1), _at(pose["model_hz"], j + 1)] for j in range(cols)]
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

def frequency_table(pose: Mapping[str, Any]) -> list[dict]:
    """Every test mode (paired, or unpaired and why), then the model's unpaired modes."""
    pairs = {p["test_mode"]: p for p in pose["pairs"]}
    unpaired = {u["test_mode"]: u for u in pose["unpaired_test_modes"]}
    modes = sorted(set(range(1, len(pose["test_hz"]) + 1)) | set(pairs) | set(unpaired))
    rows = []
    for k in modes:
        p, u = pairs.get(k), unpaired.get(k)
        test_hz = p["test_hz"] if p else u["test_hz"] if u else _at(pose["test_hz"], k)
        zeta = _at(pose["test_damping_ratio"], k)
        zeta = None if zeta is None else 100 * float(zeta)
        cells = [_cell(k), _cell(num(test_hz)), _cell(num(zeta))]
        if p:
            cells += [_cell(p["model_mode"]), _cell(num(p["model_hz"])),
                      _cell(num(p["error_percent"], "{:+.2f}")), _cell(num(p["mac"], "{:.3f}")),
                      _cell("paired, repeated group" if p.get("repeated") else "paired", "text")]
        else:
            why = u["reason"] if u else "not paired"
            cells += [_cell("–") for _ in range(4)] + [_cell(f"unpaired: {why}", "text")]
        rows.append({"cls": "" if p else "unpaired", "cells": cells})
    for u in pose["unpaired_model_modes"]:
        rows.append({"cls": "unpaired-model", "cells": [_cell("–") for _ in range(3)] + [
            _cell(u["model_mode"]), _cell(num(u["model_hz"])), _cell("–"), _cell("–"),
            _cell("model mode unpaired", "text")]})
    return rows


def _pose_line(pose: Mapping[str, Any]) -> str:
    return (f"height {num(pose['height_mm'], '{:.1f}')} mm, azimuth "
            f"{num(pose['azimuth_deg'], '{:.1f}')}°, tilt {num(pose['tilt_deg'], '{:.2f}')}°")


def _stats(pairs: list[Mapping[str, Any]]) -> list[str]:
    err = [abs(float(p["error_percent"])) for p in pairs if p["error_percent"] is not None]
    mac = [float(p["mac"]) for p in pairs if p["mac"] is not None]
    return [num(sum(err) / len(err) if err else None), num(max(err) if err else None),
            num(min(mac) if mac else None, "{:.3f}")]


def correlation_context(data: Mapping[str, Any], charts: dict, prefix: str) -> dict:
    """The template's view of a correlation dict; its charts added to `charts`."""
    s = data["summary"]
    poses = []
    for i, pose in enumerate(data["poses"]):
        keys = {}
        for kind, make in (("mac", mac_chart), ("machine", machine_chart)):
            chart = make(pose)
            if chart is not None:
                keys[kind] = f"{prefix}{kind}:{i}"
                charts[keys[kind]] = chart
        bodies: dict[str, int] = {}
        for node in pose["nodes"]:
            bodies[str(node["body"])] = bodies.get(str(node["body"]), 0) + 1
        poses.append({
            "name": pose["name"], "anchor": f"{prefix}pose-{i}", "line": _pose_line(pose),
            "source": pose["source"], "rows": frequency_table(pose), "charts": keys,
            "unpaired_test": pose["unpaired_test_modes"],
            "unpaired_model": pose["unpaired_model_modes"],
            "nodes": ", ".join(f"{n} on {b}" for b, n in bodies.items()) or "none",
            "overview": [pose["name"], num(pose["height_mm"], "{:.1f}"),
                         num(pose["azimuth_deg"], "{:.1f}"), num(pose["tilt_deg"], "{:.2f}"),
                         len(pose["test_hz"]), len(pose["model_hz"]), len(pose["pairs"]),
                         len(pose["unpaired_test_modes"]), *_stats(pose["pairs"])]})
    return {"data": data, "poses": poses, "pairing": {
        "min_mac": num(data["pairing"]["min_mac"], "{:g}"),
        "max_ratio": num(data["pairing"]["max_frequency_ratio"], "{:g}"),
        "rule": data["pairing"]["rule"]},
        "summary": [s["pairs"], num(s["mean_abs_error_percent"]),
                    num(s["max_abs_error_percent"]), num(s["min_mac"], "{:.3f}")]}


def parameter_rows(parameters: list[Mapping[str, Any]]) -> list[dict]:
    """The parameters table: an unidentifiable key flagged, its value never shown as a
    confident number."""
    rows = []
    for p in parameters:
        ci, b = p["ci95"], p["bounds"]
        interval = f"{num(ci[0], '{:.4g}')} … {num(ci[1], '{:.4g}')}" if ci else "–"
        value = num(p["value"], "{:.4g}")
        ok = bool(p["identifiable"])
        if ok:
            shown: Any = value
            if p["at_bound"]:
                shown = Markup('{} <span class="flag">at bound</span>').format(value)
        else:
            shown = Markup('<span class="flag">NOT IDENTIFIED</span> <span class="muted">'
                           '(the fit ended at {}: not to be trusted)</span>').format(value)
            interval = Markup('<span class="muted">{}</span>').format(interval)
        rows.append({"cls": "" if ok else "unidentified", "cells": [
            _cell(Markup("<code>{}</code>").format(p["key"]), "text"),
            _cell(p["unit"], "unit"), _cell(num(p["initial"], "{:.4g}")), _cell(shown, "num wrap"),
            _cell(interval), _cell(num(p["relative_std_percent"], "{:.3g}")),
            _cell(f"{num(b[0], '{:.4g}')} … {num(b[1], '{:.4g}')}" if b else "–"),
            _cell("yes" if ok else Markup('<span class="flag">NO</span>'), "text"),
            _cell(p["reason"], "text reason")]})
    return rows


FIT_COLUMNS = (("test_mode", "{:g}"), ("test_hz", "{:.2f}"), ("before_hz", "{:.2f}"),
               ("after_hz", "{:.2f}"), ("error_before_percent", "{:+.2f}"),
               ("error_after_percent", "{:+.2f}"), ("mac_after", "{:.3f}"))


def fit_rows(fit: Mapping[str, Any]) -> list[dict]:
    return [{"cls": "", "cells": [_cell(num(m[k], f)) for k, f in FIT_COLUMNS]}
            for m in fit["modes"]]


# --- the pages ----------------------------------------------------------------------------

def _render(page: str, title: str, charts: dict, **context: Any) -> str:
    from plotly.offline import get_plotlyjs

    # the charts' JSON safe inside <script type="application/json"> (as interactive.page_data)
    data = json.dumps(charts, separators=(",", ":"), allow_nan=False).replace("<", "\\u003c")
    env = Environment(loader=FileSystemLoader(TEMPLATES), autoescape=True,
                      undefined=StrictUndefined, trim_blocks=True, lstrip_blocks=True)
    return env.get_template("campaign.html.j2").render(
        page=page, title=title, charts=charts, css=(TEMPLATES / "report.css").read_text(
            encoding="utf-8"), plotly_js=get_plotlyjs() if charts else "",
        chart_data=data, report_js=(TEMPLATES / "report.js").read_text(
            encoding="utf-8"), **context)


def correlation_page(data: Mapping[str, Any]) -> str:
    """The HTML of a correlation.json dict."""
    check(data, Correlation, "correlation.json")
    charts: dict = {}
    ctx = correlation_context(data, charts, "")
    return _render("correlation", f"Correlation — {data['campaign']}", charts, c=ctx)


def identification_page(data: Mapping[str, Any]) -> str:
    """The HTML of an identification.json dict."""
    check(data, Identification, "identification.json")
    charts: dict = {}
    keys = [str(p["key"]) for p in data["parameters"]]
    for name, chart in (("singular", singular_chart(data["singular_values"])),
                        ("parameter_correlation",
                         correlation_chart(data["parameter_correlation"], keys))):
        if chart is not None:
            charts[name] = chart
    fits = []
    for i, fit in enumerate(data["fit"]):
        charts[f"fit:{i}"] = fit_chart(fit)
        fits.append({"pose": fit["pose"], "key": f"fit:{i}", "rows": fit_rows(fit)})
    after = data["correlation_after"]
    c = None if after is None else correlation_context(after, charts, "after-")
    s = [float(v) for v in data["singular_values"] if v is not None]
    condition = max(s) / min(s) if s and min(s) > 0 else None
    noise = data["noise"]
    return _render(
        "identification", f"Identification — {data['campaign']}", charts, r=data,
        c=c, fits=fits, parameters=parameter_rows(data["parameters"]),
        unidentified=[p for p in data["parameters"] if not p["identifiable"]],
        residuals=[num(data["residual_rms_percent_before"]),
                   num(data["residual_rms_percent_after"]),
                   num(noise["frequency_percent"]),
                   {"residuals": "estimated from the fit's residuals",
                    "stated": "as stated"}.get(str(noise["source"]), str(noise["source"]))],
        condition=num(condition, "{:.3g}"), seconds=num(data["seconds"], "{:.1f}"))


def write_page(html: str, path: Path) -> None:
    """Write a page atomically (a reader never sees half of it)."""
    write_text_atomic(path, html)
