"""`rps uncertainty`: the scene's input uncertainty ([uncertainty]) through the fast model at one
pose: per mode the mean, standard deviation and 2.5 / 97.5 % quantiles of the frequency, the
first-order and total Sobol' indices of every input, each with its sampling error (and the same
for the least dynamic stiffness at the tool where the scene has [tool] or [damping]);
solvers/uncertainty.py. Writes DIR/uncertainty.json, the directory replaced whole."""
from __future__ import annotations

import argparse
import json
import time

from common.errors import InputError
from runtime.places import path_argument

from ..args import load, pose_case, pose_payload, run_choice, scene_args, warn, with_choice
from ..options import declared_option
from .registry import Command

MAX_SECONDS = 1800.0  # a propagation longer than this is refused before it starts


def add_arguments(p: argparse.ArgumentParser) -> None:
    from scene.uncertainty import UncertaintySettings

    scene_args(p)
    declared_option(p, "--samples", UncertaintySettings, "samples", metavar="N",
                    help="base points of the Sobol' design (default: the scene's "
                    "[uncertainty] samples)")
    p.add_argument("--out", metavar="DIR", type=path_argument, required=True,
                   help="directory of uncertainty.json, replaced whole (required, no default)")


def run(args: argparse.Namespace) -> int:
    from runtime.outdir import check_output_dir, staged_output
    from solvers.uncertainty import propagate, refusal

    check_output_dir(args.out, "--out")
    scene = load(args)
    if scene.uncertainty is None:
        raise InputError(f"--scene {args.scene}: the scene has no [uncertainty] table (declare "
                         "the uncertain inputs: docs/scenes.md)")
    from scene import parse_scene
    from scene.uncertainty import check_ends

    check_ends(scene.uncertainty, scene.raw, scene.path, parse_scene)
    case, _ = pose_case(scene, args)
    options, source = with_choice(scene.analytical, run_choice(args, scene), args)
    why = refusal(scene, options)
    if why is not None:
        raise InputError(f"--scene {args.scene}: {why}")
    start = time.perf_counter()
    record = propagate(scene, options, case.pose, scene.fidelity.modes,
                       budget_seconds=MAX_SECONDS, samples=args.samples)
    payload = {"scene": scene.name, "case": case.name, "pose": pose_payload(case.pose),
               "settings_from": source or "the scene's", **record,
               "seconds": time.perf_counter() - start, "warnings": list(scene.warnings)}
    from results.outputs import UNCERTAINTY

    payload = UNCERTAINTY.payload(payload)
    with staged_output(args.out) as stage:  # checked against its declaration
        UNCERTAINTY.write(stage, payload)
    if args.json:
        print(json.dumps(payload))
    else:
        print(f"{scene.name}, case {case.name}: {record['model']}; {record['design']}")
        for m in record["modes"]:
            key, top = max(m["sobol_total"].items(), key=lambda kv: kv[1] or 0.0)
            print(f"  mode {m['mode']}: mean {m['mean_hz']:.4g} Hz, sd {m['std_hz']:.3g} Hz, "
                  f"95 % {m['q025_hz']:.4g} .. {m['q975_hz']:.4g} Hz"
                  + (f"; most: {key} (total index {top:.2f})" if top is not None else ""))
        for d, s in (record["least_dynamic_stiffness"] or {}).items():
            print(f"  least dynamic stiffness {d}: mean {s['mean_n_per_m']:.4g} N/m, 95 % "
                  f"{s['q025_n_per_m']:.4g} .. {s['q975_n_per_m']:.4g} N/m")
        print(f"wrote {args.out}/uncertainty.json ({record['runs']:,} runs, "
              f"{payload['seconds']:.1f} s)")
    warn(scene.warnings)
    return 0


COMMAND = Command("uncertainty", "input uncertainty through the fast model at one pose: "
                  "frequency statistics and Sobol' indices of the scene's [uncertainty]",
                  add_arguments, run, extras="fem")
