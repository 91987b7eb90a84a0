"""A design study: the scene values a design file varies, optimised for its objective under its
constraints, with the least frequency over the whole reachable workspace as the constraint
that matters (`scene.design_file`, `rps design`).

Each design is the scene with the variables set, parsed and checked like any scene (a refused
one is infeasible, its one-line reason kept), then:
- its moving mass: the three legs (at mid-stroke on a 3-RPS, their one length on a 3-PRS, every
  part of the profile), the platform plate and the payload;
- its level band (`analytical.reach.level_band`) and the least f_mode over its reachable
  workspace, with the pose (`analytical.minimum.workspace_minimum`, the design file's model).
Every design is stored in the result cache under its content (scene values, model, code), so a
study that is stopped and run again solves only what it had not (resumable).

The search is scipy's differential evolution (a global optimiser: the least frequency over a
workspace is not convex in the design) on the variables' box, the constraints as a penalty
beyond every feasible value, its budget the file's `designs`. The result: every design solved,
the feasible optimum, the Pareto front of moving mass against the least f_mode among the
designs that meet the other constraints, and at the optimum the FEM (harmonic legs, at the
scene's mesh size and one coarser) at the optimum's worst pose: the model's error there, since
a design is only reported with its model's error at that pose (the fidelity rule).
"""
from __future__ import annotations

import math
import sys
import time
from dataclasses import replace
from typing import Any, Callable

import numpy as np
from scipy.optimize import differential_evolution, minimize
from typing_extensions import NotRequired, TypedDict

from analytical.architectures import leg_length_range
from analytical.kinematics import pose_geometry
from analytical.minimum import grid_frequencies, workspace_minimum
from analytical.params import Manipulator, Pose
from analytical.platform import platform_mass
from analytical.reach import level_band, max_tilts
from common.errors import InputError, RpsError
from common.paths import display_path
from common.settings import as_dict
from results.lobe_records import StabilityLeast
from results.outputs import Output
from results.tool_records import LeastPose
from runtime.cache import ResultCache
from scene import Case
from scene.design_file import DesignSpec, design_scene
from solvers.compare import analytical_case, error_table
from solvers.refinement import two_mesh


class PoseAt(TypedDict):
    height_mm: float
    azimuth_deg: float
    tilt_deg: float


class DesignPoint(TypedDict):
    """One design: its variables' values and, unless refused, what it achieves."""
    values: list[float]
    refused: str | None  # why it is not a machine or has no workspace
    moving_mass_kg: NotRequired[float]
    level_band_mm: NotRequired[float]
    min_frequency_hz: NotRequired[float]  # least f_mode over the workspace
    worst_pose: NotRequired[PoseAt]  # where
    min_dynamic_stiffness_n_per_m: NotRequired[float]  # least over the regular workspace and
    dynamic_worst: NotRequired[LeastPose]  # the constraint's directions; where, which way
    min_critical_depth_mm: NotRequired[float | None]  # the cut's least over a coarse map and
    stability_worst: NotRequired[StabilityLeast]  # the speeds (None: stable); where, how
    on_boundary: NotRequired[bool]


class FemCheck(TypedDict):
    """The FEM at the optimum's worst pose against the model, or why it could not be made."""
    error: str | None
    fem_hz: NotRequired[float]
    model_hz: NotRequired[float]
    error_percent: NotRequired[float]
    mac: NotRequired[float]
    paired_analytical_mode: NotRequired[int]
    by_order_error_percent: NotRequired[float]
    fem_estimated_error_percent: NotRequired[float]
    mesh_size_mm: NotRequired[float]
    tolerance_percent: NotRequired[float]
    within_tolerance: NotRequired[bool]


class BoundaryMap(TypedDict):
    """f_mode over the workspace's boundary: [height][azimuth], None where unreachable."""
    heights_mm: list[float]
    azimuths_deg: list[float]
    tilt_deg: list[list[float]]
    frequencies_hz: list[list[float | None]]


