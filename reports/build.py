"""The report's entry point: results.json -> figures, report.html, report.pdf.

Everything is rendered into a hidden temporary directory beside the outputs and moved into place
only when the HTML and the PDF both exist, so a failed render leaves the previous report (or
nothing) and never a half-written one. Every number printed in a table is looked up in
results.json by a JSON pointer, which the table cell carries as `data-src` (tests check them).
"""
from __future__ import annotations

import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

from .document import context, render_html, render_pdf
from .figure_set import ReportError, make_figures
from .results import load_results

__all__ = ["ReportError", "build_report"]


def build_report(results_json_path, out_dir) -> tuple[Path, Path]:
    """Write out_dir/report.html, out_dir/report.pdf and out_dir/figures/ from a results file.

    ValueError (naming the path) for a missing, malformed or outdated results file, ReportError
    when a picture or the PDF cannot be rendered; either way out_dir is left as it was.
    """
    results_path = Path(results_json_path)
    results = load_results(results_path)
    with _staged(Path(out_dir)) as tmp:
        fig_dir = tmp / "figures"
        fig_dir.mkdir()
        try:
            html = render_html(context(results, results_path,
                                       make_figures(results, results_path, fig_dir)))
        except (ReportError, ValueError):
            raise
        except Exception as exc:  # noqa: BLE001
            raise ReportError(f"report rendering failed ({type(exc).__name__}: "
                              f"{' '.join(str(exc).split())})") from None
        (tmp / "report.html").write_text(html, encoding="utf-8")
        try:
            render_pdf(html, tmp, tmp / "report.pdf")
        except Exception as exc:  # noqa: BLE001  (weasyprint raises anything)
            raise ReportError(f"PDF rendering failed ({type(exc).__name__}: "
                              f"{' '.join(str(exc).split())})") from None
    return Path(out_dir) / "report.html", Path(out_dir) / "report.pdf"


@contextmanager
def _staged(out: Path):
    """A temporary directory inside `out`; when the block succeeds its figures/, report.html
    and report.pdf replace the outputs (figures swapped in, then each file renamed over the
    old one); on failure nothing changes, and an `out` made here is removed again."""
    created = not out.exists()
    out.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=out, prefix=".report-"))
    done = False
    try:
        yield tmp
        old = None
        if (out / "figures").exists():
            old = Path(tempfile.mkdtemp(dir=out, prefix=".figures-old-"))
            os.replace(out / "figures", old / "figures")
        os.replace(tmp / "figures", out / "figures")
        for name in ("report.html", "report.pdf"):
            os.replace(tmp / name, out / name)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
        done = True
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        if created and not done:
            shutil.rmtree(out, ignore_errors=True)  # we made it, it holds nothing else
