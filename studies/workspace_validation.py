"""The analytical models against the solid FEM over the whole workspace, not two poses.

Design of at least 100 poses over the regular workspace (the paper's Fig. 6 region):
- every height layer of a stratified set (top and bottom layers included): the level pose and
  the boundary ring theta = theta_r(z) at evenly spaced azimuths;
- poses on the reachable boundary where an S joint or an R joint is at its limit (Eq. 25);
- interior poses from a scrambled Sobol sequence in (height, tilt^2 / theta_r^2, azimuth), so
  they cover the disk of every layer evenly (seeded: the same design every run).
At each pose the FEM runs at the scene's chosen size and one size coarser; Richardson's step
between the two at the singular-rim order 1.42 gives the pose's FEM limit (`two_mesh_limit`)
and the fine mesh's estimated error: the larger of its distance to that limit
and Roache's two-mesh grid convergence index (three times it; `solvers.refinement.two_mesh`),
both in the results. Every
analytical model is paired with the fine mesh by shape and its error taken against the limit:
the model's discretisation-free target, not a mesh that is itself 0.1-0.2 % stiff. Since the
observed orders of these graded meshes are at or above 1.42, the step at 1.42 reaches at least
as far as the true limit, so the true error lies between the error against the limit and the
error against the fine mesh (both are in the results: `fem_hz` is the fine mesh's).
One pose is one task of a sweep (`runtime.sweep`), cached by content.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, cast

import numpy as np
from scipy.stats import qmc
from typing_extensions import TypedDict

import results
from analytical.architectures import actuation
from analytical.kinematics import PoseError, pose_geometry
from analytical.params import Manipulator, ModelOptions, Pose
from analytical.reach import layer_band, max_tilts, regular_radii
from common.settings import as_dict
from runtime.cache import ResultCache
from solvers.compare import analytical_case, error_table, in_parallel
from solvers.refinement import two_mesh

from .registry import OWN_TEMPLATE, Section, Study, own

PAPER_MODEL = "paper (EB, s=3, Eq. 8 inertia)"  # a label of solvers.settings.model_variants
SOBOL_SEED = 20231
LIMIT_TOL = 1e-4
# Below this MAC a FEM mode has no partner: its shape is not seen on the leg axes (e.g. a leg's
# torsion, which moves no axis point) or no beam mode resembles it. Its error is not a number.
MAC_MIN = 0.5  # a constraint within this (relative) of its bound is "at its limit"


@dataclass(frozen=True)
class DesignSize:
    layers: int = 6
    ring: int = 6  # boundary azimuths per layer
    interior: int = 64  # Sobol points (a power of two)
    limit_scan: int = 24  # azimuths scanned per layer for joint-limit poses


FULL = DesignSize()
SMALL = DesignSize(layers=2, ring=3, interior=8, limit_scan=6)  # the CI profile


def _active_limit(m: Manipulator, pose: Pose) -> str | None:
    """Which constraint of Eq. (25) the pose is at: "S joint", "R joint", "actuator"."""
    g = pose_geometry(m, pose, check_limits=False)
    if np.max(np.abs(g.s_joint_angles)) >= m.s_joint_max * (1 - LIMIT_TOL):
        return "S joint"
    if np.max(np.abs(g.r_joint_angles)) >= m.r_joint_max * (1 - LIMIT_TOL):
        return "R joint"
    act, value = actuation(m), g.actuation  # leg lengths, or a 3-PRS's slider travels
    span = act.high - act.low  # a limit at 0 (a slider's foot) is near within LIMIT_TOL of it
    if value.max() >= act.high - LIMIT_TOL * (act.high or span) or \
            value.min() <= act.low + LIMIT_TOL * (act.low or span):
        return "actuator"
    return None


def design(m: Manipulator, size: DesignSize = FULL) -> list[dict]:
    """The poses of the study: {height, azimuth, tilt (SI), kind}."""
    return design_with_dropped(m, size)[0]


def design_with_dropped(m: Manipulator, size: DesignSize = FULL) -> tuple[list[dict], int]:
    """The poses of the study, and how many designed poses were left out as unreachable."""
    low, high = layer_band(m)
    poses = []
    dropped = 0

    def add(z, phi, theta, kind):
        nonlocal dropped
        pose = Pose(float(z), float(phi % (2 * math.pi)), float(theta))
        try:
            pose_geometry(m, pose)
        except PoseError:
            dropped += 1
            return
        poses.append({"height": pose.height, "azimuth": pose.azimuth, "tilt": pose.tilt,
                      "kind": kind})

    heights = np.linspace(low, high, size.layers)
    ring = np.linspace(0.0, 2 * math.pi, size.ring, endpoint=False)
    radii = {}
    for k, z in enumerate(heights):
        layer = "bottom layer" if k == 0 else "top layer" if k == len(heights) - 1 else "layer"
        radii[k] = r = float(regular_radii(m, [z])[0])
        add(z, 0.0, 0.0, f"{layer}, level")
        for phi in ring:
            add(z, phi, r * (1 - 1e-9), f"{layer}, boundary ring")
        found = set()
        scan = np.linspace(0.0, 2 * math.pi / 3, size.limit_scan, endpoint=False)
        for phi, widest in zip(scan, max_tilts(m, z, scan)):  # each as max_tilt(m, z, phi)
            t = float(widest) * (1 - 1e-7)
            if t <= 0:
                continue
            which = _active_limit(m, Pose(z, phi, t / (1 - 1e-7)))
            if which in ("S joint", "R joint") and which not in found:
                found.add(which)
                add(z, phi, t, f"{which} at its limit")
    # theta_r(z) between the layers: linear interpolation on a finer grid, taken 0.5 % inside
    # (poses that still fall outside are dropped by `add`)
    grid = np.linspace(low, high, 2 * size.layers + 1)
    grid_r = regular_radii(m, grid)
    sobol = qmc.Sobol(3, scramble=True, seed=SOBOL_SEED).random(size.interior)
    for u in sobol:
        z = low + u[0] * (high - low)
        r = 0.995 * float(np.interp(z, grid, grid_r))
        add(z, 2 * math.pi * u[2], r * math.sqrt(u[1]), "interior (Sobol)")
    return poses, dropped


# the modules a pose's result is computed with, beyond the model packages (its cache key)
TASK_CODE = ("studies.workspace_validation", "solvers.compare", "solvers.pairing",
             "solvers.refinement",
             "results", "scene")


class PoseOutcome(TypedDict):
    """A pose's result from the sweep: `results.ValidationPose` without the pose itself."""
    error: str | None
    fem_hz: list[float] | None
    fem_limit_hz: list[float] | None
    fem_estimated_error_percent: list[float] | None
    fem_gci_percent: list[float] | None
    fem_seconds: float | None
    slenderness: list[float] | None
    models: dict[str, list[float | None]] | None