class DesignStudy(TypedDict):
    """`rps design`'s result (design.json), the design report's only input."""
    name: str
    scene: str
    variables: list[dict[str, Any]]  # name, low, high (the design file's units)
    constraints: dict[str, Any]  # min_frequency_hz, mode, min_level_band_mm
    objective: str
    model: str
    designs_solved: int
    feasible: int
    optimum: DesignPoint | None
    front: list[DesignPoint]
    designs: list[DesignPoint]
    fem_check: FemCheck | None
    optimum_map: BoundaryMap | None


class DesignFile(DesignStudy):
    """What `rps design` writes: the study, its header and the plausibility warnings."""
    record: str
    schema: int
    warnings: list[str]  # of the design file's scene and of the optimum's


DESIGN = Output(
    "design.json", "design", 1, DesignFile, "rps design",
    "A design study: the variables and their bounds, the constraints and the objective, every "
    "design solved (its values, moving mass, least frequency over the workspace and where, or "
    "why it was refused), the Pareto front, the optimum with its boundary map and the FEM at "
    "its worst pose. Written with --out FILE, and as design.json beside the design report.")


PENALTY = 1e9  # objective of an infeasible design: above every feasible one, by how far it fails
POLISH_SHARE = 0.3  # of the budget, for the local search after the global one


def moving_mass(m: Manipulator) -> float:
    """kg: three legs at mid-stroke (every part of the profile), the plate, the payload."""
    low, high = leg_length_range(m)
    legs = sum(m.material.density * math.pi / 4 * (p.outer ** 2 - p.inner ** 2) * p.length
               for p in m.leg_parts(0.5 * (low + high)))
    return 3 * legs + platform_mass(m) + m.payload.mass


def evaluate(spec: DesignSpec, values, cache: ResultCache) -> DesignPoint:
    """One design, through the cache: its values, moving mass, level band, least f_mode and
    where, or the reason it is refused."""
    values = [float(v) for v in values]
    record = DesignPoint(values=values, refused=None)
    try:
        scene = design_scene(spec, values)
    except RpsError as exc:
        record["refused"] = str(exc)
        return record
    m = scene.manipulator
    payload = {"manipulator": as_dict(m), "model": as_dict(spec.model),
               "mode": spec.constraints.mode}
    if needs_dynamic(spec):
        payload.update(damping=as_dict(scene.damping), tool=as_dict(scene.tool),
                       directions=list(spec.constraints.directions), grid=list(DYNAMIC_GRID))
    if needs_stability(spec):
        payload.update(damping=as_dict(scene.damping), tool=as_dict(scene.tool),
                       cutting=as_dict(scene.cutting), stability_grid=list(STABILITY_GRID))

    def compute() -> tuple[dict, dict]:
        out: dict = {"moving_mass_kg": moving_mass(m)}
        try:
            found = workspace_minimum(m, spec.model, mode=spec.constraints.mode)
            band = found.band
        except RpsError as exc:  # no workspace, or a model that cannot solve it: refused
            return {**out, "refused": str(exc)}, {}
        out.update(refused=None, level_band_mm=(band.high - band.low) * 1e3,
                   min_frequency_hz=found.frequency_hz,
                   worst_pose={"height_mm": found.pose.height * 1e3,
                               "azimuth_deg": math.degrees(found.pose.azimuth),
                               "tilt_deg": math.degrees(found.pose.tilt)},
                   on_boundary=found.boundary)
        try:
            if needs_dynamic(spec):
                out.update(least_dynamic(spec, scene))
            if needs_stability(spec) and not out.get("refused"):
                out.update(least_stability(spec, scene))
        except RpsError as exc:  # a model that cannot solve its map: refused, not fatal
            return {**out, "refused": str(exc)}, {}
        return out, {}

    value, _, _ = cache.get_or_compute("design-point", payload, compute,
                                       required=("moving_mass_kg",),
                                       modules=("studies.design", "scene",
                                                "studies.dynamic_stiffness",
                                                "studies.workspace_map",
                                                "studies.stability_map", "chatter"))
    record.update(value)  # type: ignore[typeddict-item]  # the cached fields of a DesignPoint
    return record


DYNAMIC_GRID = (5, 4, 24, 500)  # layers, rings, azimuths, lines of a design's dynamic map


def needs_dynamic(spec: DesignSpec) -> bool:
    return (spec.constraints.min_dynamic_stiffness > 0.0
            or spec.objective.minimise == "dynamic_stiffness")


