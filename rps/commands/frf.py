"""`rps frf`: the dynamic compliance at the tool of one pose: the tool point's 3x3 receptance
over a band by modal superposition with the residual flexibility of the modes left out, each
mode's frequency, damping ratio, modal stiffness and effective mass along x, y, z at the tool,
the peaks and the least dynamic stiffness (common/frf.py, solvers/tool_frf.py). Writes
DIR/frf.json and DIR/frf.unv (UFF 58, one FRF per response and force direction, for test
software), the directory replaced whole."""
from __future__ import annotations

import argparse
import json
import math

import numpy as np

from common.errors import InputError
from common.frf import DIRECTIONS, LINES
from runtime.places import path_argument

from ..args import (
    cache_dir,
    cache_option,
    load,
    pose_case,
    pose_payload,
    run_choice,
    scene_args,
    warn,
    with_choice,
    zone_cache,
)
from .registry import Command

MAX_LINES = 100_000  # a band's lines: 2,000 resolve a 1 % damped peak; more is a typo


def add_arguments(p: argparse.ArgumentParser) -> None:
    scene_args(p)
    p.add_argument("--model", choices=("analytical", "fem"), default="analytical",
                   help="the model: the analytical model (the scene's settings, or the run's "
                   "choice with --from-results) or the scene's solid FEM (its modes and its "
                   "static solve, at the scene's mesh size or the run's; default: analytical)")
    p.add_argument("--lines", metavar="N", type=int, default=LINES,
                   help=f"frequency lines from 0 Hz to the band's top (default {LINES})")
    p.add_argument("--top-hz", metavar="HZ", type=float,
                   help="the band's top, Hz (default: 1.25 times the highest compared mode)")
    p.add_argument("--out", metavar="DIR", type=path_argument, required=True,
                   help="directory of frf.json and frf.unv, replaced whole (required, no "
                   "default)")
    cache_option(p)


def _checked(args: argparse.Namespace) -> None:
    if not 3 <= args.lines <= MAX_LINES:
        raise InputError(f"--lines {args.lines}: expected 3 to {MAX_LINES:,} lines")
    if args.top_hz is not None and not (math.isfinite(args.top_hz) and 0 < args.top_hz <= 1e6):
        raise InputError(f"--top-hz {args.top_hz:g}: expected a frequency above 0 and at most "
                         "1e6 Hz")


def _holds_a_resonance(top_hz: float, tool) -> None:
    """Refuse a band that stops below the first mode moving the tool and its half-power band:
    its "least dynamic stiffness" would be the quasi-static value at the band's edge, not a
    resonance's."""
    omega, phi, zeta = tool.modes.omega, tool.modes.phi, tool.zeta
    size = np.linalg.norm(phi, axis=0)
    moving = np.flatnonzero(size > 1e-9 * max(float(size.max(initial=0.0)), 1e-300))
    if not len(moving):
        return
    j = int(moving[0])
    f = float(omega[j]) / (2.0 * math.pi)
    needed = min(f * (1.0 + float(zeta[j])), tool.band_top_hz)  # the band may stop there
    if top_hz < needed:
        raise InputError(f"--top-hz {top_hz:g}: below the first resonance at the tool (mode "
                         f"{j + 1}, {f:.6g} Hz, with its half-power band up to "
                         f"{f * (1.0 + float(zeta[j])):.6g} Hz): the band would hold no mode, "
                         "and its least dynamic stiffness would be the quasi-static one at the "
                         f"band's edge; give at least {needed:.6g} Hz or leave --top-hz out")


def write_uff(path, record: dict, point_base_m) -> None:
    """The nine receptances as UFF 58 on one node, the tool point (base frame)."""
    from modaltest.measured import Dofs, Frfs, Nodes
    from modaltest.uff import write_uff as write

    f = np.asarray(record["frequency_hz"], float)
    h = record["receptance_m_per_n"]
    values, response, reference = [], [], []
    for i, a in enumerate(DIRECTIONS):
        for j, b in enumerate(DIRECTIONS):
            key = a + b if a + b in h else b + a  # the matrix is symmetric
            values.append(np.asarray(h[key]["re"]) + 1j * np.asarray(h[key]["im"]))
            response.append(i + 1)
            reference.append(j + 1)
    lines = f if f[0] > 0.0 else f[1:]  # UFF 58 here: lines above 0 Hz only when it starts
    keep = slice(len(f) - len(lines), None)  # at 0 (some readers divide by f)
    frfs = Frfs(lines, Dofs.from_codes(np.ones(9, int), response),
                Dofs.from_codes(np.ones(9, int), reference),
                np.array([v[keep] for v in values]))
    write(path, Nodes(np.array([1]), np.asarray(point_base_m, float)[None]), frfs=frfs,
          description=f"rps frf: tool point receptance, {record['model']}")


