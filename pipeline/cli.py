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
import re
import signal
import sys
import textwrap
import time
from dataclasses import replace
from pathlib import Path

from analytical.beam import SHEAR_COEFFICIENTS
from analytical.params import BEAM_THEORIES, JOINT_ENDS, PLATFORM_INERTIAS, ModelOptions
from common.locations import DISTRIBUTION, cache_root, checkout_root, default_scene
from common.messages import failed
from meshing.geometry import MeshSettings

from . import human
from .fidelity import FidelitySettings
from .options import MAX_MAP_POSES, MapGrid, Workers, declared_option, typed

EXIT_BAD_INPUT = 2


def _scene_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--scene", metavar="TOML", default=str(default_scene()),
                   help="scene file: manipulator, poses, fidelity")


def _scene_args(p: argparse.ArgumentParser) -> None:
    _scene_option(p)
    p.add_argument("--case", metavar="NAME",
                   help="case of the scene (default: the scene's first case)")
    from scene import CaseSettings
    declared_option(p, "--height", CaseSettings, "height", metavar="MM",
                    help="platform height z, mm (default: the case's)")
    declared_option(p, "--azimuth", CaseSettings, "azimuth", metavar="DEG",
                    help="tilt azimuth phi, degrees (default: the case's)")
    declared_option(p, "--tilt", CaseSettings, "tilt", metavar="DEG",
                    help="tilt theta, degrees (default: the case's)")
    p.add_argument("--from-results", metavar="JSON", type=Path,
                   help="use the model the validated run chose for this scene, read from "
                   "the fidelity block of its results.json (e.g. out/results.json, written "
                   "by `make`); options given beside it still override (default: the scene's "
                   "own settings)")
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
        what = typed(args, "height", "azimuth", "tilt") or (
            f"case {case.name} of {args.scene} (height_mm = {pose.height * 1e3:g}, "
            f"azimuth_deg = {math.degrees(pose.azimuth):g}, tilt_deg = "
            f"{math.degrees(pose.tilt):g})")
        raise ValueError(f"{what}: {exc}") from None
    return replace(case, pose=pose), geometry


def _named_first(exc: Exception, key: str, what: str) -> Exception:
    """`key = value: why` as `what: why` when the user typed `what` (e.g. --size 0.5 mm)."""
    text = str(exc)
    found = re.match(rf"{re.escape(key)} = [^:]*: ", text)
    if what and found:
        return ValueError(f"{what}: {text[found.end():]}")
    return exc


def _chosen(args: argparse.Namespace, scene) -> dict | None:
    """The fidelity block of --from-results, checked to be a run of this scene file."""
    if args.from_results is None:
        return None
    import hashlib
    from results import read

    where = f"--from-results {args.from_results}"
    try:
        results = read(args.from_results)
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None
    digest = hashlib.sha256(Path(args.scene).read_bytes()).hexdigest()
    if results["scene"]["sha256"] != digest:
        raise ValueError(f"{where}: a run of scene {results['scene']['path']} "
                         f"({results['scene']['name']!r}), not of --scene {args.scene} as it "
                         "is now; run `rps validate --scene` on it first")
    return results["fidelity"]


