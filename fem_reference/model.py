"""One pose of the 3-RPS manipulator as a 3D solid: the top of the package, which dispatches.

solve_pose(manipulator, geometry, options, runtime) -> a `FemAnswer`: the pose's bodies
(`meshing.bodies.pose_assembly`), the size checked before anything is meshed
(`guard.check_mesh_size`: dofs and memory), then the legs as `options.legs` says:
  "harmonic"    Fourier harmonics on a 2D meridian mesh per leg (`harmonic.py`, the default;
                rigid platform only) -> `HarmonicResult`
  "tetrahedra"  a 3D mesh of 10-node tetrahedra (`tetrahedra.py`; also the elastic plate)
                -> `FemResult`
Every failure on bad input is a FemError with one line naming the offending value; nothing is
written (cache entries and VTU files are atomic).

The names the rest of the project reads from here (options, errors, the guard, the result of
the tetrahedra) are defined below this module and re-exported.
"""
from __future__ import annotations

import time

from meshing.bodies import GeometryError, pose_assembly

from .answer import FemAnswer
from .guard import check_mesh_size, estimate_raw_dofs
from .harmonic import HarmonicError, HarmonicResult, solve_pose_harmonic
from .options import (
    LEG_MODELS,
    PLATFORMS,
    FemError,
    FemOptions,
    FemRuntime,
    legs_for,
    with_size,
)
from .tetrahedra import FemResult, solve_pose_tetrahedra

__all__ = ["FemAnswer", "FemError", "FemOptions", "FemResult", "FemRuntime", "HarmonicResult",
           "LEG_MODELS", "PLATFORMS", "check_mesh_size", "estimate_raw_dofs", "legs_for",
           "solve_pose", "with_size"]


ELASTIC_PAYLOAD = ("platform = 'elastic' with a payload: how the payload's mass spreads over an "
                   "elastic plate is not modelled (use a rigid platform)")


def solve_pose(manipulator, geometry, options: FemOptions,
               runtime: FemRuntime = FemRuntime(), keep_system: bool = False) -> FemAnswer:
    """Natural frequencies and modes of the 3D solid model of one pose; with `keep_system`
    the answer keeps its K_q and M_q (`system`, what the direct frequency response solves;
    otherwise None: they are large)."""
    if not isinstance(options, FemOptions):
        raise FemError(f"options = {options!r}: expected FemOptions")
    if not isinstance(runtime, FemRuntime):
        raise FemError(f"runtime = {runtime!r}: expected FemRuntime")
    if options.platform == "elastic" and manipulator.payload.mass > 0.0:  # before meshing
        raise FemError(ELASTIC_PAYLOAD)
    t0 = time.perf_counter()
    try:
        assembly = pose_assembly(manipulator, geometry,
                                 elastic_platform=options.platform == "elastic")
    except GeometryError as exc:
        raise FemError(str(exc)) from None
    check_mesh_size(assembly, options, runtime)
    if options.legs == "harmonic":
        try:  # sub-second: in this process, so its per-leg caches serve the next pose
            return solve_pose_harmonic(manipulator, geometry, options, runtime.max_dofs,
                                       keep_system)
        except HarmonicError as exc:
            raise FemError(str(exc)) from None
    return solve_pose_tetrahedra(manipulator, geometry, assembly, options, runtime, t0,
                                 keep_system)
