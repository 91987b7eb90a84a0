"""`rps lobes`: milling stability lobes of one pose (chatter.lobes), from the scene's model at a
case (`--scene S --case C`, its [cutting] table) or from a tool-modes file and a cutting file
(`--tool-modes F --cutting F`). Writes DIR/lobes.json (declared: results.outputs.LOBES),
DIR/lobes.csv (one row a speed) and DIR/lobes.png, the directory replaced whole. Every input
is checked, and the semi-discretization's time estimated, before the first solve."""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from common.errors import InputError
from runtime.places import path_argument

from ..args import cache_option, load, pose_case, pose_payload, scene_args, warn
from .registry import Command

SAY_ABOVE = 2.0  # s: a longer estimate is said on stderr before the solve


def add_arguments(p: argparse.ArgumentParser) -> None:
    scene_args(p)
    p.add_argument("--model", choices=("analytical", "fem"), default="analytical",
                   help="with --scene: the model whose tool modes cut (default: analytical)")
    p.add_argument("--tool-modes", metavar="FILE", type=path_argument,
                   help="the tool's modes instead of a scene: rps frf's frf.json, a TOML or "
                   "JSON file with modes = [{frequency_hz, damping_ratio, "
                   "tool_shape_per_sqrt_kg = {x, y}}] in the cut's plane (x along the feed), "
                   "or a tap test's FRFs at the tool (UFF 58, .unv or .uff: its modes "
                   "extracted as rps identify does and scaled from the driving points; its x, "
                   "y, z the platform's, z along the tool); default: none, the scene's model "
                   "at the case")
    p.add_argument("--tool-node", metavar="N", type=int,
                   help="with a UFF --tool-modes: the tool's node (default: the one node with "
                   "a driving-point FRF)")
    p.add_argument("--cutting", metavar="FILE", type=path_argument,
                   help="with --tool-modes: a TOML file holding a [cutting] table (default: none; "
                   "with a scene, its own [cutting])")
    p.add_argument("--method", choices=("sdm", "zoa"),
                   help="override the [cutting] table's method (default: the table's, itself "
                   "'sdm' unless it says)")
    p.add_argument("--out", metavar="DIR", type=path_argument, required=True,
                   help="directory of lobes.json, lobes.csv and lobes.png, replaced whole "
                   "(required, no default)")
    cache_option(p)


def _read_any(path: Path, what: str) -> object:
    """A JSON or TOML file's content; InputError in one line."""
    from scene.toml_table import read_toml

    if path.suffix.lower() == ".json":
        try:
            return json.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise InputError(f"{what} {str(path)!r} does not exist") from None
        except OSError as exc:
            raise InputError(f"{what} {path}: cannot be read ({exc.strerror})") from None
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise InputError(f"{what} {path}: not JSON ({' '.join(str(exc).split())})"
                             ) from None
    return read_toml(path, what)


def read_cutting(path: Path):
    """The [cutting] table of a TOML file, read through its declaration."""
    from chatter.cutting import Cutting
    from scene.toml_table import Table

    raw = _read_any(path, "--cutting")
    if not isinstance(raw, dict) or "cutting" not in raw:
        raise InputError(f"--cutting {path}: no [cutting] table")
    top = Table(raw, str(path))
    table = top.table("cutting")
    value = table.settings(Cutting)
    table.done()
    top.done()
    return value


UFF_SUFFIXES = (".unv", ".uff")


def tap_test(args: argparse.Namespace, feed_direction: float):
    """(tool modes in the cut's plane, what they are in words, warnings) from a UFF file of
    FRFs at the tool (modaltest.tool_modes); InputError in one line."""
    import numpy as np

    from chatter.tool_input import from_base
    from modaltest.tool_modes import tap_modes
    from modaltest.uff import UffError, read_uff

    shown = f"--tool-modes {args.tool_modes}"
    try:
        content = read_uff(args.tool_modes, shown)
    except UffError as exc:
        raise InputError(str(exc)) from None
    if content.frfs is None:
        raise InputError(f"{shown}: no FRF (dataset 58) in the file: a tap test at the tool "
                         "gives its receptances")
    found = tap_modes(content.frfs, shown, args.tool_node)
    modes = from_base(2 * np.pi * found.frequency_hz, found.damping_ratio, found.shape,
                      np.eye(3), feed_direction)
    said = (f"node {found.node}, {len(found.frequency_hz)} modes by LSCF and LSFD, scaled "
            "from the driving points")
    return modes, said, [f"tap test: mode {m} left out" for m in found.dropped]


def _with_method(cutting, method: str | None):
    from dataclasses import replace
    return cutting if method is None else replace(cutting, method=method)