def _pose_payload(pose) -> dict:
    return {"height_mm": round(pose.height * 1e3, 9),
            "azimuth_deg": round(math.degrees(pose.azimuth), 9),
            "tilt_deg": round(math.degrees(pose.tilt), 9)}


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage error is one line on stderr and exit status 2; a refused value
    is named first, as typed (`error: --tilt 100 deg: must be ...`)."""

    def error(self, message: str):  # noqa: D401 - argparse hook
        where = "" if message.startswith("--") else f"{self.prog}: "
        self.exit(EXIT_BAD_INPUT, f"error: {where}{message}\n")


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
    declared_option(a, "--elements", ModelOptions, "elements", metavar="N",
                    help="beam elements per leg s (default: the scene's)")
    a.add_argument("--beam", choices=BEAM_THEORIES, help="beam theory (default: the scene's)")
    a.add_argument("--shear", choices=SHEAR_COEFFICIENTS,
                   help="Timoshenko shear coefficient (default: the scene's)")
    a.add_argument("--joint-ends", choices=JOINT_ENDS,
                   help="leg ends: beam elements to the joint centre, or condensed solid end "
                   "zones (default: the scene's)")
    declared_option(a, "--end-zone", ModelOptions, "end_zone", metavar="D",
                    help="length of each solid end zone, in leg diameters (default: the "
                    "scene's)")
    a.add_argument("--platform-inertia", choices=PLATFORM_INERTIAS,
                   help="platform inertia: the plate's own, or Eq. (8)'s m r2^2 "
                        "(default: the scene's)")
    declared_option(a, "--modes", FidelitySettings, "modes", metavar="N",
                    help="number of modes (default: the scene's)")

    platforms, couplings, leg_models = _fem_choices()
    f = command("fem", "3D solid FEM reference of one case")
    _scene_args(f)
    declared_option(f, "--size", MeshSettings, "size", metavar="MM",
                    help="global element size, mm (default: the scene's mesh_size_mm, or "
                    "0.32 leg diameters when the scene leaves the size to the run; the size "
                    "the run chose: --from-results)")
    f.add_argument("--platform", choices=platforms,
                   help="rigid platform or elastic plate (default: the scene's)")
    f.add_argument("--coupling", choices=couplings,
                   help="joint-face coupling (default: the scene's)")
    f.add_argument("--legs", choices=leg_models,
                   help="legs by Fourier harmonics on a meridian mesh, or 3D tetrahedra "
                   "(default: the scene's; an elastic plate takes tetrahedra)")
    declared_option(f, "--modes", FidelitySettings, "modes", metavar="N",
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
    declared_option(w, "--layers", MapGrid, "layers", default=8, metavar="N",
                    help="height layers")
    declared_option(w, "--rings", MapGrid, "rings", default=6, metavar="N",
                    help="tilt rings per layer")
    declared_option(w, "--azimuths", MapGrid, "azimuths", default=36, metavar="N",
                    help="azimuths per ring")
    declared_option(w, "--modes", FidelitySettings, "modes", default=3, metavar="N",
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
    declared_option(v, "--workers", Workers, "workers", default=None, metavar="N",
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


CHOSEN_ANALYTICAL = ("beam", "shear", "joint_ends", "elements", "platform_inertia")


def cmd_analytical(args: argparse.Namespace) -> dict:
    from analytical.model import analyse
    from analytical.modal import ModalError
    from scene import load_scene

    scene = load_scene(args.scene)
    case, _ = _case(scene, args)
    opts = scene.analytical
    chosen = _chosen(args, scene)
    if chosen is not None:
        opts = replace(opts, **{k: chosen["analytical"][k] for k in CHOSEN_ANALYTICAL})
        source = f"the run's choice, {chosen['analytical']['setting']} ({args.from_results})"
    else:
        source = ("the scene's [analytical]" if scene.analytical_given else
                  "the scene's defaults, not the model a validated run chooses (that one: "
                  "--from-results out/results.json)")
    overrides = {k: getattr(args, k) for k in ("elements", "beam", "shear", "joint_ends",
                                               "end_zone", "platform_inertia", "modes")
                 if getattr(args, k) is not None}
    opts = replace(opts, **overrides)
    start = time.perf_counter()
    try:
        result = analyse(scene.manipulator, case.pose, opts)
    except ModalError as exc:
        raise _named_first(exc, "modes", typed(args, "modes")) from None
    except ValueError as exc:  # e.g. end zones longer than the legs: name what was typed
        what = typed(args, "end_zone", "elements") if "end_zone" in str(exc) else ""
        raise ValueError(f"{what}: {exc}" if what else str(exc)) from None
    seconds = time.perf_counter() - start
    return {
        "case": case.name,
        "pose": _pose_payload(case.pose),
        "model": "analytical",
        "settings_from": source + (" with options" if overrides else ""),
        "elements": opts.elements,
        "beam": opts.beam,
        "shear": opts.shear,
        "joint_ends": opts.joint_ends,
        "platform_inertia": opts.platform_inertia,
        **({"end_zone_diameters": opts.end_zone} if opts.joint_ends == "solid" else {}),
        "frequencies_hz": [float(x) for x in result.frequencies_hz],
        "leg_lengths_mm": [float(x) * 1e3 for x in result.geometry.leg_lengths],
        "dofs": int(result.model.stiffness.shape[0]),
        "seconds": seconds,
    }


def _fem_size(args: argparse.Namespace, scene) -> tuple[float, str]:
    """The element size (m) and where it comes from."""
    chosen = _chosen(args, scene)
    if args.size is not None:
        return args.size, "--size"
    if chosen is not None:
        return chosen["fem"]["mesh_size_mm"] * 1e-3, f"the run's choice ({args.from_results})"
    if scene.fem_size_given:
        return scene.fem.mesh_size, "the scene's mesh_size_mm"
    return scene.fem.mesh_size, ("the scene's default, 0.32 leg diameters, not the size a "
                                 "validated run chooses (that one: --from-results "
                                 "out/results.json)")


def cmd_fem(args: argparse.Namespace) -> dict:
    from fem_reference import solve_pose
    from fem_reference.convergence import sequence_around
    from fem_reference.model import FemError, check_mesh_size
    from meshing.bodies import pose_assembly
    from runtime.cache import ResultCache
    from .compare import fem_options, fem_runtime
    from scene import load_scene

    scene = load_scene(args.scene)
    case, geometry = _case(scene, args)
    size, source = _fem_size(args, scene)
    count = args.modes or scene.analytical.modes
    options = fem_options(scene, size, platform=args.platform, coupling=args.coupling,
                          modes=count, legs=args.legs)
    cache = ResultCache(_cache_dir(args))
    runtime = fem_runtime(scene, cache)
    sizes = sequence_around(size, scene.fem_study.refinement) if args.estimate_error else ()
    assembly = pose_assembly(scene.manipulator, geometry,
                             elastic_platform=options.platform == "elastic")
    what = typed(args, "size")
    try:  # every size of the study checked up front, the finest first
        for h in reversed(sorted(set(sizes) | {size})):
            check_mesh_size(assembly, options.with_size(h), runtime)
    except FemError as exc:
        if sizes:  # a size of the study, not necessarily the one typed
            raise ValueError(f"{what + ' ' if what else ''}--estimate-error: {exc}") from None
        raise _named_first(exc, "mesh_size_mm", what) from None
    start = time.perf_counter()
    try:
        result = solve_pose(scene.manipulator, geometry, options, runtime)
    except FemError as exc:
        raise _named_first(exc, "mesh_size_mm", what) from None
    seconds = time.perf_counter() - start
    if args.vtu:
        result.write_vtu(args.vtu, pvd=True)
    payload = {
        "case": case.name,
        "pose": _pose_payload(case.pose),
        "model": "fem",
        "mesh_size_from": source,
        "platform": options.platform,
        "coupling": options.coupling,
        "legs": options.legs,
        "frequencies_hz": [float(x) for x in result.frequencies_hz[:count]],
        "dofs": int(result.dofs),
        "mesh_size_mm": float(result.mesh_size) * 1e3,
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


def cmd_workspace(args: argparse.Namespace) -> dict:
    """The frequency map; the grid and the mode count checked against what the model holds
    before any pose is solved."""
    from analytical.end_zones import segments
    from scene import load_scene
    from .studies import workspace_map

    scene = load_scene(args.scene)
    poses = args.layers * args.rings * args.azimuths
    if poses > MAX_MAP_POSES:
        raise ValueError(f"{typed(args, 'layers', 'rings', 'azimuths') or 'the grid'}: "
                         f"{poses:,} poses, above the {MAX_MAP_POSES:,} of one map (about a "
                         "minute); use a coarser grid")
    followed = 18 * segments(scene.analytical) - 1  # analytical.workspace's window
    if args.modes > followed:
        raise ValueError(f"{typed(args, 'modes') or f'modes = {args.modes}'}: the map follows "
                         f"at most {followed} modes with this scene's model "
                         f"(s = {scene.analytical.elements} elements per leg)")
    start = time.perf_counter()
    fmap = workspace_map(scene, args.layers, args.rings, args.azimuths, args.modes)
    fmap["seconds"] = time.perf_counter() - start
    return fmap


def cmd_cache(args: argparse.Namespace) -> int:
    from runtime.cache import cache_info, clear

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
            fmap = cmd_workspace(args)
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
            from results import read
            readme = _checkout(args.command) / "README.md"
            update_readme(readme, read(args.results))
        elif args.command == "scene-docs":
            _checkout(args.command)
            from scene.docs import write
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
