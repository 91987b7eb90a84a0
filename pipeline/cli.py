"""Command line: `python -m pipeline {analytical,fem,validate,update-baselines} ...`.

Every expected failure (bad scene value, unreachable pose, solver failure) prints one line on
stderr naming the offending value and exits with status 2, without a traceback.
"""
from __future__ import annotations

import argparse
import json
import math
import signal
import time
from dataclasses import replace
from pathlib import Path

from analytical.params import BEAM_THEORIES, PLATFORM_INERTIAS
from common.messages import failed

from fem_reference.constraints import COUPLINGS as FEM_COUPLINGS
from fem_reference.model import PLATFORMS as FEM_PLATFORMS

EXIT_BAD_INPUT = 2


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} must be >= 1")
    return value


def _finite(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text} is not finite")
    return value


def _positive_mm(text: str) -> float:
    value = _finite(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"{text} must be a positive size in mm")
    return value


def _scene_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--scene", default="scenes/paper.toml", help="scene file (TOML)")
    p.add_argument("--case", default=None, help="case name in the scene (default: its first)")
    p.add_argument("--height", type=_finite, metavar="MM",
                   help="platform height z in mm (overrides the case's pose)")
    p.add_argument("--azimuth", type=_finite, metavar="DEG", help="tilt azimuth phi in degrees")
    p.add_argument("--tilt", type=_finite, metavar="DEG", help="tilt theta in degrees")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def _case(scene, args):
    """The named case, its pose overridden by --height/--azimuth/--tilt (mm, deg at the edge)."""
    case = scene.case(args.case if args.case is not None else next(iter(scene.cases)))
    pose = case.pose
    if args.height is not None:
        pose = replace(pose, height=args.height * 1e-3)
    if args.azimuth is not None:
        pose = replace(pose, azimuth=math.radians(args.azimuth))
    if args.tilt is not None:
        pose = replace(pose, tilt=math.radians(args.tilt))
    return replace(case, pose=pose)


