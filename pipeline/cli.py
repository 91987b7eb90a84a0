"""Command line: `rps` (or `python -m pipeline`) with the subcommands analytical, fem,
workspace, validate, cache, and the developer commands check-baselines, update-baselines,
readme, scene-docs. Lengths in mm and angles in degrees at this edge; SI inside.

Every expected failure (bad scene value, unreachable pose, solver failure) prints one line on
stderr naming the offending value and exits with status 2, without a traceback.
"""
from __future__ import annotations

import argparse
import json
import math
import signal
import sys
import textwrap
import time
from dataclasses import replace
from pathlib import Path

from analytical.params import BEAM_THEORIES, PLATFORM_INERTIAS
from common.locations import DISTRIBUTION, cache_root, checkout_root, default_scene
from common.messages import failed

from . import human

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


def _scene_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--scene", metavar="TOML", default=str(default_scene()),
                   help="scene file: manipulator, poses, fidelity")


def _scene_args(p: argparse.ArgumentParser) -> None:
    _scene_option(p)
    p.add_argument("--case", metavar="NAME",
                   help="case of the scene (default: the scene's first case)")
    p.add_argument("--height", type=_finite, metavar="MM",
                   help="platform height z, mm (default: the case's)")
    p.add_argument("--azimuth", type=_finite, metavar="DEG",
                   help="tilt azimuth phi, degrees (default: the case's)")
    p.add_argument("--tilt", type=_finite, metavar="DEG",
                   help="tilt theta, degrees (default: the case's)")
    p.add_argument("--json", action="store_true", help="print one JSON object, exact values")


def _cache_option(p: argparse.ArgumentParser) -> None:
    try:
        where = str(cache_root())
    except RuntimeError:  # without the [fem] extra there is nothing to cache
        where = "the user cache directory"
    p.add_argument("--cache", metavar="DIR", type=Path,
                   help=f"result and mesh cache (default: {where}; the checkout's .cache/ "
                        "when run from the repository)")


def _cache_dir(args: argparse.Namespace) -> Path:
    return args.cache if args.cache is not None else cache_root()


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


class _Help(argparse.RawDescriptionHelpFormatter):
    """Help with every option's default beside its text (units are in the text and the
    metavars: MM, DEG); an option without a fixed default says what it defaults to."""

    def __init__(self, prog):
        super().__init__(prog, max_help_position=30, width=100)

    def _split_lines(self, text, width):
        return textwrap.wrap(" ".join(text.split()), width, break_on_hyphens=False)

    def _get_help_string(self, action):
        text = action.help or ""
        if ("default" in text or not action.option_strings or action.default is None
                or action.default is False or action.default is argparse.SUPPRESS):
            return text
        return f"{text} (default: %(default)s)"


