"""The report document: the template's context (tables, figures, verdicts, which sections the
results call for) and its rendering to HTML (Jinja2) and PDF (WeasyPrint)."""
from __future__ import annotations

import time
from pathlib import Path
from typing import Any, Sequence

from jinja2 import Environment, FileSystemLoader, StrictUndefined

from results import Record, Results, Section, verdict

from . import interactive, validation
from .campaign_summary import campaign_summary
from .case_tables import (
    comparison_table,
    fem_variants_table,
    refinement_table,
    repeated_limit_notes,
    variants_tables,
)
from .cells import Cells, align, tables_in
from .figure_set import has_paper, main_cases
from .figures import PAPER_SECONDS
from .generic_tables import generic_sections, ran, refusals
from .real_machine import shares_table, sweep_table
from .setup_tables import setup_tables
from .study_tables import (
    calibration_table,
    convention_tables,
    coupling_tables,
    hard_cases_table,
    joint_order_tables,
    speed_table,
    verification_table,
)
from .summary import designer_lines

TEMPLATES = Path(__file__).resolve().parent / "templates"


def _figure(path) -> str | None:
    return None if path is None else f"figures/{Path(path).name}"


def case_context(results: Results, i: int, figs: dict, c: Cells) -> dict:
    case = results["cases"][i]
    studied = {s["case"] for s in results["studies"]["angle_conventions"]}
    f = figs["cases"][case["name"]]
    element = f.get("element_convergence", (None, None))
    return {
        "index": i, "case": case, "name": case["name"], "description": case["description"],
        "paper": case["paper"] is not None,
        "verdict": verdict.case_verdict(case, conventions=case["name"] in studied),
        "compare": comparison_table(results, i, c),
        "variants": variants_tables(results, i, c),
        "fem_variants": fem_variants_table(results, i, c),
        "refinement": refinement_table(results, i, c),
        "repeated_limits": repeated_limit_notes(case),
        "fig_element": _figure(element[0]), "fig_element_ref": element[1],
        "fig_refinement": _figure(f.get("fem_refinement")),
        "fig_mac": _figure(f.get("mac")),
        "mode_pairs": [dict(m, fem_png=_figure(m["fem_png"]), beam_png=_figure(m["beam_png"]))
                       for m in f["modes"]["pairs"]],
        "fem_note": f["modes"]["fem_note"],
    }




def section_order(records: Sequence[Record]) -> list[tuple[str, Section | None]]:
    """Every section the report may show, in order: the report's own (summary, fidelity,
    the comparison after the scene, the mode shapes after the convergence, the other cases
    last) and the studies' in registration order; the sections drawn as their tables (no
    template of their own) after every templated one."""
    declared: dict[str, Section] = {}
    for r in records:
        if r.section is not None:
            declared.setdefault(r.section.anchor, r.section)
    own = [a for a, s in declared.items() if s.template is not None]
    order: list[tuple[str, Section | None]] = [("summary", None), ("fidelity", None)]
    for anchor in own:
        order.append((anchor, declared[anchor]))
        order += [(k, None) for k in {"scene": ("comparison",), "convergence": ("modes",)}
                  .get(anchor, ())]
    for k, after in (("comparison", "fidelity"), ("modes", "comparison")):
        if all(a != k for a, _ in order):
            at = next(i for i, (a, _) in enumerate(order) if a == after)
            order.insert(at + 1, (k, None))
    order += [(a, s) for a, s in declared.items() if s.template is None]
    return order + [("campaign", None), ("other", None)]


def sections(paper: bool, present: dict[str, bool],
             records: Sequence[Record]) -> dict[str, str]:
    """The numbered titles of the sections the results call for, by anchor: a section whose
    key `present` marks False has no data in these results and is left out."""
    own = {"summary": "Summary", "fidelity": "Fidelity: what the scene asked, what was chosen",
           "comparison": "Table I reproduction" if paper else "Analytical vs FEM",
           "modes": "Mode shapes", "campaign": "Test data: the campaign beside this run",
           "other": "Other cases"}
    titles = [(a, own[a] if s is None else s.title) for a, s in section_order(records)]
    kept = [(key, title) for key, title in titles if present.get(key, True)]
    return {key: f"{n} {title}" for n, (key, title) in enumerate(kept, start=1)}