def _pose_payload(pose) -> dict:
    return {"height_mm": round(pose.height * 1e3, 9),
            "azimuth_deg": round(math.degrees(pose.azimuth), 9),
            "tilt_deg": round(math.degrees(pose.tilt), 9)}


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage error is one line on stderr and exit status 2."""

    def error(self, message: str):  # noqa: D401 - argparse hook
        self.exit(EXIT_BAD_INPUT, f"error: {self.prog}: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="python -m pipeline", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    a = sub.add_parser("analytical", help="substructure model of one case")
    _scene_args(a)
    a.add_argument("--elements", type=_positive_int, help="beam elements per leg (s)")
    a.add_argument("--beam", choices=BEAM_THEORIES)
    a.add_argument("--platform-inertia", choices=PLATFORM_INERTIAS)
    a.add_argument("--modes", type=_positive_int)

    f = sub.add_parser("fem", help="3D solid FEM reference of one case")
    _scene_args(f)
    f.add_argument("--size", type=_positive_mm, help="mesh size in mm (overrides the scene)")
    f.add_argument("--platform", choices=FEM_PLATFORMS)
    f.add_argument("--coupling", choices=FEM_COUPLINGS)
    f.add_argument("--modes", type=_positive_int)
    f.add_argument("--vtu", help="write the mode shapes to this VTU file")
    f.add_argument("--estimate-error", action="store_true",
                   help="also run the scene's refinement sequence (cached) and report the "
                        "estimated discretisation error of this size")

    w = sub.add_parser("workspace", help="f1..fN over the regular workspace (Fig. 6)")
    w.add_argument("--scene", default="scenes/paper.toml")
    w.add_argument("--layers", type=_positive_int, default=8, help="height layers")
    w.add_argument("--rings", type=_positive_int, default=6, help="tilt rings per layer")
    w.add_argument("--azimuths", type=_positive_int, default=36, help="azimuths per ring")
    w.add_argument("--modes", type=_positive_int, default=3)
    w.add_argument("--json", action="store_true")

    v = sub.add_parser("validate", help="run the whole validation of a scene into out/")
    v.add_argument("--scene", default="scenes/paper.toml")
    v.add_argument("--out", default="out")
    v.add_argument("--cache", default=".cache")
    v.add_argument("--profile", choices=("full", "ci"), default="full",
                   help="full: every study; ci: the CI-sized subset")
    v.add_argument("--no-report", action="store_true", help="skip the HTML/PDF report")

    c = sub.add_parser("check-baselines", help="compare error tables with tests/baselines")
    c.add_argument("--results", default=None,
                   help="read the tables from this results.json (computed at the baselines' "
                        "mesh size) instead of recomputing them")

    r = sub.add_parser("readme", help="refresh README.md's results block from results.json")
    r.add_argument("--results", default="out/results.json")

    sub.add_parser("scene-docs", help="rewrite docs/scenes.md from the scene declarations")

    u = sub.add_parser("update-baselines", help="rewrite tests/baselines from a fresh CI run")
    u.add_argument("--scene", default="scenes/paper.toml")
    return parser


def _emit(payload: dict, as_json: bool) -> None:
    if as_json:
        print(json.dumps(payload, indent=None))
        return
    for key, value in payload.items():
        if key == "frequencies_hz":
            value = ", ".join(f"{x:.2f}" for x in value)
        print(f"{key:>18}: {value}")


def cmd_analytical(args: argparse.Namespace) -> dict:
    from analytical.model import analyse
    from .scene import load_scene

    scene = load_scene(args.scene)
    case = _case(scene, args)
    opts = scene.analytical
    overrides = {k: v for k, v in {"elements": args.elements, "beam": args.beam,
                                   "platform_inertia": args.platform_inertia,
                                   "modes": args.modes}.items() if v is not None}
    opts = replace(opts, **overrides)
    start = time.perf_counter()
    result = analyse(scene.manipulator, case.pose, opts)
    seconds = time.perf_counter() - start
    return {
        "case": case.name,
        "pose": _pose_payload(case.pose),
        "model": "analytical",
        "elements": opts.elements,
        "beam": opts.beam,
        "platform_inertia": opts.platform_inertia,
        "frequencies_hz": [float(x) for x in result.frequencies_hz],
        "leg_lengths_mm": [float(x) * 1e3 for x in result.geometry.leg_lengths],
        "dofs": int(result.model.stiffness.shape[0]),
        "seconds": seconds,
    }


def cmd_fem(args: argparse.Namespace) -> dict:
    from analytical.kinematics import pose_geometry
    from fem_reference import solve_pose
    from .cache import ResultCache
    from .compare import fem_options, fem_runtime
    from .scene import load_scene

    scene = load_scene(args.scene)
    case = _case(scene, args)
    size = args.size * 1e-3 if args.size is not None else scene.fem.mesh_size
    count = args.modes or scene.analytical.modes
    options = fem_options(scene, size, platform=args.platform, coupling=args.coupling,
                          modes=count)
    geometry = pose_geometry(scene.manipulator, case.pose)
    start = time.perf_counter()
    result = solve_pose(scene.manipulator, geometry, options,
                        fem_runtime(scene, ResultCache(Path(".cache"))))
    seconds = time.perf_counter() - start
    if args.vtu:
        result.write_vtu(args.vtu)
    payload = {
        "case": case.name,
        "pose": _pose_payload(case.pose),
        "model": "fem",
        "platform": options.platform,
        "coupling": options.coupling,
        "frequencies_hz": [float(x) for x in result.frequencies_hz[:count]],
        "dofs": int(result.dofs),
        "mesh_size_m": float(result.mesh_size),
        "timings": {k: float(v) for k, v in result.timings.items()},
        "seconds": seconds,
    }
    if args.estimate_error:
        from .run import fem_refinement
        sizes = tuple(sorted(set(scene.fem_study.refinement) | {size}, reverse=True))
        study = fem_refinement(replace(scene, fem=replace(scene.fem, platform=options.platform,
                                                          coupling=options.coupling)),
                               case, geometry, ResultCache(Path(".cache")), sizes)
        k = study["sizes_m"].index(size)
        payload["estimated_error_percent"] = study["estimated_error_percent"][k]
        payload["extrapolated_hz"] = study["extrapolated_hz"]
        payload["observed_order"] = study["observed_order"]
    return payload


def _terminate(signum, frame):
    """SIGTERM (kill) unwinds like Ctrl-C, so staged outputs are removed on the way out."""
    raise KeyboardInterrupt


def _print_workspace(fmap: dict) -> None:
    print(f"{'z (mm)':>8} {'tilt_r (deg)':>12}  lowest f_k over the layer (Hz)")
    for z, r, layer in zip(fmap["heights_mm"], fmap["regular_tilt_deg"], fmap["frequencies_hz"]):
        values = [f for ring in layer for az in ring for f in [az] if az and az[0] is not None]
        lows = [min(v[k] for v in values) for k in range(len(values[0]))] if values else []
        print(f"{z:8.1f} {r:12.2f}  " + ", ".join(f"{f:.2f}" for f in lows))
    print(f"{fmap['seconds']:.2f} s, {fmap['settings']}")


def main(argv: list[str] | None = None) -> int:
    signal.signal(signal.SIGTERM, _terminate)
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        if args.command == "analytical":
            _emit(cmd_analytical(args), args.json)
        elif args.command == "fem":
            _emit(cmd_fem(args), args.json)
        elif args.command == "workspace":
            from .scene import load_scene
            from .studies import workspace_map
            start = time.perf_counter()
            fmap = workspace_map(load_scene(args.scene), args.layers, args.rings,
                                 args.azimuths, args.modes)
            fmap["seconds"] = time.perf_counter() - start
            if args.json:
                print(json.dumps(fmap))
            else:
                _print_workspace(fmap)
        elif args.command == "validate":
            from .run import validate
            validate(args.scene, Path(args.out), Path(args.cache), args.profile,
                     build_report=not args.no_report)
        elif args.command == "check-baselines":
            from .baselines import check_command
            return check_command(args.results)
        elif args.command == "readme":
            from reports.results import load_results
            from .tables import update_readme
            results = load_results(args.results)  # ValueError naming the file
            try:
                update_readme(Path("README.md"), results)
            except (KeyError, IndexError, TypeError) as exc:
                raise ValueError(f"{args.results}: unexpected content ({type(exc).__name__}: "
                                 f"{exc})") from None
        elif args.command == "scene-docs":
            from .scene_docs import write
            print(f"wrote {write()}")
        elif args.command == "update-baselines":
            from .baselines import update_command
            return update_command(args.scene)
    except (KeyboardInterrupt, ValueError, RuntimeError, OSError) as exc:
        return failed(exc)
    return 0