def validate_pose(task: Mapping[str, Any]) -> PoseOutcome:
    """One pose: FEM at two sizes, every analytical model paired by shape (a sweep task)."""
    scene, pose = task["scene"], Pose(**task["pose"])
    cache = ResultCache(task["cache_dir"])
    count = scene.fidelity.modes
    geometry = pose_geometry(scene.manipulator, pose)
    both = two_mesh(scene, geometry, cache, task["size"], count, coarse=task["coarse_size"])
    fine, limit = both.fine, np.asarray(both.limit_hz)
    models: dict[str, list[float | None]] = {}
    case = _PoseCase(pose)
    for label, options in task["models"].items():
        a = analytical_case(scene, case, options)
        rows = sorted(error_table(a, fine, count, reference_hz=limit),
                      key=lambda r: r["fem_mode"])
        models[label] = [r["error_vs_reference_percent"] if r["mac"] >= MAC_MIN else None
                         for r in rows]
    leg = np.asarray(geometry.leg_lengths) / scene.manipulator.leg_diameter
    return PoseOutcome(error=None, fem_hz=fine.record["frequencies_hz"][:count],
                       fem_limit_hz=limit.tolist(),
                       fem_estimated_error_percent=both.estimated_error_percent,
                       fem_gci_percent=both.gci_percent,
                       fem_seconds=fine.record["timings"].get("total"),
                       slenderness=[float(leg.min()), float(leg.max())], models=models)


def failed_pose(error: str) -> PoseOutcome:
    """A pose the sweep could not solve: its reason, and nothing else."""
    return PoseOutcome(error=error, fem_hz=None, fem_limit_hz=None,
                       fem_estimated_error_percent=None, fem_gci_percent=None, fem_seconds=None,
                       slenderness=None, models=None)


@dataclass(frozen=True)
class _PoseCase:
    """The little of a scene case that `analytical_case` reads."""

    pose: Pose
    name: str = "pose"


def task_payload(task: Mapping[str, Any]) -> Mapping[str, object]:
    """What determines a task's result, for its cache key."""
    s = task["scene"]
    return {"manipulator": as_dict(s.manipulator), "fem": as_dict(s.fem),
            "modes": s.fidelity.modes, "pose": task["pose"], "size": task["size"],
            "coarse_size": task["coarse_size"],
            "models": {k: as_dict(v) for k, v in task["models"].items()}}