class _Version(argparse.Action):
    """--version: the project's version and commit, worked out only when asked."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, **kwargs):
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        from .version import describe
        print(describe())
        parser.exit(0)


def _fem_choices() -> tuple[tuple[str, ...] | None, ...]:
    """The FEM's platform, coupling and leg-discretisation options; Nones without the [fem]
    extra (then the fem command says which extra to install)."""
    try:
        from fem_reference.constraints import COUPLINGS
        from fem_reference.model import LEG_MODELS, PLATFORMS
    except ImportError:
        return None, None, None
    return PLATFORMS, COUPLINGS, LEG_MODELS


def build_parser(prog: str = "rps") -> argparse.ArgumentParser:
    parser = _Parser(prog=prog, description=__doc__, formatter_class=_Help)
    parser.add_argument("--version", action=_Version,
                        help="print the project's version and git commit, and exit")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser,
                                metavar="COMMAND", title="commands")

    def command(name: str, text: str) -> argparse.ArgumentParser:
        return sub.add_parser(name, help=text, description=text, formatter_class=_Help)

    a = command("analytical", "substructure model of one case (Gong & Lou's Eqs. 1-25)")
    _scene_args(a)
    a.add_argument("--elements", type=_positive_int, metavar="N",
                   help="beam elements per leg s (default: the scene's)")
    a.add_argument("--beam", choices=BEAM_THEORIES, help="beam theory (default: the scene's)")
    a.add_argument("--platform-inertia", choices=PLATFORM_INERTIAS,
                   help="platform inertia: the plate's own, or Eq. (8)'s m r2^2 "
                        "(default: the scene's)")
    a.add_argument("--modes", type=_positive_int, metavar="N",
                   help="number of modes (default: the scene's)")

    platforms, couplings, leg_models = _fem_choices()
    f = command("fem", "3D solid FEM reference of one case")
    _scene_args(f)
    f.add_argument("--size", type=_positive_mm, metavar="MM",
                   help="global element size, mm (default: the scene's mesh_size_mm)")
    f.add_argument("--platform", choices=platforms,
                   help="rigid platform or elastic plate (default: the scene's)")
    f.add_argument("--coupling", choices=couplings,
                   help="joint-face coupling (default: the scene's)")
    f.add_argument("--legs", choices=leg_models,
                   help="legs by Fourier harmonics on a meridian mesh, or 3D tetrahedra "
                   "(default: the scene's; an elastic plate takes tetrahedra)")
    f.add_argument("--modes", type=_positive_int, metavar="N",
                   help="number of modes (default: the scene's)")
    f.add_argument("--vtu", metavar="PATH",
                   help="also write the mode shapes for ParaView: PATH (.vtu, legs and "
                        "platform) and a .pvd beside it (default: not written)")
    f.add_argument("--estimate-error", action="store_true",
                   help="also run a refinement study (cached) and report the estimated "
                        "discretisation error of this size: the scene's refinement_mm, with "
                        "the size inserted, or its ratios scaled to the size when the size "
                        "lies outside it")
    _cache_option(f)

    w = command("workspace", "f1..fN over the regular workspace (Fig. 6)")
    _scene_option(w)
    w.add_argument("--layers", type=_positive_int, default=8, metavar="N",
                   help="height layers")
    w.add_argument("--rings", type=_positive_int, default=6, metavar="N",
                   help="tilt rings per layer")
    w.add_argument("--azimuths", type=_positive_int, default=36, metavar="N",
                   help="azimuths per ring")
    w.add_argument("--modes", type=_positive_int, default=3, metavar="N",
                   help="modes per pose")
    w.add_argument("--json", action="store_true", help="print one JSON object, exact values")

    v = command("validate", "run the whole validation of a scene: results, tables, report")
    _scene_option(v)
    v.add_argument("--out", metavar="DIR", type=Path, default=Path("out"),
                   help="output directory: results.json, tables/, modes/, report.html/.pdf")
    _cache_option(v)
    v.add_argument("--profile", choices=("full", "ci"), default="full",
                   help="full: every case and study; ci: the scene's ci_cases only, no "
                        "refinement study or variants")
    v.add_argument("--no-report", action="store_true", help="skip the HTML/PDF report")
    v.add_argument("--workers", type=_positive_int, default=None,
                   help="local worker processes of the workspace sweep (default: the number "
                        "of cores)")
    v.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="send the sweep's poses to this running dask.distributed scheduler "
                        "(e.g. tcp://10.0.0.5:8786) instead of local workers (default: none)")

    k = command("cache", "where the caches are and how big; clear them")
    k.add_argument("action", choices=("info", "clear"),
                   help="info: directory, entries and size; clear: delete every entry")
    _cache_option(k)
    k.add_argument("--json", action="store_true", help="print one JSON object (info)")

    c = command("check-baselines", "recompute the CI error tables and compare them with "
                "tests/baselines (checkout only)")
    c.add_argument("--results", metavar="PATH", help="read the tables from this results.json "
                   "(computed at the baselines' mesh size) instead of recomputing them "
                   "(default: none)")

    r = command("readme", "refresh README.md's results block from results.json (checkout "
                "only)")
    r.add_argument("--results", metavar="PATH", type=Path, default=Path("out/results.json"),
                   help="results file of a full run")

    command("scene-docs", "rewrite docs/scenes.md from the scene declarations (checkout only)")

    u = command("update-baselines", "rewrite tests/baselines from a fresh CI run (checkout "
                "only)")
    _scene_option(u)
    return parser


def _emit(payload: dict, as_json: bool) -> None:
    if as_json:
        print(json.dumps(payload, indent=None))
        return
    print("\n".join(human.payload_lines(payload)))


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
    from fem_reference.convergence import sequence_around
    from fem_reference.model import check_mesh_size
    from meshing.bodies import pose_assembly
    from .cache import ResultCache
    from .compare import fem_options, fem_runtime
    from .scene import load_scene

    scene = load_scene(args.scene)
    case = _case(scene, args)
    size = args.size * 1e-3 if args.size is not None else scene.fem.mesh_size
    count = args.modes or scene.analytical.modes
    options = fem_options(scene, size, platform=args.platform, coupling=args.coupling,
                          modes=count, legs=args.legs)
    geometry = pose_geometry(scene.manipulator, case.pose)
    cache = ResultCache(_cache_dir(args))
    runtime = fem_runtime(scene, cache)
    sizes = sequence_around(size, scene.fem_study.refinement) if args.estimate_error else ()
    assembly = pose_assembly(scene.manipulator, geometry,
                             elastic_platform=options.platform == "elastic")
    for h in reversed(sizes):  # every size of the study checked up front, the finest first
        check_mesh_size(assembly, options.with_size(h), runtime)
    start = time.perf_counter()
    result = solve_pose(scene.manipulator, geometry, options, runtime)
    seconds = time.perf_counter() - start
    if args.vtu:
        result.write_vtu(args.vtu, pvd=True)
    payload = {
        "case": case.name,
        "pose": _pose_payload(case.pose),
        "model": "fem",
        "platform": options.platform,
        "coupling": options.coupling,
        "legs": options.legs,
        "frequencies_hz": [float(x) for x in result.frequencies_hz[:count]],
        "dofs": int(result.dofs),
        "mesh_size_m": float(result.mesh_size),
        "min_scaled_jacobian": float(result.min_quality),
        "timings": {k: float(v) for k, v in result.timings.items()},
        "seconds": seconds,
    }
    if sizes:
        from .run import fem_refinement
        study = fem_refinement(replace(scene, fem=replace(scene.fem, platform=options.platform,
                                                          coupling=options.coupling,
                                                          legs=options.legs)),
                               geometry, cache, sizes)
        k = min(range(len(sizes)), key=lambda i: abs(sizes[i] - size))
        payload["refinement_mm"] = [h * 1e3 for h in sizes]
        payload["estimated_error_percent"] = study["estimated_error_percent"][k]
        payload["extrapolated_hz"] = study["extrapolated_hz"]
        payload["observed_order"] = study["observed_order"]
    return payload


def cmd_cache(args: argparse.Namespace) -> int:
    from .cache import cache_info, clear

    directory = _cache_dir(args)
    if args.action == "clear":
        removed = clear(directory)
        print(f"cleared {directory}: {removed['entries']} entries, "
              f"{removed['bytes'] / 1e6:.1f} MB")
        return 0
    info = cache_info(directory)
    if args.json:
        print(json.dumps(info))
        return 0
    print(f"cache: {info['directory']}" + ("" if info["exists"] else " (empty, not created)"))
    for kind, part in info["kinds"].items():
        print(f"  {kind:<10} {part['entries']:>6} entries  {part['bytes'] / 1e6:9.1f} MB")
    print(f"  {'total':<10} {info['entries']:>6} entries  {info['bytes'] / 1e6:9.1f} MB")
    return 0


def _checkout(command: str) -> Path:
    """The repository checkout, which the developer commands write into."""
    root = checkout_root()
    if root is None:
        raise ValueError(f"{command}: writes into the repository checkout; run it from a "
                         f"clone of {DISTRIBUTION} (pip install -e .)")
    return root


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
    prog = "rps" if Path(sys.argv[0]).name == "rps" else "python -m pipeline"
    parser = build_parser(prog)
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
            results = validate(args.scene, args.out, _cache_dir(args), args.profile,
                               build_report=not args.no_report, workers=args.workers,
                               scheduler=args.scheduler)
            print(human.summary(results, args.out, report=not args.no_report))
        elif args.command == "cache":
            return cmd_cache(args)
        elif args.command == "check-baselines":
            _checkout(args.command)
            from .baselines import check_command
            return check_command(args.results)
        elif args.command == "readme":
            from reports.readme import update_readme
            from .results import read
            readme = _checkout(args.command) / "README.md"
            update_readme(readme, read(args.results))
        elif args.command == "scene-docs":
            _checkout(args.command)
            from .scene_docs import write
            print(f"wrote {write()}")
        elif args.command == "update-baselines":
            _checkout(args.command)
            from .baselines import update_command
            return update_command(args.scene)
    except ModuleNotFoundError as exc:
        extras = "fem,report" if args.command == "validate" else "fem"
        print(f"error: {exc.name} is not installed; `{prog} {args.command}` needs "
              f"pip install '{DISTRIBUTION}[{extras}]'", file=sys.stderr)
        return EXIT_BAD_INPUT
    except (KeyboardInterrupt, ValueError, RuntimeError, OSError) as exc:
        return failed(exc)
    return 0
