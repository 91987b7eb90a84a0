"""The report's entry point: results.json -> figures, report.html, report.pdf.

Everything is rendered into a staging directory beside the output directory, which is swapped
in whole only when the HTML and the PDF both exist (runtime.outdir), so a failed or killed
render leaves the previous outputs (or nothing) and never a half-written report. Every number
printed in a table is looked up in results.json by a JSON pointer, which the table cell carries
as `data-src` (tests check them).
"""
from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Sequence

from common.paths import inside
from common.worker import stoppable
from results import Record
from results.tables import write_tables
from runtime.outdir import staged_output

from .document import context, render_html, render_pdf
from .figure_set import ReportError, make_figures
from .interactive import build_charts
from .results import load_results

__all__ = ["ReportError", "build_report", "render_report"]

REPORT_ENTRIES = ("report.html", "report.pdf", "figures")
LEGACY_TEMPORARIES = (".report-", ".figures-old-")  # left inside out/ by earlier versions


def build_report(results_json_path, out_dir, cache_dir: Path | None = None,
                 workers: int | None = None, *,
                 records: Sequence[Record]) -> tuple[Path, Path]:
    """Write out_dir/report.html, out_dir/report.pdf and out_dir/figures/ from a results file.

    The new out_dir is built whole beside it (its other files copied, then the report
    rendered) and swapped in as one step (runtime.outdir): never a temporary folder inside
    out_dir, never a report of one run beside the figures of another. ValueError (naming the
    path) for a missing, malformed or outdated results file, ReportError when a picture or the
    PDF cannot be rendered; either way out_dir is left as it was. Figures are drawn on
    `workers` processes (default: the cores) and reused from `cache_dir` when given.
    `records`: the registry of study records (`studies.RECORDS`), handed in by the caller.
    """
    out = Path(out_dir)
    results = load_results(results_json_path, records)  # refused before out_dir is locked
    with staged_output(out, keep=lambda name: name not in REPORT_ENTRIES
                       and not name.startswith(LEGACY_TEMPORARIES)) as stage:
        stoppable(render_report, results_json_path, stage, cache_dir,  # Ctrl-C / SIGTERM
                  workers or os.cpu_count() or 1, records=records)  # stop it at once
        # the full tables the report links, beside it: these results' only, never those of
        # the run the folder held before (a run's own report has them from the run itself)
        tables = inside(stage, "tables")
        shutil.rmtree(tables, ignore_errors=True)
        tables.mkdir()
        write_tables(results, stage, records)
    return out / "report.html", out / "report.pdf"


def render_report(results_json_path, directory, cache_dir: Path | None = None,
                  workers: int = 1, *, records: Sequence[Record]) -> tuple[Path, Path]:
    """Render report.html, report.pdf and figures/ into `directory`, a staging directory that
    the caller swaps in whole (nothing here is visible until then); the figures on `workers`
    processes, reused from the figure cache under `cache_dir` (`figure_jobs`).

    report.pdf is the static page (the pictures of figures/); report.html the same context
    with the interactive charts (reports.interactive), self-contained."""
    results_path = Path(results_json_path)
    target = Path(directory)
    results = load_results(results_path, records)
    fig_dir = inside(target, "figures")
    fig_dir.mkdir()
    try:
        ctx = context(results, results_path,
                      make_figures(results, results_path, fig_dir, cache_dir, workers), records)
        html = render_html(ctx)  # static: the PDF's source
        notes: list[str] = []
        charts = build_charts(results, results_path, notes)
        page = render_html(dict(ctx, notes=ctx["notes"] + notes), charts, target)
    except (ReportError, ValueError):
        raise
    except Exception as exc:  # noqa: BLE001
        raise ReportError(f"report rendering failed ({type(exc).__name__}: "
                          f"{' '.join(str(exc).split())})") from None
    inside(target, "report.html").write_text(page, encoding="utf-8")
    try:
        render_pdf(html, target, inside(target, "report.pdf"))
    except Exception as exc:  # noqa: BLE001  (weasyprint raises anything)
        raise ReportError(f"PDF rendering failed ({type(exc).__name__}: "
                          f"{' '.join(str(exc).split())})") from None
    return target / "report.html", target / "report.pdf"
