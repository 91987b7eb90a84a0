"""`rps verify`: the solid FEM against published free-vibration benchmarks (NAFEMS and closed
forms), each at three mesh sizes; writes DIR/verification.json and prints the table."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from runtime.places import path_argument

from ..args import cache_dir, cache_option
from .registry import Command

if TYPE_CHECKING:  # results (and pydantic, an extra) only when the benchmarks run
    from results import FemVerification


def add_arguments(v: argparse.ArgumentParser) -> None:
    v.add_argument("--out", metavar="DIR", type=path_argument, default=Path("out"),
                   help="output directory of verification.json (default: out)")
    cache_option(v)
    v.add_argument("--json", action="store_true", help="print the record as one JSON object")


def table_lines(record: FemVerification) -> list[str]:
    """One line per reference mode: reference, finest answer, deviation, order, stated error."""
    head = (f"{'benchmark':<14} {'mode':<34} {'ref (Hz)':>10} {'FEM (Hz)':>10} {'dev %':>8} "
            f"{'order':>6} {'stated %':>9} {'tol %':>6}  passes")
    lines = [head, "-" * len(head)]
    for case in record["cases"]:
        for m in case["modes"]:
            order = "-" if m["observed_order"] is None else f"{m['observed_order']:.2f}"
            ok = ("yes" if m["passed"] else "NO") if m["counted"] else "not counted"
            lines.append(f"{case['name']:<14} {m['label'][:34]:<34} {m['reference_hz']:>10.3f} "
                         f"{m['hz'][-1]:>10.3f} {m['deviation_percent']:>+8.3f} {order:>6} "
                         f"{m['stated_error_percent']:>9.3g} {m['tolerance_percent']:>6.3g}"
                         f"  {ok}")
        for c in case["checks"]:
            values = c["value"] if isinstance(c["value"], list) else [c["value"]]
            verdict = ("holds" if c["passed"] else "FAILS") + ("" if c["counted"]
                                                              else ", not counted")
            lines.append(f"{case['name']:<14} check ({verdict}): {c['what']}: "
                         f"{', '.join(f'{v:.3g}' for v in values)} {c['op']} {c['limit']:.3g}")
    verdict = "all passed" if record["passed"] else "FAILED"
    lines.append(f"{len(record['cases'])} benchmarks, {verdict} "
                 f"({record['seconds']:.0f} s when computed)")
    return lines


def run(args: argparse.Namespace) -> int:
    from runtime.cache import ResultCache
    from runtime.outdir import check_output_dir, staged_output
    from studies.fem_verification import verification_record

    # where it goes, before the benchmarks run: an output directory of this pipeline (a run's
    # out/, whose other files are kept) or a new or empty one, never a folder of someone's files
    check_output_dir(args.out, "--out")
    cache = ResultCache(cache_dir(args))
    record = verification_record(cache,
                                 progress=lambda name: print(f"benchmark {name} ...",
                                                             file=sys.stderr, flush=True))
    from results.outputs import VERIFICATION

    with staged_output(args.out, keep=lambda name: name != VERIFICATION.file) as stage:
        VERIFICATION.write(stage, record)  # checked against its declaration
    path = args.out / VERIFICATION.file
    if args.json:  # the file's content, header included
        print(json.dumps(VERIFICATION.payload(record)))
    else:
        print("\n".join(table_lines(record)))
        print(f"wrote {path}")
    return 0 if record["passed"] else 1


COMMAND = Command("verify", "the solid FEM against published free-vibration benchmarks",
                  add_arguments, run)