class DynamicOutcome(TypedDict, total=False):
    """A design's least dynamic stiffness and where, or why it has none."""
    refused: str
    min_dynamic_stiffness_n_per_m: float
    dynamic_worst: LeastPose


def least_dynamic(spec: DesignSpec, scene) -> DynamicOutcome:
    """The least dynamic stiffness at the scene's tool over a coarse map of the regular
    workspace (DYNAMIC_GRID; studies.dynamic_stiffness), in the weakest of the constraint's
    directions, and where."""
    from dataclasses import replace

    from .dynamic_stiffness import dynamic_stiffness_map

    layers, rings, azimuths, lines = DYNAMIC_GRID
    found = dynamic_stiffness_map(replace(scene, analytical=spec.model), layers, rings,
                                  azimuths, lines)
    rows = [r for r in found["least"] if r["direction"] in spec.constraints.directions]
    if not rows:  # the tool never moves along these directions
        return DynamicOutcome(refused="the tool point does not move along "
                              f"{', '.join(spec.constraints.directions)} in any mode summed: "
                              "no dynamic stiffness to take there")
    worst = min(rows, key=lambda r: r["stiffness_n_per_m"])
    return DynamicOutcome(min_dynamic_stiffness_n_per_m=worst["stiffness_n_per_m"],
                          dynamic_worst=worst)


STABILITY_GRID = (2, 2, 6, 30)  # layers, rings, azimuths, speeds of a design's stability map


def needs_stability(spec: DesignSpec) -> bool:
    return (spec.constraints.min_critical_depth > 0.0
            or spec.objective.minimise == "critical_depth")


class StabilityOutcome(TypedDict, total=False):
    """A design's least critical depth and where (None: stable at every pose and speed up to
    the search's ceiling)."""
    min_critical_depth_mm: float | None
    stability_worst: StabilityLeast


def least_stability(spec: DesignSpec, scene) -> StabilityOutcome:
    """The least critical depth of the scene's cut over a coarse stability map of the regular
    workspace (STABILITY_GRID: studies.stability_map, the design's search model, its speeds
    thinned evenly over the [cutting] range), and where."""
    from .stability_map import stability_map

    layers, rings, azimuths, speeds = STABILITY_GRID
    cutting = scene.cutting
    if not cutting.spindle_list:
        cutting = replace(cutting, speeds=min(speeds, cutting.speeds))
    found = stability_map(replace(scene, analytical=spec.model, cutting=cutting), layers,
                          rings, azimuths, say=False)
    if not found["least"]:
        return StabilityOutcome(min_critical_depth_mm=None)
    return StabilityOutcome(min_critical_depth_mm=found["least"][0]["depth_mm"],
                            stability_worst=found["least"][0])


def depth_mm(record: DesignPoint) -> float:
    """The design's least critical depth, mm (inf: stable everywhere)."""
    value = record.get("min_critical_depth_mm")
    return math.inf if value is None else value


def meets(spec: DesignSpec, record: DesignPoint, frequency: bool = True) -> bool:
    """The design meets the band constraint and (with `frequency`) the frequency and dynamic
    stiffness targets."""
    if record.get("refused"):
        return False
    c = spec.constraints
    ok = record["level_band_mm"] >= c.min_level_band * 1e3 - 1e-9
    if not frequency:
        return ok
    ok = ok and record["min_frequency_hz"] >= c.min_frequency_hz
    if c.min_dynamic_stiffness > 0.0:
        ok = ok and record["min_dynamic_stiffness_n_per_m"] >= c.min_dynamic_stiffness
    if c.min_critical_depth > 0.0:
        ok = ok and depth_mm(record) >= c.min_critical_depth * 1e3
    return ok


