"""`rps correlate`: a modal test campaign against the model: per pose the model's modes at the
test's nodes and directions, the MAC matrix, pairs by shape and frequency with their errors,
the unpaired modes named (modaltest/). Writes DIR/correlation.json, DIR/tables/*.csv and
DIR/correlation.html, the directory replaced whole."""
from __future__ import annotations

import argparse
import json

from runtime.places import path_argument

from ..campaign_args import campaign_options, page, prepared
from .registry import Command


def add_arguments(p: argparse.ArgumentParser) -> None:
    campaign_options(p)
    p.add_argument("--model", choices=("analytical", "fem"), default="analytical",
                   help="the model correlated: the analytical model (the scene's settings, or "
                   "the run's choice with --from-results) or the scene's solid FEM at each pose")
    p.add_argument("--out", metavar="DIR", type=path_argument, required=True,
                   help="directory of correlation.json, its tables and page, replaced whole "
                   "(required, no default)")


def run(args: argparse.Namespace) -> int:
    from modaltest.run import run_correlation, write_correlation
    from runtime.outdir import staged_output

    campaign, options, source, cache = prepared(args, fem=args.model == "fem")
    data = run_correlation(campaign, options, source, args.model, cache)
    with staged_output(args.out) as stage:
        write_correlation(data, stage)
        page("correlation", data, stage)
    if args.json:
        print(json.dumps(data))
        return 0
    print(f"{campaign.name}: {data['model']['description']}")
    for pose in data["poses"]:
        print(f"pose {pose['name']} ({pose['source']}): {len(pose['pairs'])} of "
              f"{len(pose['test_hz'])} test modes paired")
        for p in pose["pairs"]:
            print(f"  test {p['test_mode']} {p['test_hz']:9.3f} Hz ~ model {p['model_mode']} "
                  f"{p['model_hz']:9.3f} Hz  {p['error_percent']:+7.3f} %  MAC "
                  f"{p['mac']:.3f}")
        for u in pose["unpaired_test_modes"]:
            print(f"  test {u['test_mode']} {u['test_hz']:9.3f} Hz unpaired: {u['reason']}")
    print(f"wrote {args.out}/correlation.json ({data['seconds']:.2f} s)")
    return 0


COMMAND = Command("correlate", "a modal test campaign against the model: MAC, pairs, "
                  "frequency errors", add_arguments, run, extras="modal-test")
