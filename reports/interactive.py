"""The interactive report.html: which figures become plotly charts, their data as one JSON block,
and the pictures left static embedded, so the page is one self-contained file that works
offline (plotly.js inlined once; no request to any network).

report.pdf is rendered from the same context without any of this (the static pictures), so the
two show the same records of results.json: every chart here has its static twin there (a study
drawn as its tables too: `study_figure_set`, the chart first, then the tables), but the
uncertainty charts of the cases other than the main ones, whose numbers report.pdf keeps in
the tables.
"""
from __future__ import annotations

import base64
import json
from pathlib import Path
from typing import Any, Mapping, cast

import plotly.io

from results import Results

from . import interactive_charts as charts
from . import interactive_lobes as lobe_charts
from . import interactive_maps as maps
from . import interactive_tool as tool_charts
from . import interactive_uncertainty as uncertainty_charts
from .figure_set import has_paper, main_cases, reference, run_settings
from .figures import PAPER_SECONDS
from .interactive_modes import mode_viewer
from .study_figure_set import chart_key

TEMPLATES = Path(__file__).resolve().parent / "templates"


def _figure_json(fig) -> dict:
    return json.loads(plotly.io.to_json(fig, validate=False))


def build_charts(results: Results, results_path: Path, notes: list[str]) -> dict:
    """{key: {"figure": plotly JSON, ...}} of every interactive figure these results hold.

    A chart that cannot be drawn is left out (its static picture stays in the page) and said
    in `notes`."""
    out: dict = {}

    def add(key: str, make, *args, section: str | None = None, caption: str = "") -> None:
        """`section`: the anchor of a study drawn as its tables, where the page draws the
        chart with `caption` (its static twin, `study_figure_set`'s, is report.pdf's)."""
        try:
            value = make(*args)
        except Exception as exc:  # noqa: BLE001  (a chart never sinks the report)
            notes.append(f"interactive {key}: {type(exc).__name__}: "
                         f"{' '.join(str(exc).split())}; " + (
                             "the static picture is shown" if section is None else
                             "not drawn (its tables are shown)"))
            return
        if value is None:
            return
        if isinstance(value, dict):  # a mode viewer: its figure and animation data
            out[key] = dict(value, figure=_figure_json(value["figure"]))
        else:
            out[key] = {"figure": _figure_json(value)}
        if section is not None:
            out[key].update(section=section, caption=caption)

    main = {c["name"] for c in main_cases(results)}
    m = results["scene"]["manipulator"]
    for case in results["cases"]:  # the report shows these of its main cases only
        name = case["name"]
        if name not in main:
            continue
        if case["element_convergence"]:
            ref, label = reference(case)
            add(chart_key("element_convergence", name), charts.element_convergence,
                case["element_convergence"], ref, label)
        if case["fem_refinement"]:
            add(chart_key("fem_refinement", name), charts.fem_refinement,
                case["fem_refinement"], case["fem"]["mesh_size_mm"])
        add(chart_key("mac", name), charts.mac_matrix, case["mac_matrix"], case["pairs"])
        add(chart_key("modes", name), mode_viewer, case, m, results_path)
    speed = {c["name"]: c["speed_vs_error"] for c in results["cases"] if c["speed_vs_error"]}
    if speed:
        add(chart_key("speed"), charts.speed_vs_error, speed, run_settings(results),
            PAPER_SECONDS if has_paper(results) else None)
    ws = results["studies"]["workspace"]
    if ws and maps.valid_layers(ws):
        add(chart_key("workspace_map"), maps.workspace_map, ws, ws["settings"],
            m["actuator"])
        add(chart_key("workspace_height"), maps.workspace_height, ws)
    wv = results["studies"]["workspace_validation"]
    if wv and wv["worst_pose"]:
        add(chart_key("validation_map"), maps.validation_map, wv)
    for study in results["studies"]["lowest_modes"]:
        if study["sweep"]:
            add(chart_key("sweep", study["case"]), charts.stiffness_sweep, study)
    for case in results["cases"]:  # every case: the study's tables hold every case
        tool = case.get("tool_response")
        if tool:
            add(chart_key("tool_response", case["name"]), tool_charts.tool_response, tool,
                case["name"], section="tool-response", caption=tool_caption(case, tool))
    for case in results["cases"]:
        spread = case.get("uncertainty")
        if spread and spread["sobol"]:
            add(chart_key("uncertainty", case["name"]), uncertainty_charts.sobol_bars, spread,
                case["name"], section="uncertainty",
                caption=f"{case['description']} ({case['name']}): what drives the spread, "
                "per output (f_k: the k-th lowest frequency; least d: the least dynamic "
                "stiffness at the tool along d): bars each input's total Sobol' index with "
                "its 95 % sampling error, diamonds its first-order index (without "
                f"interactions); {spread['design']}; {spread['model']}.")
    path = results["studies"].get("uncertainty_path")
    if path and path["poses"]:
        add(chart_key("uncertainty_path"), uncertainty_charts.path_band, path,
            section="uncertainty-path",
            caption=f"Along the workspace map's worst path ({path['path']}; "
            f"{path['model']}): the value at the scene's values (line) and the 95 % band of "
            "the inputs (shaded), f1 and, where the scene asks for it, the least dynamic "
            "stiffness at the tool (log).")
    stiffness = results["studies"].get("dynamic_stiffness")
    if stiffness:
        add(chart_key("dynamic_stiffness"), tool_charts.dynamic_stiffness_map, stiffness,
            section="dynamic-stiffness", caption=stiffness_caption(stiffness))
    for case in results["cases"]:
        lobes = cast("dict[str, Any] | None", case.get("lobes"))
        if lobes:
            add(chart_key("lobes", case["name"]), lobe_charts.case_lobes, lobes, case["name"],
                section="lobes", caption=lobes_caption(case, lobes))
    stable = cast("dict[str, Any] | None", results["studies"].get("stability_map"))
    if stable:
        add(chart_key("stability_map"), lobe_charts.stability_map, stable,
            section="stability-map", caption=stability_caption(stable))
    return out


