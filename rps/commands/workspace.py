"""`rps workspace`: the lowest frequencies over the regular workspace (the paper's Fig. 6), or
with `--minimum K` the least f_K over the whole reachable workspace and where it is
(`analytical.minimum`)."""
from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import replace
from typing import TYPE_CHECKING, Any, Iterable, cast

from common.errors import InputError
from scene import FidelitySettings

from ..args import cache_option, load, scene_option, warn, zone_cache
from ..options import MAX_MAP_POSES, MapGrid, declared_option, typed
from .registry import Command

if TYPE_CHECKING:  # results (and pydantic, an extra) only where JSON is printed
    from ..answers import MinimumAnswer as MinimumOutput
    from ..answers import WorkspaceAnswer as WorkspaceOutput


def cmd_workspace(args: argparse.Namespace) -> WorkspaceOutput | MinimumOutput:
    """The frequency map; the grid and the mode count checked against what the model holds
    before any pose is solved."""
    from analytical.workspace import followed_modes
    from studies.workspace_map import workspace_map

    scene = load(args)
    scene = replace(scene, analytical=zone_cache(args, scene.analytical))
    if args.minimum is not None:
        from ..answers import MINIMUM_ANSWER
        return MINIMUM_ANSWER.checked(MINIMUM_ANSWER.payload(
            {**_minimum(scene, args), "warnings": list(scene.warnings)}))
    poses = args.layers * args.rings * args.azimuths
    if poses > MAX_MAP_POSES:
        raise InputError(f"{typed(args, 'layers', 'rings', 'azimuths') or 'the grid'}: "
                         f"{poses:,} poses, above the {MAX_MAP_POSES:,} of one map (about a "
                         "minute); use a coarser grid")
    followed = followed_modes(scene.manipulator, scene.analytical)
    if args.modes > followed:
        raise InputError(f"{typed(args, 'modes') or f'modes = {args.modes}'}: the map follows "
                         f"at most {followed} modes with this scene's model "
                         f"(s = {scene.analytical.elements} elements per leg)")
    start = time.perf_counter()
    fmap = workspace_map(scene, args.layers, args.rings, args.azimuths, args.modes)
    seconds = time.perf_counter() - start
    from ..answers import WORKSPACE_ANSWER
    return WORKSPACE_ANSWER.checked(WORKSPACE_ANSWER.payload(
        {**fmap, "seconds": seconds, "warnings": list(scene.warnings)}))


def _minimum(scene, args: argparse.Namespace) -> dict[str, Any]:
    """The fields of a MinimumAnswer (rps/answers.py) but its header and warnings."""
    # the least f_K over the reachable workspace, with the scene's analytical model
    from dataclasses import replace

    from analytical.minimum import workspace_minimum
    from analytical.substructure import model_coordinates

    k = args.minimum
    if k > model_coordinates(scene.manipulator, scene.analytical):
        raise InputError(f"{typed(args, 'minimum')}: the scene's model has only "
                         f"{model_coordinates(scene.manipulator, scene.analytical)} modes")
    options = replace(scene.analytical, modes=k)
    start = time.perf_counter()
    found = workspace_minimum(scene.manipulator, options, mode=k)
    return {"mode": k, "frequency_hz": found.frequency_hz,
            "pose": {"height_mm": found.pose.height * 1e3,
                     "azimuth_deg": math.degrees(found.pose.azimuth),
                     "tilt_deg": math.degrees(found.pose.tilt)},
            "on_boundary": found.boundary, "at_band_end": found.band_end,
            "coarse_grid_hz": found.coarse_hz, "poses_solved": found.evaluations,
            "settings": options.describe(),
            "seconds": time.perf_counter() - start}


def _print_minimum(found: MinimumOutput) -> None:
    p = found["pose"]
    where = ("on the workspace's boundary" if found["on_boundary"] else
             "at an end of the level band" if found["at_band_end"] else "inside the workspace")
    print(f"least f{found['mode']} over the reachable workspace: {found['frequency_hz']:.4f} Hz "
          f"at z = {p['height_mm']:.2f} mm, azimuth {p['azimuth_deg']:.2f} deg, tilt "
          f"{p['tilt_deg']:.3f} deg ({where}); coarse grid {found['coarse_grid_hz']:.4f} Hz; "
          f"{found['poses_solved']} poses, {found['seconds']:.1f} s, {found['settings']}")


def _print_workspace(fmap: WorkspaceOutput) -> None:
    print(f"{'z (mm)':>8} {'tilt_r (deg)':>12}  lowest f_k over the layer (Hz)")
    for z, r, layer in zip(fmap["heights_mm"], fmap["regular_tilt_deg"], fmap["frequencies_hz"]):
        values = [az for ring in layer for az in ring if az and az[0] is not None]
        lows = [_least(v[k] for v in values) for k in range(len(values[0]))] if values else []
        print(f"{z:8.1f} {r:12.2f}  " + ", ".join(f"{f:.2f}" for f in lows))
    print(f"{fmap['seconds']:.2f} s, {fmap['settings']}")


def _least(values: Iterable[float | None]) -> float:
    """The least of the values, none of them None (TypeError then, as min or printing None
    would raise)."""
    listed = list(values)
    found = [v for v in listed if v is not None]
    if len(found) < len(listed):
        raise TypeError("a reachable map pose without one of its frequencies")
    return min(found)


def add_arguments(w: argparse.ArgumentParser) -> None:
    scene_option(w)
    declared_option(w, "--layers", MapGrid, "layers", default=8, metavar="N",
                    help="height layers")
    declared_option(w, "--rings", MapGrid, "rings", default=6, metavar="N",
                    help="tilt rings per layer")
    declared_option(w, "--azimuths", MapGrid, "azimuths", default=36, metavar="N",
                    help="azimuths per ring")
    declared_option(w, "--modes", FidelitySettings, "modes", default=3, metavar="N",
                    help="modes per pose")
    declared_option(w, "--minimum", FidelitySettings, "modes", metavar="K",
                    help="instead of the map: the least f_K over the whole reachable workspace "
                    "and its pose (coarse grid, then local searches; default: the map)")
    w.add_argument("--json", action="store_true", help="print one JSON object, exact values")
    cache_option(w)


def run(args: argparse.Namespace) -> int:
    fmap = cmd_workspace(args)
    if args.json:
        print(json.dumps(fmap))
    elif args.minimum is not None:  # cmd_workspace answered with the minimum
        _print_minimum(cast("MinimumOutput", fmap))
    else:  # and otherwise with the map
        _print_workspace(cast("WorkspaceOutput", fmap))
    warn(fmap["warnings"])
    return 0


COMMAND = Command("workspace", "f1..fN over the regular workspace (Fig. 6)", add_arguments, run)