def percentiles(poses: list[results.ValidationPose], labels) -> results.PerMode:
    """Per model and mode: median, p95 and max of |error vs FEM| (%) over the poses."""
    out: results.PerMode = {}
    ok = [p for p in poses if p.get("models")]
    for label in labels:
        errs = np.abs(np.array([[np.nan if e is None else e for e in (p["models"] or {})[label]]
                                for p in ok], float))  # (n, modes), NaN: unpaired
        if errs.size == 0:
            continue
        out[label] = results.ModeStatistics(
            median=_nan(np.nanmedian(errs, axis=0)), p95=_nan(np.nanpercentile(errs, 95, axis=0)),
            max=_nan(np.nanmax(errs, axis=0)), unpaired=np.isnan(errs).sum(axis=0).tolist())
    return out


def _nan(values) -> list[float | None]:
    return [None if not np.isfinite(v) else float(v) for v in values]


def worst_error(errors) -> float:
    """Largest |error| of a pose's paired modes (unpaired ones have no error)."""
    return max((abs(e) for e in errors if e is not None), default=0.0)


def worst_pose(poses: list[results.ValidationPose],
               label: str) -> results.ValidationPose | None:
    ok = [p for p in poses if p["models"]]
    if not ok:
        return None
    return max(ok, key=lambda p: worst_error((p["models"] or {})[label]))


def run_study(scene, models: dict[str, ModelOptions], cache: ResultCache, coarse_size: float,
              size: DesignSize = FULL, workers: int = 2, scheduler: str | None = None,
              announce=None, progress=None,
              seconds_per_pose: float | None = None) -> results.ValidationSweep:
    """studies.workspace_validation of results.json (see the module docstring)."""
    from runtime.sweep import run_sweep

    poses = design(scene.manipulator, size)
    shared = in_parallel(scene, 1 if scheduler else min(workers, len(poses)))  # at once here
    tasks = [{"scene": shared, "cache_dir": str(cache.directory),
              "pose": {k: p[k] for k in ("height", "azimuth", "tilt")},
              "size": scene.fem.mesh_size, "coarse_size": coarse_size,
              "models": models} for p in poses]
    solved = run_sweep(validate_pose, tasks, [task_payload(t) for t in tasks], cache,
                        "workspace-pose", workers=workers, scheduler=scheduler,
                        announce=announce, seconds_per_task=seconds_per_pose,
                        progress=progress, code=TASK_CODE)
    rows = [results.ValidationPose(
        height_mm=p["height"] * 1e3, azimuth_deg=math.degrees(p["azimuth"]),
        tilt_deg=math.degrees(p["tilt"]), kind=p["kind"],
        # a solved pose's answer is validate_pose's (the sweep's cache keeps it as it was)
        **(failed_pose(r["error"]) if r.get("error") else cast(PoseOutcome, r)))
        for p, r in zip(poses, solved)]
    return results.ValidationSweep(
        poses=rows, per_mode=percentiles(rows, list(models)),
        models={k: as_dict(v) for k, v in models.items()},
        mesh_size_mm=scene.fem.mesh_size * 1e3, coarse_mesh_size_mm=coarse_size * 1e3,
        failed=sum(1 for r in rows if r["error"]))


def summarise(study: results.ValidationSweep, default: str) -> results.WorkspaceValidation:
    """The study with its default model (the run's chosen one) and that model's worst pose."""
    worst = worst_pose(study["poses"], default)
    errors = None if worst is None else (worst["models"] or {})[default]
    return results.WorkspaceValidation(
        **study, default_model=default, worst_pose=None if worst is None or errors is None
        else results.WorstPose(
            height_mm=worst["height_mm"], azimuth_deg=worst["azimuth_deg"],
            tilt_deg=worst["tilt_deg"], kind=worst["kind"], slenderness=worst["slenderness"],
            fem_estimated_error_percent=worst["fem_estimated_error_percent"],
            error_percent=errors, worst_error_percent=worst_error(errors)))


STUDY = Study(own("workspace_validation", "scene", section=Section(
    "validation", "The model against the FEM over the workspace", "workspace validation",
    OWN_TEMPLATE), tables=(
        results.Table("poses", ("height_mm", "azimuth_deg", "tilt_deg", "kind", "fem_seconds",
                                "error"), each="poses"),
        results.Table("worst_pose", ("height_mm", "azimuth_deg", "tilt_deg", "kind",
                                     "worst_error_percent"), each="worst_pose"))),
    "fidelity", None, profiles=("full", "ci"))
