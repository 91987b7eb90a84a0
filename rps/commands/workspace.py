"""`rps workspace`: the lowest frequencies over the regular workspace (the paper's Fig. 6)."""
from __future__ import annotations

import argparse
import json
import time

from common.errors import InputError
from scene import FidelitySettings

from ..args import scene_option
from ..options import MAX_MAP_POSES, MapGrid, declared_option, typed
from .registry import Command


def cmd_workspace(args: argparse.Namespace) -> dict:
    """The frequency map; the grid and the mode count checked against what the model holds
    before any pose is solved."""
    from analytical.workspace import followed_modes
    from scene import load_scene
    from studies.workspace_map import workspace_map

    scene = load_scene(args.scene)
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
    fmap["seconds"] = time.perf_counter() - start
    return fmap


def _print_workspace(fmap: dict) -> None:
    print(f"{'z (mm)':>8} {'tilt_r (deg)':>12}  lowest f_k over the layer (Hz)")
    for z, r, layer in zip(fmap["heights_mm"], fmap["regular_tilt_deg"], fmap["frequencies_hz"]):
        values = [f for ring in layer for az in ring for f in [az] if az and az[0] is not None]
        lows = [min(v[k] for v in values) for k in range(len(values[0]))] if values else []
        print(f"{z:8.1f} {r:12.2f}  " + ", ".join(f"{f:.2f}" for f in lows))
    print(f"{fmap['seconds']:.2f} s, {fmap['settings']}")


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
    w.add_argument("--json", action="store_true", help="print one JSON object, exact values")


def run(args: argparse.Namespace) -> int:
    fmap = cmd_workspace(args)
    if args.json:
        print(json.dumps(fmap))
    else:
        _print_workspace(fmap)
    return 0


COMMAND = Command("workspace", "f1..fN over the regular workspace (Fig. 6)", add_arguments, run)
