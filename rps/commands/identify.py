"""`rps identify`: the campaign's [identify] scene keys fitted to every pose's paired test
frequencies, with 95 % intervals and identifiability (modaltest/identify.py). Writes
DIR/identification.json, DIR/identified.toml (the scene with the fitted values, ready to
validate), DIR/tables/*.csv and DIR/identification.html, the directory replaced whole."""
from __future__ import annotations

import argparse
import json

from runtime.places import path_argument

from ..campaign_args import campaign_options, page, prepared
from .registry import Command


def add_arguments(p: argparse.ArgumentParser) -> None:
    campaign_options(p)
    p.add_argument("--out", metavar="DIR", type=path_argument, required=True,
                   help="directory of identification.json, identified.toml, tables and page "
                   "(replaced whole; required, no default)")


def run(args: argparse.Namespace) -> int:
    from modaltest.run import run_identification, write_identification
    from runtime.outdir import staged_output

    campaign, options, source, _ = prepared(args, fem=False, need_keys=True)
    data, identified = run_identification(campaign, options, source)
    with staged_output(args.out) as stage:
        write_identification(data, identified, stage)
        page("identification", data, stage)
    if args.json:
        print(json.dumps(data))
        return 0
    print(f"{campaign.name}: {data['model']['description']}")
    print(f"frequency residual rms {data['residual_rms_percent_before']:.3f} % -> "
          f"{data['residual_rms_percent_after']:.3f} % over "
          f"{sum(len(p['modes']) for p in data['fit'])} paired modes; noise "
          + (f"{data['noise']['frequency_percent']:.3g} % ({data['noise']['source']})"
             if data["noise"]["frequency_percent"] is not None else data["noise"]["source"]))
    for p in data["parameters"]:
        flag = "" if p["identifiable"] else "  NOT IDENTIFIABLE"
        print(f"  {p['key']}: {p['initial']:.6g} -> {p['value']:.6g} {p['unit']}  95 % "
              f"[{p['ci95'][0]:.4g}, {p['ci95'][1]:.4g}]{flag}: {p['reason']}")
    print(f"wrote {args.out}/identification.json and identified.toml ({data['evaluations']} "
          f"evaluations, {data['seconds']:.2f} s)")
    return 0


COMMAND = Command("identify", "fit scene keys (springs, masses, moduli) to a modal test "
                  "campaign, with 95 %% intervals", add_arguments, run, extras="modal-test")
