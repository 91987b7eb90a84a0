"""`rps design`: a design study from a design file (`scene.design_file`, `studies.design`):
the optimum, the Pareto front of moving mass against the least frequency over the workspace,
and the FEM at the optimum's worst pose. Resumable: every design solved is cached."""
from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING

from runtime.places import path_argument

from ..args import cache_dir, cache_option, warn
from .registry import Command

if TYPE_CHECKING:  # the study's modules only when it runs
    from studies.design import DesignStudy


def add_arguments(d: argparse.ArgumentParser) -> None:
    d.add_argument("--design", metavar="TOML", required=True,
                   help="design file: the scene, the variables and their bounds, the "
                   "constraints, the objective (designs/*.toml; required, no default)")
    d.add_argument("--out", metavar="FILE", type=path_argument, default=None,
                   help="also write the study as JSON to this file (default: print only)")
    d.add_argument("--report", metavar="DIR", type=path_argument, default=None,
                   help="write design.json, design.html and design.pdf (the front, the "
                   "optimum's frequency map) into this directory, replaced whole (default: "
                   "none)")
    cache_option(d)
    d.add_argument("--json", action="store_true", help="print one JSON object, exact values")


def _print(result: DesignStudy) -> None:
    print(f"{result['name']}: {result['designs_solved']} designs solved, "
          f"{result['feasible']} meet every constraint ({result['model']})")
    best = result["optimum"]
    if best is None:
        print("no design meets the constraints within the bounds")
        return
    names = [v["name"] for v in result["variables"]]
    values = ", ".join(f"{n} = {x:.4g}" for n, x in zip(names, best["values"]))
    p = best["worst_pose"]
    mode = result["constraints"]["mode"]
    print(f"optimum: {values}\n  moving mass {best['moving_mass_kg']:.3f} kg, least f{mode} "
          f"over the workspace {best['min_frequency_hz']:.3f} Hz at z = {p['height_mm']:.1f} "
          f"mm, azimuth {p['azimuth_deg']:.1f} deg, tilt {p['tilt_deg']:.2f} deg")
    if "min_critical_depth_mm" in best:
        depth, w = best["min_critical_depth_mm"], best.get("stability_worst")
        print("  the cut is stable at every pose and speed of the coarse stability map"
              if depth is None or w is None else
              f"  least critical depth {depth:.3f} mm at {w['spindle_rpm']:.0f} rpm "
              f"({w['kind']}), z = {w['height_mm']:.1f} mm, azimuth {w['azimuth_deg']:.1f} "
              f"deg, tilt {w['tilt_deg']:.2f} deg")
    check = result["fem_check"]
    if check and check["error"]:
        print(f"  {check['error']}")
    elif check:
        print(f"  FEM there ({check['mesh_size_mm']:.1f} mm, stated error "
              f"{check['fem_estimated_error_percent']:.3g} %): {check['fem_hz']:.3f} Hz, the "
              f"model's error {check['error_percent']:+.3f} % ("
              + ("within" if check["within_tolerance"] else "NOT within")
              + f" the scene's {check['tolerance_percent']:g} %)"
              + (f"; paired by shape with the model's mode {check['paired_analytical_mode']}, "
                 f"by order {check['by_order_error_percent']:+.3f} %"
                 if check["paired_analytical_mode"] != mode else ""))
    print("Pareto front (moving mass kg, least f Hz): " + ", ".join(
        f"({r['moving_mass_kg']:.2f}, {r['min_frequency_hz']:.2f})" for r in result["front"]))


def check_output_file(path: Path) -> None:
    """--out must name a file in an existing directory (checked before the study runs)."""
    from runtime.outdir import OutputError

    if path.is_dir():
        raise OutputError(f"--out {path}: is a directory; give a file name (e.g. design.json)")
    if not path.absolute().parent.is_dir():
        raise OutputError(f"--out {path}: its directory {path.absolute().parent} does not "
                          "exist")
    from runtime.places import PlaceError, check_writable_dir
    try:
        check_writable_dir(path.absolute().parent, "--out", typed=str(path))
    except PlaceError as exc:
        raise OutputError(str(exc)) from None


def run(args: argparse.Namespace) -> int:
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from runtime.cache import ResultCache
    from runtime.outdir import check_output_dir
    from scene.design_file import load_design
    from studies.design import DESIGN, run_design

    spec = load_design(args.design)  # every check before the first design is solved
    if args.report is not None:  # where the study goes, before it starts (it takes minutes)
        check_output_dir(args.report, "--report")
    if args.out is not None:
        check_output_file(args.out)
    cache = ResultCache(cache_dir(args))
    with Progress(TextColumn("designs"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                  TimeElapsedColumn(), transient=True, disable=args.json) as progress:
        task = progress.add_task("designs", total=spec.search.designs)
        result = run_design(spec, cache, lambda done, total: progress.update(task,
                                                                            completed=done))
    output = DESIGN.checked(DESIGN.payload({**result,
                                            "warnings": design_warnings(spec, result)}))
    if args.out is not None:
        DESIGN.write_to(args.out, output)
    if args.report is not None:
        from reports.design_report import render_design_report
        from runtime.outdir import staged_output

        with staged_output(args.report) as stage:
            render_design_report(output, stage)
    if args.json:
        print(json.dumps(output))
    else:
        _print(output)
    warn(output["warnings"])
    return 0


def design_warnings(spec, result: DesignStudy) -> list[str]:
    """The plausibility warnings of the design file's scene and of the optimum's."""
    from scene import parse_scene
    from scene.design_file import design_scene

    found = list(parse_scene(spec.raw_scene, spec.scene_path).warnings)
    if result["optimum"] is not None:
        found += [w for w in design_scene(spec, result["optimum"]["values"]).warnings
                  if w not in found]
    return found


COMMAND = Command("design", "optimise named scene values: least frequency over the workspace "
                  "against moving mass", add_arguments, run)
