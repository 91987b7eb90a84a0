"""`rps analytical`: the substructure model at one case or pose, with the model's settings from
the scene, the run's choice (--from-results) or the options."""
from __future__ import annotations

import argparse
import time
from dataclasses import replace
from typing import TYPE_CHECKING

from analytical.beam import SHEAR_COEFFICIENTS
from analytical.params import (
    BEAM_THEORIES,
    JOINT_ENDS,
    LEG_MODELS,
    PLATFORM_INERTIAS,
    ModelOptions,
)
from common.errors import InputError
from scene import FidelitySettings

from ..args import (
    cache_option,
    emit,
    load,
    named_first,
    pose_case,
    pose_payload,
    run_choice,
    scene_args,
    with_choice,
    zone_cache,
)
from ..options import declared_option, typed
from .registry import Command

if TYPE_CHECKING:
    from results.outputs import AnalyticalAnswer


def cmd_analytical(args: argparse.Namespace) -> AnalyticalAnswer:
    """The analytical model at one pose: the --json answer, checked against its declaration
    (results.outputs.ANALYTICAL_ANSWER)."""
    from analytical.modal import ModalError
    from analytical.model import analyse
    from results.outputs import ANALYTICAL_ANSWER

    scene = load(args)
    case, _ = pose_case(scene, args)
    opts, source = with_choice(scene.analytical, run_choice(args, scene), args)
    if source is None:
        source = ("the scene's [analytical]" if scene.analytical_given else
                  "the scene's defaults, not the model a validated run chooses (that one: "
                  "--from-results out/results.json)")
    overrides = {k: getattr(args, k) for k in ("elements", "beam", "shear", "joint_ends",
                                               "legs", "end_zone", "platform_inertia", "modes")
                 if getattr(args, k) is not None}
    if args.legs == "solid" and args.joint_ends is None:  # solid legs have no end zones
        overrides["joint_ends"] = "beam"
    opts = zone_cache(args, replace(opts, **overrides))
    start = time.perf_counter()
    try:
        result = analyse(scene.manipulator, case.pose, opts)
    except ModalError as exc:
        raise named_first(exc, "modes", typed(args, "modes")) from None
    except ValueError as exc:  # e.g. end zones longer than the legs: name what was typed
        what = typed(args, "end_zone", "elements") if "end_zone" in str(exc) else ""
        raise InputError(f"{what}: {exc}" if what else str(exc)) from None
    seconds = time.perf_counter() - start
    return ANALYTICAL_ANSWER.checked(ANALYTICAL_ANSWER.payload({
        "case": case.name,
        "pose": pose_payload(case.pose),
        "warnings": list(scene.warnings),
        "model": "analytical",
        "settings_from": source + (" with options" if overrides else ""),
        "elements": opts.elements,
        "beam": opts.beam,
        "shear": opts.shear,
        "joint_ends": opts.joint_ends,
        "legs": opts.legs,
        "platform_inertia": opts.platform_inertia,
        **({"end_zone_diameters": opts.end_zone} if opts.joint_ends == "solid" else {}),
        "frequencies_hz": [float(x) for x in result.frequencies_hz],
        "leg_lengths_mm": [float(x) * 1e3 for x in result.geometry.leg_lengths],
        "actuation_mm": [float(x) * 1e3 for x in result.geometry.actuation],
        "dofs": int(result.model.stiffness.shape[0]),
        "seconds": seconds,
    }))


def add_arguments(a: argparse.ArgumentParser) -> None:
    scene_args(a)
    declared_option(a, "--elements", ModelOptions, "elements", metavar="N",
                    help="beam elements per leg s (default: the scene's)")
    a.add_argument("--beam", choices=BEAM_THEORIES, help="beam theory (default: the scene's)")
    a.add_argument("--shear", choices=SHEAR_COEFFICIENTS,
                   help="Timoshenko shear coefficient (default: the scene's)")
    a.add_argument("--joint-ends", choices=JOINT_ENDS,
                   help="leg ends: beam elements to the joint centre, or condensed solid end "
                   "zones (default: the scene's)")
    a.add_argument("--legs", choices=LEG_MODELS,
                   help="the legs' parts: frame elements, or each part condensed whole from its "
                   "solid (slower; --beam, --shear and --joint-ends do not apply) (default: the "
                   "scene's)")
    declared_option(a, "--end-zone", ModelOptions, "end_zone", metavar="D",
                    help="length of each solid end zone, in leg diameters (default: the "
                    "scene's)")
    a.add_argument("--platform-inertia", choices=PLATFORM_INERTIAS,
                   help="platform inertia: the plate's own, or Eq. (8)'s m r2^2 "
                        "(default: the scene's)")
    declared_option(a, "--modes", FidelitySettings, "modes", metavar="N",
                    help="number of modes (default: the scene's)")
    cache_option(a)


def run(args: argparse.Namespace) -> int:
    emit(cmd_analytical(args), args.json)
    return 0


COMMAND = Command("analytical", "substructure model of one case (Gong & Lou's Eqs. 1-25)",
                  add_arguments, run)
