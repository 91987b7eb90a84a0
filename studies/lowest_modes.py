"""What sets the lowest modes (issue 23): the drive's stiffness swept, and where the strain
energy of every mode lies.

A real machine's joints are bearings and its drive a ball screw: springs in series with the
legs. Which of them sets a mode is read two ways, per case:

- the sweep: f1-f6 of both models with the scene's actuator stiffness k_a scaled by 0.01 to
  100 (the FEM at the run's mesh size, modes paired by shape), beside the rigid drive. Where
  a mode's frequency is 1/sqrt(2) of its rigid-drive value, the drive and the rest of the
  machine are equally compliant for it (springs in series: 1/f^2 = 1/f_drive^2 +
  1/f_structure^2): its knee, above which the structure takes over. A mode the drive never
  halves in the sweep (set by the joints or the legs) has no knee;
- the energy: the share of each mode's strain energy x^T K x in the legs, the joint springs,
  the drive and the platform (`analytical.modal.strain_energy_shares`, the run's analytical
  model at the scene's values; the platform is rigid in both models, its share 0 by
  construction).

A scene with no spring (rigid joints and drive) needs neither: the study records nothing.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

import results
from analytical.kinematics import pose_geometry
from analytical.modal import ENERGY_PARTS, strain_energy_shares
from analytical.model import analyse
from common.stiffness import MIN_SPRING
from scene import Scene
from solvers.compare import analytical_case, error_table
from solvers.refinement import two_mesh

from .registry import OWN_TEMPLATE, Context, Section, Study, floats, own

FACTORS = (0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0)
DRIVE = "actuator_axial"
KNEE = 1.0 / math.sqrt(2.0)  # f1 / f1(rigid drive) where drive and structure share f1


def with_drive(scene: Scene, factor: float | None) -> Scene:
    """The scene with its drive's stiffness scaled by `factor` (None: a rigid drive)."""
    springs = scene.manipulator.stiffness
    springs = (replace(springs, actuator_axial=0.0) if factor is None
               else springs.scaled(factor, {DRIVE}))
    return replace(scene, manipulator=replace(scene.manipulator, stiffness=springs))


def swept(k_a: float) -> tuple[float, ...]:
    """The factors of the sweep for a drive of stiffness k_a: FACTORS, less those that would
    take it below the softest spring a scene may declare (`common.stiffness.MIN_SPRING`)."""
    return tuple(f for f in FACTORS if f * k_a >= MIN_SPRING)


def knee(factors, f, rigid_f: float) -> float | None:
    """The factor at which f / f(rigid drive) crosses 1/sqrt(2), interpolated in log k_a;
    None when the sweep does not cross it."""
    ratio = np.asarray(f) / rigid_f
    logs = np.log10(factors)
    for k in range(len(ratio) - 1):
        if (ratio[k] - KNEE) * (ratio[k + 1] - KNEE) <= 0.0 and ratio[k] != ratio[k + 1]:
            t = (KNEE - ratio[k]) / (ratio[k + 1] - ratio[k])
            return float(10 ** (logs[k] + t * (logs[k + 1] - logs[k])))
    return None


def shares(scene: Scene, pose, count: int) -> list[results.EnergyShares]:
    """Each of the first `count` modes' strain energy by part, percent (the run's model)."""
    res = analyse(scene.manipulator, pose, replace(scene.analytical, modes=count))
    parts = strain_energy_shares(res.model, res.modal.shapes)
    out: list[results.EnergyShares] = []
    for k in range(count):
        row = {part: float(100.0 * parts[part][k]) for part in ENERGY_PARTS}
        out.append(results.EnergyShares(mode=k + 1,
                                        frequency_hz=float(res.frequencies_hz[k]),
                                        legs_percent=row["legs"], joints_percent=row["joints"],
                                        drive_percent=row["drive"],
                                        platform_percent=row["platform"],
                                        largest=max(row, key=lambda part: row[part])))
    return out


def sweep_point(scene: Scene, case, geometry, cache, factor: float | None,
                count: int) -> results.SweepPoint:
    variant = with_drive(scene, factor)
    a = analytical_case(variant, case, variant.analytical)
    both = two_mesh(variant, geometry, cache, variant.fem.mesh_size, count)
    fem = both.fine
    rows = sorted(error_table(a, fem, count), key=lambda r: r["fem_mode"])
    springs = variant.manipulator.stiffness
    return results.SweepPoint(
        factor=factor, actuator_n_per_um=springs.actuator_axial / 1e6,
        analytical_hz=floats(a.record["frequencies_hz"][:count]),
        fem_hz=floats(fem.record["frequencies_hz"][:count]),
        fem_estimated_error_percent=both.estimated_error_percent,
        fem_gci_percent=both.gci_percent,
        error_percent=[r["error_percent"] for r in rows])


def lowest_modes(scene: Scene, case_names, cache) -> list[results.LowestModes]:
    """Per case: the sweep (when the drive is a spring) and the energy shares."""
    springs = scene.manipulator.stiffness
    if springs.rigid:
        return []
    count = scene.analytical.modes
    out: list[results.LowestModes] = []
    for name in case_names:
        case = scene.case(name)
        geometry = pose_geometry(scene.manipulator, case.pose)
        sweep: list[results.SweepPoint] = []
        knees: list[float | None] = []
        rigid = None
        if springs.actuator_axial > 0.0:
            rigid = sweep_point(scene, case, geometry, cache, None, count)
            factors = swept(springs.actuator_axial)
            sweep = [sweep_point(scene, case, geometry, cache, f, count) for f in factors]
            knees = [knee(factors, [p["analytical_hz"][j] for p in sweep],
                          rigid["analytical_hz"][j]) for j in range(count)]
        energy = shares(scene, case.pose, count)
        out.append(results.LowestModes(
            case=name, mesh_size_mm=1e3 * scene.fem.mesh_size, sweep=sweep, rigid_drive=rigid,
            knee_factors=knees,
            knee_n_per_um=[None if k is None else k * springs.actuator_axial / 1e6
                           for k in knees],
            shares=energy, sets_lowest=energy[0]["largest"]))
    return out


def run(ctx: Context) -> list:
    return lowest_modes(ctx.scene, ctx.scene.ci_cases, ctx.cache)


STUDY = Study(own("lowest_modes", "scene", section=Section(
    "lowest-modes", "What sets the lowest modes: drive, joints and legs",
    "what sets the lowest modes", OWN_TEMPLATE)), "scene", run)
