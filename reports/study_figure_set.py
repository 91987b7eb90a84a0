"""The figures of the studies drawn as their tables (no template of their own), planned with
the report's others (`figure_set`'s plan: drawn in worker processes, cached): per section
anchor, each figure's picture, its caption and the key of its interactive twin in report.html
(`chart_key`, the same key `interactive` gives the chart)."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Protocol, TypedDict, cast

from common.paths import distinct_stems, inside
from results import Results

from . import cut_figures, study_figures, study_maps
from .results import main_cases


class Plan(Protocol):
    def add(self, draw_fn, outputs, *args, then=None, errors=(), **kwargs) -> None: ...


def chart_key(kind: str, name: str | None = None) -> str:
    """The key of a chart in report.html's JSON block and in the template (`interactive`),
    and of the static figure that is its twin in report.pdf."""
    return kind if name is None else f"{kind}:{name}"


class StudyFigure(TypedDict):
    """A figure of a study drawn as its tables (no template of its own): its picture, a
    sentence of what it shows, and the key of the interactive chart of the same picture
    (interactive.chart_key) or None."""
    src: Path
    caption: str
    chart: str | None


def study_figure_set(results: Results, fig_dir: Path, notes: list[str], plan: Plan
                     ) -> dict[str, list[StudyFigure]]:
    """The figures of the studies drawn as their tables, by section anchor, cases in the
    results' order (planned into `plan`; a figure that fails to draw leaves its section, said
    in `notes`)."""
    out: dict[str, list[StudyFigure]] = {}

    def add(anchor: str, draw_fn, record, stem: str, caption: str, chart: str | None,
            what: str) -> None:
        path = inside(fig_dir, f"{stem}.png")
        entry = StudyFigure(src=path, caption=caption, chart=chart)
        out.setdefault(anchor, []).append(entry)

        def done(outcome):
            if outcome.error is not None:
                out[anchor].remove(entry)
                notes.append(f"{what}: {outcome.error}")
        plan.add(draw_fn, path, record, path, then=done)

    cases = results["cases"]
    stems = distinct_stems((case["name"] for case in cases), "case name")
    for case in main_cases(results):  # the report's subject; the others' spread is in the
        spread = case.get("uncertainty")  # tables (and report.html's charts)
        if not spread:
            continue
        name, stem = case["name"], stems[case["name"]]
        if study_figures.has_sobol(spread):
            add("uncertainty", study_figures.sobol_bars, spread, f"sobol_{stem}",
                study_figures.sobol_caption(case, spread), chart_key("uncertainty", name),
                f"{name}: Sobol' indices")
        if study_figures.has_validation(spread):
            add("uncertainty", study_figures.validation_spread, spread, f"vv20_{stem}",
                study_figures.validation_caption(case, spread), None,
                f"{name}: V&V 20 and frequency spread")
    studies = results["studies"]
    path = studies.get("uncertainty_path")
    if path and path["poses"]:
        add("uncertainty-path", study_figures.path_band, path, "uncertainty_path",
            study_figures.path_caption(path), chart_key("uncertainty_path"),
            "uncertainty along the worst path")
    stiffness = studies.get("dynamic_stiffness")
    if stiffness and study_maps.stiffness_panels(stiffness):
        add("dynamic-stiffness", study_maps.dynamic_stiffness_map, stiffness,
            "dynamic_stiffness", study_maps.stiffness_caption(stiffness),
            chart_key("dynamic_stiffness"), "dynamic stiffness map")
    for case in cases:
        lobes = cast("dict[str, Any] | None", case.get("lobes"))
        if lobes and cut_figures.has_lobes(lobes):
            add("lobes", cut_figures.case_lobes, lobes, f"lobes_{stems[case['name']]}",
                cut_figures.lobes_caption(case, lobes), chart_key("lobes", case["name"]),
                f"{case['name']}: stability lobes")
    stable = cast("dict[str, Any] | None", studies.get("stability_map"))
    if stable and study_maps.stability_layers(stable):
        add("stability-map", study_maps.stability_map, stable, "stability_map",
            study_maps.stability_caption(stable), chart_key("stability_map"),
            "stability map")
    for case in cases:
        tool = case.get("tool_response")
        if tool and cut_figures.tool_directions(tool):
            add("tool-response", cut_figures.tool_response, tool,
                f"tool_response_{stems[case['name']]}",
                cut_figures.tool_caption(case, tool), chart_key("tool_response", case["name"]),
                f"{case['name']}: tool response")
    return out
