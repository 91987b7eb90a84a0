"""`rps report`: rebuild report.html, report.pdf and figures/ from a results file (the report
of every registered study: `studies.RECORDS`). A bad results file is one line and exit 2; an
interruption leaves the output directory as it was."""
from __future__ import annotations

import argparse
from pathlib import Path

from runtime.places import path_argument

from .registry import Command


def add_arguments(r: argparse.ArgumentParser) -> None:
    r.add_argument("--results", metavar="PATH", type=path_argument,
                   default=Path("out/results.json"), help="results file written by a run")
    r.add_argument("--out", metavar="DIR", type=path_argument, default=Path("out"),
                   help="directory for report.html, report.pdf and figures/")


def run(args: argparse.Namespace) -> int:
    from common.messages import failed
    from reports.build import build_report
    from studies import RECORDS

    try:
        html, pdf = build_report(args.results, args.out, records=RECORDS)
    except KeyboardInterrupt as exc:  # the report is swapped in whole, or not at all
        return failed(exc, interrupted="the output directory was left as it was")
    print(f"wrote {html} and {pdf}")
    return 0


COMMAND = Command("report", "rebuild the HTML and PDF report from a results file",
                  add_arguments, run, extras="fem,report")