def context(results: Results, results_path: Path, figs: dict, records: Sequence[Record]) -> dict:
    c = Cells(results)
    cases = [case_context(results, i, figs, c) for i in range(len(results["cases"]))]
    main_names = {m["name"] for m in main_cases(results)}
    main = [x for x in cases if x["name"] in main_names]
    other = [x for x in cases if x["name"] not in main_names]
    studies = results["studies"]
    ws = studies["workspace"]
    conventions = convention_tables(results, c)
    calibration = calibration_table(results, c)
    joint_orders = joint_order_tables(results, c)
    couplings = coupling_tables(results, c)
    hard = hard_cases_table(results, c)
    verification = verification_table(results, c)
    lowest = [{"case": study["case"], "sets": study["sets_lowest"], "study": study,
               "knees": [(j + 1, k, f) for j, (k, f) in enumerate(
                   zip(study["knee_n_per_um"], study["knee_factors"])) if k is not None],
               "sweep": sweep_table(results, c, ci) if study["sweep"] else None,
               "shares": shares_table(results, c, ci),
               "fig": _figure(figs.get("sweeps", {}).get(study["case"]))}
              for ci, study in enumerate(studies["lowest_modes"])]
    env = results["environment"]
    generic = generic_sections(results, records, c)
    notes = list(figs["notes"])
    campaign = campaign_summary(results_path, results["scene"]["path"],
                                results["scene"]["sha256"], notes)
    ctx: dict[str, Any] = {
        "results": results, "scene": results["scene"], "env": env,
        "profile": results["profile"], "fixture_note": results["fixture_note"],
        "results_name": results_path.name,
        "headline": verdict.headline(results),
        "fidelity_sentences": validation.sentences(results),
        "fidelity_table": validation.fidelity_table(results, c),
        "candidates_table": validation.candidates_table(results, c),
        "percentile_table": validation.percentile_table(results, c),
        "worst_pose_table": validation.worst_pose_table(results, c),
        "validation": results["studies"]["workspace_validation"],
        "fig_validation": _figure(figs.get("validation_map")),
        "section": sections(has_paper(results), {
            **{a: bool(g) or ran(results, records, a) for a, g in generic.items()},
            "convergence": any(x["fig_element"] or x["refinement"] for x in main),
            "speed": bool(figs.get("speed")), "workspace": bool(figs.get("workspace_polar")),
            "validation": bool(results["studies"]["workspace_validation"]),
            "joint-orders": bool(joint_orders), "joint-couplings": bool(couplings),
            "hard-cases": bool(hard), "studies": bool(conventions or calibration),
            "lowest-modes": bool(lowest), "verification": bool(verification),
            "campaign": bool(campaign), "other": bool(other)}, records),
        "campaign": campaign,
        "designer_lines": designer_lines(results, campaign),
        "generic_sections": generic,
        "generic_refusals": refusals(results, records),
        "section_nothing": {r.section.anchor: r.section.nothing for r in records
                            if r.section is not None and r.section.nothing},
        "study_figures": {anchor: [dict(f, src=_figure(f["src"])) for f in shown]
                          for anchor, shown in figs.get("studies", {}).items()},
        "study_charts": {f["chart"] for shown in figs.get("studies", {}).values()
                         for f in shown if f.get("chart")},
        "cases": cases, "main_cases": main, "other_cases": other,
        "tables": setup_tables(results, c),
        "speed_table": speed_table(results, c),
        "joint_orders": joint_orders,
        "couplings": couplings,
        "couplings_sizes": ", ".join(
            f"{h:g}" for h in (studies["joint_couplings"][0]["readings"][0]["mesh_sizes_mm"]
                               if studies["joint_couplings"] else [])),
        "hard_cases": hard,
        "verification_table": verification,
        "verification": results["studies"].get("fem_verification"),
        "lowest_modes": lowest,
        "fig_leg_profile": _figure(figs.get("leg_profile")),
        "hard_failed": [r for r in results["studies"]["hard_cases"] if not r["passed"]],
        "conventions": conventions,
        "calibration": calibration,
        "calibration_study": studies["height_calibration"],
        "fig_speed": _figure(figs.get("speed")),
        "fig_ws_polar": _figure(figs.get("workspace_polar")),
        "fig_ws_height": _figure(figs.get("workspace_height")),
        "ws_heights": figs.get("workspace_heights"),
        "ws_settings": ws["settings"] if ws else None,
        "notes": [f"Warning: {w}" for w in results["scene"]["warnings"]] + notes,
        "has_paper": has_paper(results),
        "paper_seconds": PAPER_SECONDS if has_paper(results) else None,
        "generated": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
    }
    # the studies these results do not hold, named once under the contents
    springs = results["scene"]["manipulator"]["stiffness"]
    needless = set() if any(springs.values()) else {"lowest-modes"}  # a scene without springs
    ctx["omitted"] = [s.absent for key, s in section_order(records)
                      if s is not None and s.absent is not None and key not in ctx["section"]
                      and key not in needless]
    # the studies only some scenes ask for, named with what would ask for them (issue 54); the
    # full profile runs every study a scene asks for, so one missing there was not asked
    ctx["not_asked"] = [f"{s.title.split(':')[0].lower()} ({s.asks})"
                        for key, s in section_order(records)
                        if s is not None and s.asks is not None
                        and not ran(results, records, key) and results["profile"] == "full"]
    return ctx


def render_html(ctx: dict, charts: dict | None = None, directory: Path | None = None) -> str:
    """The page: static (the PDF's source: pictures as files under figures/) without
    `charts`; with them (`interactive.build_charts`) the interactive report.html, one
    self-contained file: charts drawn by the inlined plotly.js, the pictures left static
    embedded from `directory`."""
    align(tables_in({k: v for k, v in ctx.items() if k not in ("results", "scene", "env")}))
    env = Environment(loader=FileSystemLoader(TEMPLATES), autoescape=True,
                      undefined=StrictUndefined, trim_blocks=True, lstrip_blocks=True)
    env.globals["css"] = (TEMPLATES / "report.css").read_text(encoding="utf-8")
    page: dict[str, object] = {"charts": {}}
    if charts is None:
        env.filters["embed"] = lambda src: src
    else:
        if directory is None:
            raise ValueError("an interactive page needs the directory its pictures are in")
        env.filters["embed"] = interactive.embedded(directory)
        page = {"charts": charts, "plotly_js": interactive.plotly_js(),
                "chart_data": interactive.page_data(charts),
                "report_js": interactive.report_js()}
    return env.get_template("report.html.j2").render(**ctx, **page)


def render_pdf(html: str, base: Path, target: Path) -> None:
    """The page as a PDF, laid out with the report's own fonts (`fonts`), never the
    machine's: the same pages on every machine."""
    import logging

    from weasyprint import CSS, HTML
    from weasyprint.text.fonts import FontConfiguration

    from .fonts import font_faces

    logging.getLogger("weasyprint").setLevel(logging.ERROR)
    logging.getLogger("fontTools").setLevel(logging.ERROR)
    config = FontConfiguration()
    HTML(string=html, base_url=str(base)).write_pdf(
        str(target), stylesheets=[CSS(string=font_faces(), font_config=config)],
        font_config=config)