def objective(spec: DesignSpec, record: DesignPoint) -> float:
    """The optimiser's value (lower is better): any feasible design's below PENALTY, then the
    designs failing a constraint by how far (relative shortfalls, capped), then the refused
    ones (not a machine, or no workspace) at 10 PENALTY."""
    if record.get("refused"):
        return 10 * PENALTY
    if not meets(spec, record):
        c = spec.constraints
        short = max(0.0, c.min_frequency_hz - record["min_frequency_hz"]) / max(
            c.min_frequency_hz, 1.0)
        if c.min_level_band:
            short += max(0.0, c.min_level_band * 1e3 - record["level_band_mm"]) / (
                c.min_level_band * 1e3)
        if c.min_dynamic_stiffness:
            short += max(0.0, c.min_dynamic_stiffness
                         - record["min_dynamic_stiffness_n_per_m"]) / c.min_dynamic_stiffness
        if c.min_critical_depth:
            short += max(0.0, c.min_critical_depth * 1e3 - depth_mm(record)) / (
                c.min_critical_depth * 1e3)
        return PENALTY * (1.0 + min(short, 5.0))
    if spec.objective.minimise == "critical_depth":
        return -min(depth_mm(record), PENALTY / 10)  # stable everywhere: the best there is
    if spec.objective.minimise == "moving_mass":
        return record["moving_mass_kg"]
    if spec.objective.minimise == "dynamic_stiffness":
        return -record["min_dynamic_stiffness_n_per_m"]
    return -record["min_frequency_hz"]


def pareto_front(spec: DesignSpec, records: list[DesignPoint]) -> list[DesignPoint]:
    """The designs (meeting the band constraint) no other one beats on both moving mass
    (lower) and least frequency (higher), by mass."""
    pool = sorted((r for r in records if meets(spec, r, frequency=False)),
                  key=lambda r: (r["moving_mass_kg"], -r["min_frequency_hz"]))
    front, best = [], -math.inf
    for r in pool:
        if r["min_frequency_hz"] > best:
            front.append(r)
            best = r["min_frequency_hz"]
    return front


def fem_check(spec: DesignSpec, record: DesignPoint, cache: ResultCache) -> FemCheck:
    """The FEM at the design's worst pose against the model: the fidelity rule's statement."""
    scene = design_scene(spec, record["values"])
    p = record["worst_pose"]
    pose = Pose(p["height_mm"] * 1e-3, math.radians(p["azimuth_deg"]), math.radians(p["tilt_deg"]))
    count = spec.constraints.mode
    geometry = pose_geometry(scene.manipulator, pose)
    both = two_mesh(scene, geometry, cache, scene.fem.mesh_size, count)
    case = Case("worst pose", "the design's worst pose", pose, "scene")
    rows = error_table(analytical_case(scene, case, replace(spec.model, modes=count)),
                       both.fine, count)
    row = next((r for r in rows if r["fem_mode"] == count), None)
    if row is None:
        raise InputError(f"FEM mode {count} found no analytical mode of its shape")
    tol = scene.fidelity.tolerance_percent
    fem_k = float(both.fine.record["frequencies_hz"][count - 1])
    return FemCheck(fem_hz=row["f_fem_hz"], model_hz=row["f_analytical_hz"],
                    error_percent=row["error_percent"], mac=row["mac"],
                    paired_analytical_mode=row["analytical_mode"],
                    by_order_error_percent=100.0 * (record["min_frequency_hz"] / fem_k - 1.0),
                    fem_estimated_error_percent=both.estimated_error_percent[count - 1],
                    mesh_size_mm=scene.fem.mesh_size * 1e3, tolerance_percent=tol,
                    within_tolerance=abs(row["error_percent"]) <= tol, error=None)


MAP_GRID = (24, 36)  # heights x azimuths of the optimum's map on the workspace's boundary


def boundary_map(spec: DesignSpec, record: DesignPoint) -> BoundaryMap:
    """f_mode of a design over its workspace's boundary (every height of the level band and
    azimuth, at the largest reachable tilt), where the least value usually lies: the optimum's
    frequency map."""
    m = design_scene(spec, record["values"]).manipulator
    band = level_band(m)
    heights = np.linspace(band.low, band.high, MAP_GRID[0])
    phis = np.linspace(0.0, 2 * math.pi, MAP_GRID[1], endpoint=False)
    top = max_tilts(m, heights, phis, 1e-9)
    z, p = np.meshgrid(heights, phis, indexing="ij")
    hz = grid_frequencies(m, replace(spec.model, modes=spec.constraints.mode), z, p, top)
    return BoundaryMap(heights_mm=(heights * 1e3).tolist(),
                       azimuths_deg=np.degrees(phis).tolist(), tilt_deg=np.degrees(top).tolist(),
                       frequencies_hz=[[float(f) if math.isfinite(f) else None for f in row]
                                       for row in hz[..., -1]])


