"""The FEM at several sizes: a refinement study of one pose through the result cache, the
two-mesh estimate of a solve that has no study, and the cache filled ahead on the sweep's
workers (every study that needs the FEM limit or the FEM's error asks here)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np
from typing_extensions import TypedDict

import results as schema
from runtime.cache import ResultCache
from scene import Scene
from solvers.compare import Solve, fem_case, in_parallel


def study_sizes(refinement, size: float | None = None) -> tuple[float, ...]:
    """The sizes of a refinement study (m, coarse -> fine): the scene's sequence, with `size`
    (the run's own) added unless it already is one of them (to 1e-9: a size read in mm and a
    size computed in leg diameters may differ in the last bit, and two sizes that close would
    make the extrapolation divide by ~0)."""
    sizes = [float(h) for h in refinement]
    if size is not None and not any(math.isclose(size, h, rel_tol=1e-9) for h in sizes):
        sizes.append(float(size))
    return tuple(sorted(sizes, reverse=True))


def sizes_m(study: schema.Refinement) -> list[float]:
    """A refinement study's mesh sizes in m (the record holds them in mm)."""
    return [h * 1e-3 for h in study["mesh_sizes_mm"]]


def size_index(sizes, size: float) -> int | None:
    """Where `size` is in a study's `sizes` (to 1e-9, as `study_sizes` added it); None when it
    is not one of them."""
    for k, h in enumerate(sizes):
        if math.isclose(size, h, rel_tol=1e-9):
            return k
    return None


def coarse_size(scene: Scene, size: float) -> float:
    """The second, coarser mesh of a two-mesh estimate: the next size of the scene's
    refinement sequence above `size`, or 1.25 size beyond it."""
    coarser = [h for h in scene.fem_study.refinement if h > size * (1 + 1e-9)]
    return min(coarser) if coarser else size * 1.25


@dataclass(frozen=True)
class TwoMesh:
    """A FEM solve at `size` with its error from a second solve one size coarser (modes in
    order, the first `count`): Roache's two-mesh GCI (factor 3 at the rims' order 1.42), the
    stated error (the larger of it and Richardson's step, %) and the two-mesh limit (Hz)."""

    fine: Solve[schema.FemRecord]
    gci_percent: list[float]
    estimated_error_percent: list[float]
    limit_hz: list[float]


def two_mesh(scene: Scene, geometry, cache: ResultCache, size: float, count: int,
             coarse: float | None = None, **options) -> TwoMesh:
    """The FEM of one pose at `size` and at `coarse` (default `coarse_size`), through the
    cache; `options` as `fem_case`'s (platform, coupling, legs, max_dofs)."""
    from fem_reference.convergence import two_mesh_error, two_mesh_gci, two_mesh_limit

    coarse = coarse_size(scene, size) if coarse is None else coarse
    fine = fem_case(scene, geometry, cache, size, **options)
    pair = (fine.record["frequencies_hz"][:count],
            fem_case(scene, geometry, cache, coarse, **options).record["frequencies_hz"][:count],
            coarse / size)
    gci = two_mesh_gci(*pair)
    return TwoMesh(fine, gci.tolist(), np.maximum(two_mesh_error(*pair), gci).tolist(),
                   two_mesh_limit(*pair).tolist())


class Solved(TypedDict):
    """A sweep task's answer: None, or why it failed (`runtime.sweep`)."""
    error: str | None


def _solve_fem(task: Mapping[str, Any]) -> Solved:
    """One FEM solve into the result cache (a task of `prefetch_fem`)."""
    fem_case(task["scene"], task["geometry"], ResultCache(task["cache_dir"]), task["size"],
             max_dofs=task["max_dofs"])
    return Solved(error=None)


def prefetch_fem(scene: Scene, geometries: list, sizes, cache: ResultCache, workers: int,
                 scheduler: str | None = None, max_dofs: int | None = None) -> None:
    """Fill the result cache with the FEM solve of every geometry at every size, on the
    sweep's workers (finest first, for balance; each solve within its share of the memory,
    `in_parallel`, and `max_dofs` when given); the callers then read them from the cache. A
    failed solve is left to its caller, which repeats it and reports its error."""
    from runtime.sweep import map_tasks

    count = len(sizes) * len(geometries)
    at_once = 1 if scheduler else min(workers, count)  # dask: one solve per remote process
    tasks = [{"scene": in_parallel(scene, at_once), "geometry": g, "size": h,
              "cache_dir": str(cache.directory), "max_dofs": max_dofs}
             for h in sorted(sizes) for g in geometries]
    if workers > 1 or scheduler:
        map_tasks(_solve_fem, tasks, workers, scheduler)


def fem_refinement(scene: Scene, geometry, cache: ResultCache,
                   sizes: tuple[float, ...]) -> schema.Refinement:
    """Solve at every size (each through the cache) and extrapolate every frequency
    (Richardson with the observed order, and the grid convergence index, GCI:
    fem_reference.convergence): a results.Refinement. Its `estimated_error_percent`, the error
    every consumer states and chooses by, is the larger of the two."""
    from fem_reference.convergence import study_from_values
    from meshing.bodies import pose_assembly

    solves = [fem_case(scene, geometry, cache, size).record for size in sizes]
    count = scene.analytical.modes
    volume = pose_assembly(scene.manipulator, geometry,
                           elastic_platform=scene.fem.platform == "elastic").volume
    study = study_from_values(sizes, [s["frequencies_hz"][:count] for s in solves],
                              [s["dofs"] for s in solves], [s["raw_dofs"] for s in solves],
                              [s["timings"] for s in solves], volume)
    return schema.Refinement(
        mesh_sizes_mm=[h * 1e3 for h in study.sizes],
        effective_mesh_sizes_mm=[h * 1e3 for h in study.effective_sizes],
        frequencies_hz=study.frequencies_hz, dofs=study.dofs, raw_dofs=study.raw_dofs,
        timings=study.timings,
        seconds=[t.get("total", sum(t.values())) for t in study.timings],
        mesh_cache_hit=[s["mesh_cache_hit"] for s in solves],
        observed_order=study.orders,
        orders_by_triplet=[m.orders_by_triplet for m in study.modes],
        status=[m.status for m in study.modes],
        extrapolated_hz=study.extrapolated_hz,
        richardson_error_percent=(100 * study.relative_errors).tolist(),
        gci_percent=(100 * study.gci_errors).tolist(),
        gci_order=[g.order for g in study.gci],
        gci_observed_order=[g.observed_order for g in study.gci],
        gci_safety_factor=[g.safety_factor for g in study.gci],
        gci_extrapolated_hz=[g.extrapolated_hz for g in study.gci],
        gci_percent_max=(100 * study.gci_errors.max(axis=1)).tolist(),
        estimated_error_percent=(100 * study.stated_errors).tolist(),
        estimated_error_percent_max=[100 * study.max_error(k) for k in range(len(sizes))])
