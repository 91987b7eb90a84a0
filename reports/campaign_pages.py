"""A test campaign's pages: correlation.html (test modes against the model's, pose by pose) and
identification.html (the parameters fitted to them), each one self-contained file that works
offline (plotly.js inlined once, the charts drawn by templates/report.js from one JSON block).
Drawn from the campaign's JSON dicts only: nothing is recomputed, no solver imported. A dict
missing a key the page needs raises a CampaignDataError (a KeyError, and a ValueError) naming
the key and where it is missing, before anything is drawn; a null value is printed "–"."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Mapping

from jinja2 import Environment, FileSystemLoader, StrictUndefined
from markupsafe import Markup

from common.atomic import write_text_atomic
from common.errors import InputError
from results.campaign_records import SCHEMA, Correlation, Identification
from results.declare import check_type

from .campaign_charts import (
    at_mode,
    correlation_chart,
    fit_chart,
    mac_chart,
    machine_chart,
    num,
    singular_chart,
)

TEMPLATES = Path(__file__).resolve().parent / "templates"
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


def _cell(text: Any, cls: str = "num") -> dict:
    return {"text": text, "cls": cls}


def frequency_table(pose: Mapping[str, Any]) -> list[dict]:
    """Every test mode (paired, or unpaired and why), then the model's unpaired modes."""
    pairs = {p["test_mode"]: p for p in pose["pairs"]}
    unpaired = {u["test_mode"]: u for u in pose["unpaired_test_modes"]}
    modes = sorted(set(range(1, len(pose["test_hz"]) + 1)) | set(pairs) | set(unpaired))
    rows = []
    for k in modes:
        p, u = pairs.get(k), unpaired.get(k)
        test_hz = p["test_hz"] if p else u["test_hz"] if u else at_mode(pose["test_hz"], k)
        zeta = at_mode(pose["test_damping_ratio"], k)
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


VALIDATION_COLUMNS = (("test_mode", "{}"), ("test_hz", "{:.4f}"), ("e_percent", "{:+.3f}"),
                      ("u_num_percent", "{:.3g}"), ("u_input_percent", "{:.3g}"),
                      ("u_d_percent", "{:.3g}"), ("u_val_percent", "{:.3g}"),
                      ("e_identified_percent", "{:+.3f}"))


def validation_rows(rows: list[Mapping[str, Any]]) -> list[dict]:
    return [{"cls": "", "cells": [_cell(v["pose"], "")]
             + [_cell(num(v[k], f)) for k, f in VALIDATION_COLUMNS] + [_cell(v["verdict"], "")]}
            for v in rows]


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
        validation=validation_rows(data["validation"]),
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
