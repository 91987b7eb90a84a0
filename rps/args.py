"""What several commands share: the scene, case and pose options, the cache directory, the
run's choice read from --from-results, and how a command prints its payload."""
from __future__ import annotations

import argparse
import json
import math
import re
import sys
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping

from common.errors import InputError
from common.locations import DISTRIBUTION, cache_root, checkout_root, default_scene
from runtime.places import path_argument

from . import human
from .options import declared_option, typed

if TYPE_CHECKING:
    from results.tool_records import OutputPose


def scene_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--scene", metavar="TOML", default=str(default_scene()),
                   help="scene file: manipulator, poses, fidelity")


def scene_args(p: argparse.ArgumentParser) -> None:
    scene_option(p)
    p.add_argument("--case", metavar="NAME",
                   help="case of the scene (default: the scene's first case)")
    from scene import CaseSettings
    declared_option(p, "--height", CaseSettings, "height", metavar="MM",
                    help="platform height z, mm (default: the case's)")
    declared_option(p, "--azimuth", CaseSettings, "azimuth", metavar="DEG",
                    help="tilt azimuth phi, degrees (default: the case's)")
    declared_option(p, "--tilt", CaseSettings, "tilt", metavar="DEG",
                    help="tilt theta, degrees (default: the case's)")
    p.add_argument("--from-results", metavar="JSON", type=path_argument,
                   help="use the model the validated run chose for this scene, read from "
                   "the fidelity block of its results.json (e.g. out/results.json, written "
                   "by `make`); options given beside it still override (default: the scene's "
                   "own settings)")
    p.add_argument("--json", action="store_true", help="print one JSON object, exact values")


def cache_option(p: argparse.ArgumentParser) -> None:
    try:
        where = str(cache_root())
    except RuntimeError:  # without the [fem] extra there is nothing to cache
        where = "the user cache directory"
    p.add_argument("--cache", metavar="DIR", type=path_argument,
                   help=f"cache of FEM results, meshes and solid end zones (default: {where}; "
                        "the checkout's .cache/ "
                        "when run from the repository)")


def cache_dir(args: argparse.Namespace, stores: bool = True, need: int | None = None) -> Path:
    """The cache directory, checked to be a directory the run can write into with room for
    what it `stores` (`need` bytes, default runtime.places.MIN_FREE_CACHE; one line naming
    --cache otherwise, before any work)."""
    from runtime.places import MIN_FREE_CACHE, check_free_space, check_writable_dir
    option = "--cache" if args.cache is not None else "the cache directory (default of --cache)"
    path = check_writable_dir(args.cache if args.cache is not None else cache_root(), option)
    if stores:
        check_free_space(path, need or MIN_FREE_CACHE, option, typed=str(args.cache or path))
    return path


def zone_cache(args: argparse.Namespace, options):
    """The model options whose solid end zones are kept under --cache (checked writable with
    room first); options without solid joint ends store nothing and are returned as they are."""
    if options.joint_ends != "solid":
        return options
    return replace(options, cache_dir=str(cache_dir(args)))


def pose_case(scene, args):
    """The named case, its pose overridden by --height/--azimuth/--tilt (read in mm and deg,
    in SI here), and its geometry; an unreachable pose is refused naming what was typed."""
    from analytical.kinematics import PoseError, pose_geometry

    case = scene.case(args.case if args.case is not None else next(iter(scene.cases)))
    pose = case.pose
    for name in ("height", "azimuth", "tilt"):
        if getattr(args, name) is not None:
            pose = replace(pose, **{name: getattr(args, name)})
    try:
        geometry = pose_geometry(scene.manipulator, pose)
    except PoseError as exc:
        from studies.reachable import case_keys
        what = typed(args, "height", "azimuth", "tilt") or (
            f"{case_keys(case.name, case)} in {args.scene}")
        raise InputError(f"{what}: {exc}") from None
    return replace(case, pose=pose), geometry


def named_first(exc: Exception, key: str, what: str) -> Exception:
    """`key = value: why` as `what: why` when the user typed `what` (e.g. --size 0.5 mm)."""
    text = str(exc)
    found = re.match(rf"{re.escape(key)} = [^:]*: ", text)
    if what and found:
        return InputError(f"{what}: {text[found.end():]}")
    return exc


def run_choice(args: argparse.Namespace, scene) -> Mapping[str, Any] | None:
    """The fidelity block of --from-results, checked to be a run of this scene file."""
    if args.from_results is None:
        return None
    import hashlib

    from results import read
    from studies import RECORDS

    where = f"--from-results {args.from_results}"
    try:
        results = read(args.from_results, RECORDS)
    except ValueError as exc:
        raise InputError(f"{where}: {exc}") from None
    digest = hashlib.sha256(Path(args.scene).read_bytes()).hexdigest()
    if results["scene"]["sha256"] != digest or results["scene"]["name"] != scene.name:
        raise InputError(f"{where}: a run of scene {results['scene']['path']} "
                         f"({results['scene']['name']!r}), not of --scene {args.scene} as it "
                         "is now; run `rps validate --scene` on it first")
    return results["fidelity"]


CHOSEN_ANALYTICAL = ("beam", "shear", "joint_ends", "legs", "elements", "platform_inertia")


def with_choice(options, chosen: Mapping[str, Any] | None, args: argparse.Namespace):
    """(options, where they came from): `options` with the run's chosen analytical settings
    (the fidelity block `run_choice` read), or as they are and None without a choice."""
    if chosen is None:
        return options, None
    return (replace(options, **{k: chosen["analytical"][k] for k in CHOSEN_ANALYTICAL}),
            f"the run's choice, {chosen['analytical']['setting']} ({args.from_results})")


def pose_payload(pose) -> OutputPose:
    """A pose as every command's output gives it (mm, degrees)."""
    from results.tool_records import OutputPose
    return OutputPose(height_mm=round(pose.height * 1e3, 9),
                      azimuth_deg=round(math.degrees(pose.azimuth), 9),
                      tilt_deg=round(math.degrees(pose.tilt), 9))


def load(args: argparse.Namespace):
    """The scene of --scene (every check of its values and of the machine as a whole)."""
    from scene import load_scene
    return load_scene(args.scene)


def emit(payload: Mapping[str, Any], as_json: bool) -> None:
    """The command's result on stdout; its "warnings" (the scene's, analytical.plausibility)
    stay in the JSON object and are printed on stderr after the result."""
    warnings = payload.get("warnings") or []
    if as_json:
        print(json.dumps(payload, indent=None))
    else:
        print("\n".join(human.payload_lines({k: v for k, v in payload.items()
                                             if k not in ("warnings", "record", "schema")})))
    warn(warnings)


def warn(warnings) -> None:
    """The scene's warnings on stderr, one line each, after a command's result."""
    for text in warnings:
        print(f"warning: {text}", file=sys.stderr)


def checkout(command: str) -> Path:
    """The repository checkout, which the developer commands write into."""
    root = checkout_root()
    if root is None:
        raise InputError(f"{command}: writes into the repository checkout; run it from a "
                         f"clone of {DISTRIBUTION} (pip install -e .)")
    return root


def fem_choices() -> tuple[tuple[str, ...] | None, ...]:
    """The FEM's platform, coupling and leg-discretisation options; Nones without the [fem]
    extra (then the fem command says which extra to install)."""
    from common.joints import COUPLINGS

    try:
        from fem_reference.model import LEG_MODELS, PLATFORMS
    except ImportError:
        return None, None, None
    return PLATFORMS, COUPLINGS, LEG_MODELS
