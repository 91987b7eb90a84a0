"""`rps validate`: the whole validation of a scene into out/ (results, tables, mode files and,
unless --no-report, the report)."""
from __future__ import annotations

import argparse
from pathlib import Path

from runtime.places import path_argument

from .. import human
from ..args import cache_dir, cache_option, scene_option
from ..options import Workers, declared_option
from .registry import Command


def add_arguments(v: argparse.ArgumentParser) -> None:
    scene_option(v)
    v.add_argument("--out", metavar="DIR", type=path_argument, default=Path("out"),
                   help="output directory: results.json, tables/, modes/, report.html/.pdf")
    cache_option(v)
    v.add_argument("--profile", choices=("full", "ci"), default="full",
                   help="full: every case and study; ci: the scene's ci_cases only, no "
                        "refinement study or variants")
    v.add_argument("--no-report", action="store_true", help="skip the HTML/PDF report")
    declared_option(v, "--workers", Workers, "workers", default=None, metavar="N",
                    help="local worker processes of the workspace sweep (default: the number "
                    "of cores)")
    v.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="send the sweep's poses to this running dask.distributed scheduler "
                        "(e.g. tcp://10.0.0.5:8786) instead of local workers (default: none)")


def run(args: argparse.Namespace) -> int:
    from pipeline.run import Report, validate

    report: Report | None = None
    if not args.no_report:  # the [report] extra only when a report is asked for
        from functools import partial

        from reports.build import render_report
        from studies import RECORDS
        report = partial(render_report, records=RECORDS)
    from runtime.outdir import check_output_dir
    from runtime.places import MIN_FREE_RUN, check_scheduler

    check_output_dir(args.out)  # every place the run uses, before the scene is read
    cache = cache_dir(args, need=MIN_FREE_RUN if args.profile == "full" else None)
    scheduler = check_scheduler(args.scheduler) if args.scheduler is not None else None
    results = validate(args.scene, args.out, cache, args.profile, report=report,
                       workers=args.workers, scheduler=scheduler)
    print(human.summary(results, args.out, report=not args.no_report))
    return 0


COMMAND = Command("validate", "run the whole validation of a scene: results, tables, report",
                  add_arguments, run, extras="fem,report")