def run(args: argparse.Namespace) -> int:
    import time

    from chatter.lobes import lobes, plan
    from chatter.tool_input import from_base, read_modes
    from results.outputs import LOBES
    from runtime.outdir import check_output_dir, staged_output

    check_output_dir(args.out, "--out")
    start = time.perf_counter()
    head: dict = {}
    warnings: list[str] = []
    if args.tool_modes is not None:
        if args.cutting is None:
            raise InputError("--tool-modes without --cutting: give the cut's [cutting] table "
                             "in a TOML file")
        if args.case or args.height is not None or args.tilt is not None \
                or args.azimuth is not None or args.from_results:
            raise InputError("--tool-modes with a case or pose option: the tool-modes file "
                             "is the pose's modes; leave --case, --height, --azimuth, --tilt "
                             "and --from-results out")
        cutting = _with_method(read_cutting(args.cutting), args.method)
        name = Path(args.tool_modes).name
        if Path(args.tool_modes).suffix.lower() in UFF_SUFFIXES:
            modes, said, warnings = tap_test(args, cutting.feed_direction)
            head = {"source": f"tap test {name} ({said})"}
        else:
            if args.tool_node is not None:
                raise InputError(f"--tool-node with --tool-modes {name}: a node names the "
                                 "tool in a UFF file of FRFs (.unv, .uff)")
            modes = read_modes(_read_any(args.tool_modes, "--tool-modes"),
                               str(args.tool_modes), cutting.feed_direction)
            head = {"source": f"tool-modes file {name}"}
        plan_ = plan(modes, cutting)
    else:
        if args.cutting is not None:
            raise InputError("--cutting with a scene: the scene's own [cutting] table is used "
                             "(--cutting goes with --tool-modes)")
        if args.tool_node is not None:
            raise InputError("--tool-node with a scene: the scene's [tool] point is used "
                             "(--tool-node goes with a UFF --tool-modes)")
        scene = load(args)
        if scene.cutting is None:
            raise InputError(f"--scene {args.scene}: no [cutting] table (docs/scenes.md "
                             "[cutting]); or give --tool-modes and --cutting")
        cutting = _with_method(scene.cutting, args.method)
        case, geometry = pose_case(scene, args)
        from .frf import tool_model

        tool, settings = tool_model(args, scene, geometry, scene.fidelity.modes)
        modes = from_base(tool.modes.omega, tool.zeta, tool.modes.phi, geometry.rotation,
                          cutting.feed_direction)
        head = {"source": f"scene {scene.name}, case {case.name}", "scene": scene.name,
                "case": case.name, "pose": pose_payload(case.pose), "model": tool.label}
        warnings = list(scene.warnings)
        plan_ = plan(modes, cutting)
        del settings
    if plan_.seconds > SAY_ABOVE:
        print(f"rps lobes: {plan_.speeds} speeds with {plan_.modes} tool modes by "
              f"{cutting.method}: about {plan_.seconds:.0f} s", file=sys.stderr)
    record = lobes(modes, cutting)
    record["seconds"] = time.perf_counter() - start
    payload = LOBES.payload({**head, **record, "warnings": warnings})
    with staged_output(args.out) as stage:
        LOBES.write(stage, payload)
        (stage / "lobes.csv").write_text(csv_rows(payload), encoding="utf-8")
        from reports.lobes_plot import draw_lobes
        draw_lobes(payload, stage / "lobes.png")
    if args.json:
        print(json.dumps(payload))
    else:
        _say(payload, args.out)
    warn(warnings)
    return 0


def csv_rows(payload: dict) -> str:
    """lobes.csv: one row a speed."""
    from results.declare import csv_text

    keys = ["spindle_rpm", "critical_depth_mm", "chatter_frequency_hz", "kind",
            "zoa_depth_mm"] + (["coarse_depth_mm", "error_percent", "intervals"]
                               if "intervals" in payload else [])
    rows = [{k: payload[k][i] for k in keys} for i in range(len(payload["spindle_rpm"]))]
    return csv_text(rows)


def _say(payload: dict, out) -> None:
    least = payload["least"]
    print(f"{payload['source']}: {len(payload['spindle_rpm'])} speeds by {payload['method']}")
    if least is None:
        print(f"stable at every speed up to {payload['ceiling_mm']:.4g} mm")
    else:
        print(f"least critical depth {least['depth_mm']:.4g} mm at {least['spindle_rpm']:.0f} "
              f"rpm ({least['kind']}, chatter at {least['chatter_frequency_hz']:.1f} Hz)")
    best = payload["best"]
    depth = "stable to the ceiling" if best["depth_mm"] is None \
        else f"{best['depth_mm']:.4g} mm"
    print(f"best speed {best['spindle_rpm']:.0f} rpm: {depth}")
    if "max_error_percent" in payload:
        print(f"stated discretisation error at most {payload['max_error_percent']:.2g} % "
              "(the depth at half the intervals)")
    absolute = payload["absolute_limit_mm"]
    if absolute is not None and math.isfinite(absolute):
        print(f"zero-order absolute limit {absolute:.4g} mm")
    print(f"wrote {out}/lobes.json, lobes.csv and lobes.png ({payload['seconds']:.2f} s)")


COMMAND = Command("lobes", "milling stability lobes of one pose: the critical depth of cut per "
                  "spindle speed from the tool's modes (semi-discretization or zero-order)",
                  add_arguments, run, extras="fem,report")
