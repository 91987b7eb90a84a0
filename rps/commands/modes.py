"""`rps modes`: the model's predicted modes at one pose as a Universal File (nodes 2411, modes
55) for test software, at the points of a CSV or at the candidate sensor points, and with
--suggest N the N sensor directions effective independence keeps (pre-test planning;
modaltest/pretest.py)."""
from __future__ import annotations

import argparse
import json

from common.errors import InputError
from runtime.places import path_argument
from scene import FidelitySettings

from ..args import (
    load,
    pose_case,
    pose_payload,
    run_choice,
    scene_args,
    warn,
    with_choice,
    zone_cache,
)
from ..options import declared_option
from .registry import Command

TOLERANCE = 0.010  # m: a point within 10 mm of a body's surface lies on it (as a campaign's)


def add_arguments(p: argparse.ArgumentParser) -> None:
    scene_args(p)
    p.add_argument("--out", metavar="FILE", type=path_argument, required=True,
                   help="the Universal File written (.unv or .uff); with --suggest also "
                   "FILE's name with .sensors.csv (required, no default)")
    p.add_argument("--points", metavar="CSV", type=path_argument,
                   help="points x_mm, y_mm, z_mm in the base frame at the pose, each on the "
                   "platform or a leg (default: candidate points on the platform's top face and "
                   "the legs' surfaces)")
    declared_option(p, "--modes", FidelitySettings, "modes", metavar="N",
                    help="number of modes (default: the scene's)")
    p.add_argument("--suggest", metavar="N", type=int,
                   help="also choose N sensor directions by effective independence (at least "
                   "the number of modes; default: none)")


def run(args: argparse.Namespace) -> int:
    from analytical.substructure import model_coordinates
    from common.atomic import write_text_atomic
    from modaltest import uff
    from modaltest.models import analytical_field
    from modaltest.pretest import (
        candidate_points,
        effective_independence,
        prediction,
        read_points,
    )
    from results.declare import csv_text

    if args.out.suffix.lower() not in (".unv", ".uff"):
        raise InputError(f"--out {args.out}: expected a file name ending .unv or .uff")
    if not args.out.absolute().parent.is_dir():
        raise InputError(f"--out {args.out}: its directory does not exist")
    scene = load(args)
    case, geometry = pose_case(scene, args)
    options, _ = with_choice(scene.analytical, run_choice(args, scene), args)
    options = zone_cache(args, options)
    modes = args.modes if args.modes is not None else scene.fidelity.modes
    modes = min(modes, model_coordinates(scene.manipulator, options))
    points = (read_points(args.points) if args.points is not None
              else candidate_points(scene.manipulator, geometry))
    if args.suggest is not None and not modes <= args.suggest <= 3 * len(points):
        raise InputError(f"--suggest {args.suggest}: expected {modes} (the modes) to "
                         f"{3 * len(points)} (the points' directions)")
    field = analytical_field(scene.manipulator, case.pose, geometry, options, modes)
    where = f"--points {args.points}" if args.points is not None else "candidate points"
    nodes, predicted = prediction(field, scene.manipulator, geometry, points, modes, TOLERANCE,
                                  where)
    uff.write_uff(args.out, nodes, predicted,
                  description=f"rps modes: {scene.name}, case {case.name}")
    payload = {"case": case.name, "pose": pose_payload(case.pose), "out": str(args.out),
               "points": len(points), "frequencies_hz": predicted.frequencies_hz.tolist()}
    if args.suggest is not None:
        keep = effective_independence(predicted.shapes, args.suggest)
        names = "xyz"
        rows = [{"node": int(predicted.dofs.node[k]),
                 **{f"{c}_mm": float(v * 1e3) for c, v in
                    zip(names, points[int(predicted.dofs.node[k]) - 1])},
                 "direction": names[int(abs(predicted.dofs.direction[k]).argmax())]}
                for k in keep]
        sensors = args.out.with_suffix(".sensors.csv")
        write_text_atomic(sensors, csv_text(rows))
        payload["sensors"] = str(sensors)
    if args.json:
        from ..answers import MODES_ANSWER
        print(json.dumps(MODES_ANSWER.checked(MODES_ANSWER.payload(payload))))
    else:
        print(f"wrote {args.out}: {len(points)} points, {modes} modes "
              f"({', '.join(f'{f:.2f}' for f in predicted.frequencies_hz)} Hz)")
        if "sensors" in payload:
            print(f"wrote {payload['sensors']}: {args.suggest} sensor directions by effective "
                  "independence")
    warn(scene.warnings)
    return 0


COMMAND = Command("modes", "the model's modes at chosen points as a Universal File, and "
                  "sensor positions by effective independence (pre-test planning)",
                  add_arguments, run, extras="modal-test")