def lobes_caption(case, record: Mapping[str, Any]) -> str:
    """The caption of a case's lobes."""
    median = record["median_error_percent"]
    said = "" if median is None else (f"; the analytical model's depth is within "
                                      f"{median:.2g} % of the FEM's at the median speed, "
                                      f"{record['max_error_percent']:.2g} % at worst")
    band = record.get("band")
    spread = ""
    if band and not band["refused"] and band["least_q025_mm"] is not None:
        spread = (f" Shaded: 95 % of {band['samples']} machines drawn from the scene's "
                  f"[uncertainty] ({band['model']}); their least depth over the speeds is "
                  f"{band['least_q025_mm']:.3g} mm or more for 97.5 % of them (the scene's "
                  f"own machine: {_mm(band['least_nominal_mm'])}).")
    elif band and band["refused"]:
        spread = f" The band over [uncertainty] was not drawn: {band['refused']}."
    return (f"{case['description']} ({case['name']}): the critical axial depth of the "
            f"scene's cut against spindle speed ({record['method']}; stable below a curve), "
            f"from the analytical model's tool modes and the FEM's at "
            f"{record['fem_mesh_size_mm']:g} mm and {record['coarse_mesh_size_mm']:g} mm"
            f"{said}.{spread}")


def _mm(value: float | None) -> str:
    return "stable at every speed" if value is None else f"{value:.3g} mm"


def stability_caption(record: Mapping[str, Any]) -> str:
    """The caption of the stability map."""
    lo, hi = record["spindle_rpm_range"]
    return (f"The least critical depth of the scene's cut over {record['speeds']} spindle "
            f"speeds from {lo:.0f} to {hi:.0f} rpm ({record['method']}) at every pose of "
            "the map: angle = azimuth φ (deg), radius = tilt θ (deg), colour = depth (mm); "
            f"star: the least over the map. The analytical model ({record['analytical']}), "
            f"damping {record['damping']}, tool point {_point(record)}.")


def _point(record: Mapping[str, Any]) -> str:
    return "(" + ", ".join(f"{v:g}" for v in record["point_mm"]) + ") mm"


def tool_caption(case, record: Mapping[str, Any]) -> str:
    """The caption of a case's tool-response chart."""
    return (f"{case['description']} ({case['name']}): the receptance of the tool point "
            f"{_point(record)} from the platform centre, |H_xx|, |H_yy|, |H_zz| (m/N, log "
            f"scale) against frequency: lines the analytical model ({record['analytical']}), "
            f"dashed the FEM's modal sum (h = {record['fem_mesh_size_mm']:g} mm), circles the "
            "solid's direct frequency response at each of its peaks, all three at one "
            f"damping: {record['check_damping']} (the scene's own, {record['damping']}: "
            "`rps frf`).")


def stiffness_caption(record: Mapping[str, Any]) -> str:
    """The caption of the least-dynamic-stiffness map."""
    return (f"The least dynamic stiffness at the tool point {_point(record)}, 1 / max |H_dd| "
            "(N/m), along x, y, z (buttons) over every layer of the workspace map: angle = "
            "azimuth φ (deg), radius = tilt θ (deg), colour = stiffness on a log scale shared "
            "by the direction's panels (each panel's range in its title); star: the least over "
            f"the map. The analytical model ({record['analytical']}, {record['modes_summed']} "
            f"modes summed, {record['lines']} lines), damping {record['damping']}; a pose "
            "unreached, or where the tool does not move along the direction, has no point.")


def page_data(charts_by_key: dict) -> str:
    """The charts as one JSON text safe inside <script type="application/json">: every "<"
    escaped (JSON reads \\u003c as "<")."""
    text = json.dumps(charts_by_key, separators=(",", ":"), allow_nan=False)
    return text.replace("<", "\\u003c")  # no "</script>" nor "<!--" can end the block


def plotly_js() -> str:
    """plotly.js, inlined once (the page makes no network request)."""
    from plotly.offline import get_plotlyjs

    return get_plotlyjs()


def report_js() -> str:
    return (TEMPLATES / "report.js").read_text(encoding="utf-8")


def embedded(directory: Path):
    """A template filter: figures/x.png -> a data: URI of that file under `directory`, so
    the static pictures the page keeps travel inside it."""
    def to_uri(src: str | None) -> str | None:
        if src is None:
            return None
        data = (Path(directory) / src).read_bytes()
        return "data:image/png;base64," + base64.b64encode(data).decode("ascii")
    return to_uri
