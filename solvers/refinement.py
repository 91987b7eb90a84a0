"""The FEM at several sizes: a refinement study of one pose through the result cache, and the
cache filled ahead on the sweep's workers (every study that needs the FEM limit asks here)."""
from __future__ import annotations

import results as schema
from runtime.cache import ResultCache
from scene import Scene
from solvers.compare import fem_case, in_parallel


def _solve_fem(task: dict) -> dict:
    """One FEM solve into the result cache (a task of `prefetch_fem`)."""
    fem_case(task["scene"], task["geometry"], ResultCache(task["cache_dir"]), task["size"],
             max_dofs=task["max_dofs"])
    return {"error": None}


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
                   sizes: tuple[float, ...]) -> dict:
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
        sizes_m=study.sizes, effective_sizes_m=study.effective_sizes,
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