def tool_model(args: argparse.Namespace, scene, geometry, compared: int):
    """The chosen model's modes at the tool of one pose (`--model`) and its settings record;
    InputError for the FEM without the rigid platform."""
    from solvers.tool_frf import analytical_tool, fem_tool

    chosen = run_choice(args, scene)
    if args.model == "analytical":
        options, source = with_choice(scene.analytical, chosen, args)
        options = zone_cache(args, options)
        tool = analytical_tool(scene.manipulator, geometry, options, scene.damping,
                               scene.tool.point, compared,
                               label=f"analytical ({options.describe()})")
        settings = {"model": "analytical", "settings": options.describe(),
                    "settings_from": source or "the scene's"}
    else:
        if scene.fem.platform != "rigid":
            raise InputError(f"--model fem with the scene's fem.platform = "
                             f"{scene.fem.platform!r}: the tool point needs the rigid "
                             "platform")
        from fem_reference import solve_pose
        from solvers.compare import fem_options, fem_runtime

        from .fem import fem_size

        args.size = None
        size, source = fem_size(args, scene)
        options = fem_options(scene, size, modes=compared)
        from runtime.cache import ResultCache
        result = solve_pose(scene.manipulator, geometry, options,
                            fem_runtime(scene, ResultCache(cache_dir(args))), keep_system=True)
        tool = fem_tool(result, scene.damping, scene.tool.point, compared,
                        label=f"FEM ({size * 1e3:g} mm, {options.legs} legs)")
        settings = {"model": "fem", "mesh_size_mm": size * 1e3, "mesh_size_from": source,
                    "dofs": int(result.dofs)}
    return tool, settings


def run(args: argparse.Namespace) -> int:
    import time

    from runtime.outdir import check_output_dir, staged_output
    from solvers.tool_frf import frf_record

    _checked(args)
    check_output_dir(args.out, "--out")
    scene = load(args)
    case, geometry = pose_case(scene, args)
    compared = scene.fidelity.modes
    start = time.perf_counter()
    tool, settings = tool_model(args, scene, geometry, compared)
    if args.top_hz is not None and args.top_hz > tool.band_top_hz * (1 + 1e-9):
        raise InputError(f"--top-hz {args.top_hz:g}: above {tool.band_top_hz:.6g} Hz, where "
                         "the first mode left out of the sum resonates (the band may not "
                         "reach it: its resonance would be missing)")
    if args.top_hz is not None:
        _holds_a_resonance(args.top_hz, tool)
    lines = tool.lines(args.lines, args.top_hz)
    record = frf_record(tool, np.asarray(scene.tool.point) * 1e3, scene.damping, lines)
    point_base = (np.asarray(geometry.platform_centre, float)
                  + np.asarray(geometry.rotation, float) @ np.asarray(scene.tool.point))
    payload = {"scene": scene.name, "case": case.name, "pose": pose_payload(case.pose),
               **settings, **record, "point_base_mm": (point_base * 1e3).tolist(),
               "platform_rotation": np.asarray(geometry.rotation, float).tolist(),
               "seconds": time.perf_counter() - start, "warnings": list(scene.warnings)}
    from results.outputs import FRF

    payload = FRF.payload(payload)
    with staged_output(args.out) as stage:  # frf.json checked against its declaration
        FRF.write(stage, payload)
        write_uff(stage / "frf.unv", payload, point_base)
    if args.json:
        print(json.dumps(payload))
    else:
        print(f"{scene.name}, case {case.name}: {record['model']}, {record['damping']}")
        print(f"tool point {record['point_mm']} mm (platform frame), static compliance "
              + ", ".join(f"{d}{d} {record['static_compliance_m_per_n'][i][i]:.4g}"
                          for i, d in enumerate(DIRECTIONS)) + " m/N")
        for k, m in enumerate(record["modes"][:compared]):
            stiff = m["modal_stiffness_n_per_m"]
            print(f"  mode {k + 1}: {m['frequency_hz']:9.3f} Hz  zeta {m['damping_ratio']:.4f}"
                  "  k " + "  ".join(f"{d} {stiff[d]:.4g}" if stiff[d] is not None else
                                     f"{d} -" for d in DIRECTIONS) + " N/m")
        for d, least in record["least_dynamic_stiffness"].items():
            print(f"least dynamic stiffness {d}: {least['stiffness_n_per_m']:.4g} N/m at "
                  f"{least['frequency_hz']:.3f} Hz (mode {least['mode']})")
        print(f"wrote {args.out}/frf.json and frf.unv ({len(lines)} lines, "
              f"{payload['seconds']:.2f} s)")
    warn(scene.warnings)
    return 0


COMMAND = Command("frf", "the dynamic compliance at the tool of one pose: receptance, modal "
                  "stiffness per mode, least dynamic stiffness", add_arguments, run,
                  extras="fem,modal-test")
