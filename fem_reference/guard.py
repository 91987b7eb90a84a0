"""The DOF and memory guard: a solve's size estimated before meshing, and refused when too big.

`check_mesh_size` is asked before any mesh is built (by `model.solve_pose` and the CLI, for
every size of a refinement study up front): the raw dofs estimated from the bodies' volume and
surfaces (tetrahedra: `estimate_raw_dofs` here; harmonic legs: `meridian.estimate_raw_dofs`)
against `FemRuntime.max_dofs`, then the solve's peak memory against the machine's
(`resources.check_memory`).
"""
from __future__ import annotations

import math

import numpy as np

from meshing.bodies import Assembly
from meshing.geometry import MeshSettings, element_size

from .meridian import estimate_raw_dofs as estimate_harmonic
from .options import FemError, FemOptions, FemRuntime
from .resources import MemoryLimitError, check_memory

# P2 nodes ~ NODES_PER_VOLUME V / h^3 + NODES_PER_AREA A / h^2 + NODES_PER_RIM_AREA times the
# rims' surface term (estimate_raw_dofs). Fitted (relative least squares) to 82 meshes of the
# pinned gmsh options with Netgen's optimiser: the paper's legs, three poses, 16-50 mm, uniform
# and six graded families; then raised by 1.2 so that no mesh has more nodes than estimated:
# estimate / actual 1.01-1.36 there, 1.15-1.38 on stocky (d = 150 mm) and slender (d = 30 mm)
# legs. The fit leaves no separate volume term at the rims: the surface meshes carry the
# grading, and the interior follows them.
NODES_PER_VOLUME = 4.4
NODES_PER_AREA = 7.4
NODES_PER_RIM_AREA = 14.0
MAX_ESTIMATE = 10**15  # dofs: the estimate of absurdly small sizes, far above any guard


def estimate_raw_dofs(assembly: Assembly, settings: MeshSettings) -> int:
    """Raw dof count of the P2 mesh, estimated from volume and surface before meshing.

    Uniform part: NODES_PER_VOLUME V / h^3 + NODES_PER_AREA A / h^2. Graded part, at every
    joint-face rim (a circle of the leg radius R): the surface nodes that the finer size s(r) of
    `meshing.geometry.element_size` adds at a distance r from the rim, on the two surfaces that
    meet there (the face and the wall), NODES_PER_RIM_AREA int (1/s^2 - 1/h^2) 2 (2 pi R) dr.
    """
    h = settings.size
    tubes = [c for c in assembly.cylinders if c.hollow]
    try:
        if not tubes:
            nodes = (NODES_PER_VOLUME * assembly.volume / h**3
                     + NODES_PER_AREA * assembly.area / h**2)
        else:  # the solids (and the plate) at h, each tube at its own size
            plate = [assembly.plate] if assembly.plate is not None else []
            solids = [c for c in assembly.cylinders if not c.hollow] + plate
            nodes = (NODES_PER_VOLUME * sum(b.volume for b in solids) / h**3
                     + NODES_PER_AREA * sum(b.area for b in solids) / h**2)
            nodes += sum(_tube_nodes(c, settings) for c in tubes)
        if settings.rim_factor < 1 and settings.rim_zone > 0:
            for c in assembly.cylinders:
                if c.hollow:
                    continue
                reach = min(settings.rim_zone, c.radius, 0.5 * c.length)
                r = reach * np.concatenate([np.linspace(0.0, 1e-3, 50)[:-1],
                                            np.geomspace(1e-3, 1.0, 400)])
                finer = 1 / element_size(settings, r) ** 2 - 1 / h**2
                nodes += (NODES_PER_RIM_AREA * 2 * (2 * math.pi * c.radius)
                          * float(np.trapezoid(2 * finer, r)))
    except (ZeroDivisionError, OverflowError, FloatingPointError):  # h^3 underflows
        nodes = math.inf
    if not math.isfinite(nodes):
        return MAX_ESTIMATE
    return int(3 * nodes) if 3 * nodes < MAX_ESTIMATE else MAX_ESTIMATE


def _tube_nodes(c, settings: MeshSettings) -> float:
    """P2 nodes of a tube: meshed at h_t = min(h, wall) (`meshing.geometry`'s wall field), its
    rims graded on both circles (radius R + r_in in the rim term), the grading's size at most
    h_t. The same constants as the solids'; a thin wall's elements are squat (one across the
    wall), so the volume term counts them as h_t cubes: an upper bound (checked in
    tests/test_fem_real_legs.py)."""
    h = float(settings.size)
    ht = min(h, c.wall)
    nodes = NODES_PER_VOLUME * c.volume / ht**3 + NODES_PER_AREA * c.area / ht**2
    if settings.rim_factor < 1 and settings.rim_zone > 0:
        reach = min(settings.rim_zone, c.wall, 0.5 * c.length)
        r = reach * np.concatenate([np.linspace(0.0, 1e-3, 50)[:-1],
                                    np.geomspace(1e-3, 1.0, 400)])
        finer = 1 / np.minimum(element_size(settings, r), ht) ** 2 - 1 / ht**2
        nodes += (NODES_PER_RIM_AREA * 2 * (2 * math.pi * (c.radius + c.inner_radius))
                  * float(np.trapezoid(2 * finer, r)))
    return nodes


PLATE_WIDTH_PER_THICKNESS = 2.0  # an elastic plate fills like a leg of twice its thickness


def section_width(assembly: Assembly) -> float:
    """The width the LU fill model (resources.peak_bytes) takes for the meshed bodies: the leg
    diameter it was fitted on, or, with an elastic plate thicker than half the legs, twice the
    plate's thickness. Measured (max RSS of `rps fem --platform elastic --legs tetrahedra`):
    a 41 mm plate of 222 mm radius on 18.9 mm legs at 12 mm, 1.95 GB (estimate with the legs
    alone 1.32 GB, with this width 2.78 GB); the slender scene's 15 mm plate on 30 mm legs at
    9.6 and 7.5 mm, 1.30 and 3.65 GB (its legs set the width: 2.17 and 4.21 GB)."""
    width = 2 * max(c.radius for c in assembly.cylinders)
    if assembly.plate is not None:
        width = max(width, PLATE_WIDTH_PER_THICKNESS * assembly.plate.thickness)
    return width


def check_mesh_size(assembly: Assembly, options: FemOptions, runtime: FemRuntime) -> None:
    """Refuse, before meshing, a size coarser than a leg or whose estimated dofs exceed the
    DOF guard, or (tetrahedra) whose solve would not fit in memory: FemError naming the size."""
    settings = options.mesh
    diameter = 2 * max(c.radius for c in assembly.cylinders)
    shown = f"mesh_size_mm = {settings.size * 1e3:g}"
    if settings.size > diameter:
        raise FemError(f"{shown}: coarser than the leg diameter {diameter * 1e3:g} mm (needs "
                       "at least one element across a leg)")
    harmonic = options.legs == "harmonic"
    if harmonic:  # 2D meridians: a fraction of the memory of 3D meshes
        estimate = estimate_harmonic(assembly, settings.size)
    else:
        estimate = estimate_raw_dofs(assembly, settings)
    if estimate > runtime.max_dofs:
        raise FemError(f"{shown}: about {estimate}{' harmonic' if harmonic else ''} dofs "
                       f"expected, above max_dofs = {runtime.max_dofs}")
    try:  # before meshing: peak against the memory the machine has, whatever max_dofs says
        check_memory(estimate, section_width(assembly), settings.size, harmonic=harmonic,
                     share=runtime.memory_share)
    except MemoryLimitError as exc:
        raise FemError(str(exc)) from None
