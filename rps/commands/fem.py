"""`rps fem`: the solid FEM reference at one case or pose, its size from the scene, the run's
choice (--from-results) or --size, optionally with its estimated discretisation error."""
from __future__ import annotations

import argparse
import time
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from common.errors import InputError
from meshing.geometry import MeshSettings
from runtime.places import path_argument
from scene import FidelitySettings

from ..args import (
    cache_dir,
    cache_option,
    emit,
    fem_choices,
    load,
    named_first,
    pose_case,
    pose_payload,
    run_choice,
    scene_args,
)
from ..options import declared_option, typed
from .registry import Command

if TYPE_CHECKING:
    from results.outputs import FemAnswer


def fem_size(args: argparse.Namespace, scene) -> tuple[float, str]:
    """The element size (m) and where it comes from."""
    chosen = run_choice(args, scene)
    if args.size is not None:
        return args.size, "--size"
    if chosen is not None:
        return chosen["fem"]["mesh_size_mm"] * 1e-3, f"the run's choice ({args.from_results})"
    if scene.fem_size_given:
        return scene.fem.mesh_size, "the scene's mesh_size_mm"
    return scene.fem.mesh_size, ("the scene's default, 0.32 leg diameters, not the size a "
                                 "validated run chooses (that one: --from-results "
                                 "out/results.json)")


def check_vtu(path) -> None:
    """--vtu names a file (its .pvd beside it) in a folder the command can write into."""
    from runtime.places import check_writable_dir

    text = str(path)
    if path.is_dir():
        raise InputError(f"--vtu {text}: is a directory; give a file name (e.g. modes.vtu)")
    check_writable_dir(path.absolute().parent, "--vtu", typed=text)


def source_key(source: str) -> str:
    """The scene key behind a size that was not typed (named in a refusal)."""
    return "" if source.startswith(("--", "the run's")) else "fem.mesh_size_mm"


def cmd_fem(args: argparse.Namespace) -> FemAnswer:
    """The solid FEM at one pose: the --json answer, checked against its declaration
    (results.outputs.FEM_ANSWER)."""
    from fem_reference import solve_pose
    from fem_reference.convergence import sequence_around
    from fem_reference.model import FemError, check_mesh_size
    from meshing.bodies import pose_assembly
    from runtime.cache import ResultCache
    from solvers.compare import fem_options, fem_runtime

    scene = load(args)
    if args.vtu:  # written after the solve: where, before it
        check_vtu(args.vtu)
    case, geometry = pose_case(scene, args)
    size, source = fem_size(args, scene)
    count = args.modes or scene.analytical.modes
    options = fem_options(scene, size, platform=args.platform, coupling=args.coupling,
                          modes=count, legs=args.legs)
    cache = ResultCache(cache_dir(args))
    runtime = fem_runtime(scene, cache)
    sizes = sequence_around(size, scene.fem_study.refinement) if args.estimate_error else ()
    assembly = pose_assembly(scene.manipulator, geometry,
                             elastic_platform=options.platform == "elastic")
    what = typed(args, "size")
    for h in reversed(sorted(set(sizes) | {size})):  # every size of the study, finest first
        try:
            check_mesh_size(assembly, options.with_size(h), runtime)
        except FemError as exc:
            if h != size:  # a size of the study, not the one typed: say where it comes from
                tail = str(exc).split(": ", 1)[-1]
                raise InputError(
                    f"{what + ' ' if what else ''}--estimate-error: the refinement study's "
                    f"{h * 1e3:g} mm mesh (fem.refinement_mm = "
                    f"{[float(f'{r * 1e3:.6g}') for r in scene.fem_study.refinement]}, its "
                    f"ratios around the size): {tail}") from None
            raise named_first(exc, "mesh_size_mm", what or source_key(source)) from None
    start = time.perf_counter()
    try:
        result = solve_pose(scene.manipulator, geometry, options, runtime)
    except FemError as exc:
        raise named_first(exc, "mesh_size_mm", what) from None
    seconds = time.perf_counter() - start
    if args.vtu:
        result.write_vtu(args.vtu, pvd=True)
    payload: dict[str, Any] = {
        "case": case.name,
        "pose": pose_payload(case.pose),
        "warnings": list(scene.warnings),
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
        from solvers.refinement import fem_refinement
        study = fem_refinement(replace(scene, fem=replace(scene.fem, platform=options.platform,
                                                          coupling=options.coupling,
                                                          legs=options.legs)),
                               geometry, cache, sizes)
        k = min(range(len(sizes)), key=lambda i: abs(sizes[i] - size))
        payload["refinement_mm"] = [h * 1e3 for h in sizes]
        payload["estimated_error_percent"] = study["estimated_error_percent"][k]
        payload["extrapolated_hz"] = study["extrapolated_hz"]
        payload["observed_order"] = study["observed_order"]
    from results.outputs import FEM_ANSWER
    return FEM_ANSWER.checked(FEM_ANSWER.payload(payload))


def add_arguments(f: argparse.ArgumentParser) -> None:
    platforms, couplings, leg_models = fem_choices()
    scene_args(f)
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
    f.add_argument("--vtu", metavar="PATH", type=path_argument,
                   help="also write the mode shapes for ParaView: PATH (.vtu, legs and "
                        "platform) and a .pvd beside it (default: not written)")
    f.add_argument("--estimate-error", action="store_true",
                   help="also run a refinement study (cached) and report the estimated "
                        "discretisation error of this size: the scene's refinement_mm, with "
                        "the size inserted, or its ratios scaled to the size when the size "
                        "lies outside it")
    cache_option(f)


def run(args: argparse.Namespace) -> int:
    emit(cmd_fem(args), args.json)
    return 0


COMMAND = Command("fem", "3D solid FEM reference of one case", add_arguments, run)