SAY_ABOVE = 60.0  # s: a study estimated longer says so on stderr when its first design is done


def say_estimate(spec: DesignSpec, seconds: float) -> None:
    """The study's time from its first design (a cached design: nothing to say)."""
    total = seconds * spec.search.designs
    if total > SAY_ABOVE:
        layers, rings, azimuths, speeds = STABILITY_GRID
        print(f"design: {seconds:.1f} s a design (its stability map: up to "
              f"{layers * rings * azimuths} poses x {speeds} speeds), about "
              f"{total / 60:.0f} min for {spec.search.designs} designs (cached designs are "
              "not solved again)", file=sys.stderr)


def run_design(spec: DesignSpec, cache: ResultCache,
               step: Callable[[int, int], None] = lambda done, total: None) -> DesignStudy:
    """The study (the module doc); `step(done, budget)` after every design solved."""
    n = len(spec.variables)
    low = np.array([v.low for v in spec.variables])
    high = np.array([v.high for v in spec.variables])
    budget = spec.search.designs
    global_budget = budget - int(POLISH_SHARE * budget)
    population = min(max(5, global_budget // 4), 15 * n)  # scipy: popsize * n of them
    popsize = -(-population // n)
    generations = max(0, global_budget // (popsize * n) - 1)
    records: list[DesignPoint] = []
    seen: dict[tuple, DesignPoint] = {}

    def solve(x) -> float:
        values = low + np.clip(x, 0.0, 1.0) * (high - low)
        key = tuple(np.round(values, 9))
        if key not in seen:
            if len(records) >= budget:  # over budget (never adopted: worse than any design)
                return 100 * PENALTY
            started = time.perf_counter()
            seen[key] = evaluate(spec, values, cache)
            if not records and needs_stability(spec):  # the first design says the whole
                say_estimate(spec, time.perf_counter() - started)
            records.append(seen[key])
            step(len(records), budget)
        return objective(spec, seen[key])

    found = differential_evolution(solve, [(0.0, 1.0)] * n, popsize=popsize,
                                   maxiter=generations, seed=spec.search.seed, polish=False,
                                   init="latinhypercube", tol=1e-6)
    # the rest of the budget: a local search from the best design (bounded Nelder-Mead on the
    # same penalised objective), which closes in on the constraint the optimum lies on
    minimize(solve, found.x, method="Nelder-Mead", bounds=[(0.0, 1.0)] * n,
             options={"maxfev": max(0, budget - len(records)), "xatol": 1e-4,
                      "fatol": 1e-6 * max(abs(found.fun), 1e-12)})
    feasible = [r for r in records if meets(spec, r)]
    optimum = min(feasible, key=lambda r: objective(spec, r)) if feasible else None
    out = DesignStudy(
        name=spec.name, scene=display_path(spec.scene_path),
        variables=[{"name": v.name, "low": v.low, "high": v.high} for v in spec.variables],
        constraints={"min_frequency_hz": spec.constraints.min_frequency_hz,
                     "mode": spec.constraints.mode,
                     "min_level_band_mm": spec.constraints.min_level_band * 1e3,
                     "min_dynamic_stiffness_n_per_m": spec.constraints.min_dynamic_stiffness,
                     "directions": list(spec.constraints.directions),
                     "min_critical_depth_mm": spec.constraints.min_critical_depth * 1e3},
        objective=spec.objective.minimise, model=spec.model.describe(),
        designs_solved=len(records), feasible=len(feasible), optimum=optimum,
        front=pareto_front(spec, records), designs=records, fem_check=None, optimum_map=None)
    if optimum is None:
        return out
    out["optimum_map"] = boundary_map(spec, optimum)
    try:
        out["fem_check"] = fem_check(spec, optimum, cache)
    except RpsError as exc:  # the study stands; the check says why it could not be made
        out["fem_check"] = FemCheck(error=f"the optimum's FEM check failed: {exc}")
    return out
