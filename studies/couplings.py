"""The joint-end model under both joint-face couplings (issue 13, part 1).

A joint face of the solid can be tied to its joint rigidly (the face moves as a rigid body:
its section cannot warp or contract, the stress-singular rims) or by a distributing coupling
(the joint takes the face's mean motion, the face deforms freely). Both are honest readings of a
pin or ball joint, and they bracket it. For every CI case and both couplings this study refines
the FEM with that coupling (the scene's refinement sizes, Richardson limit) and compares with it
the beam-ended Timoshenko model and the Timoshenko model between solid end zones coupled the
same way (`ModelOptions.joint_coupling`), plus the run's chosen setting: the error per mode
against the FEM limit, with and without the joint-end model, per coupling.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

import results
from analytical.kinematics import pose_geometry
from common.joints import COUPLINGS
from runtime.cache import ResultCache
from scene import Scene
from solvers.compare import analytical_case, error_table, fem_case, model_reading
from solvers.settings import Settings, speed_settings

from .registry import OWN_TEMPLATE, Context, Section, Study, own

MODELS = ("Timoshenko (Hutchinson), s=5", "Timoshenko (Hutchinson) + solid ends, s=5")


def coupled(scene: Scene, coupling: str) -> Scene:
    """The scene with both models' joint faces coupled `coupling`-wise."""
    return replace(scene, fem=replace(scene.fem, coupling=coupling),
                   analytical=replace(scene.analytical, joint_coupling=coupling))


def models(scene: Scene, chosen_label: str | None) -> Settings:
    settings = speed_settings(scene)
    labels = list(MODELS) + ([chosen_label] if chosen_label in settings
                             and chosen_label not in MODELS else [])
    return {label: settings[label] for label in labels}


def coupling_study(scene: Scene, case_names, cache: ResultCache, chosen_label: str | None,
                   workers: int = 1,
                   scheduler: str | None = None) -> list[results.CouplingCase]:
    """Per case and coupling: the FEM limit and each model's error against it."""
    from solvers.refinement import fem_refinement, prefetch_fem

    count = scene.analytical.modes
    sizes = tuple(sorted(scene.fem_study.refinement, reverse=True))
    for coupling in COUPLINGS:
        prefetch_fem(coupled(scene, coupling),
                     [pose_geometry(scene.manipulator, scene.case(n).pose) for n in case_names],
                     sizes, cache, workers, scheduler)
    out = []
    for name in case_names:
        case = scene.case(name)
        geometry = pose_geometry(scene.manipulator, case.pose)
        readings = []
        for coupling in COUPLINGS:
            variant = coupled(scene, coupling)
            entry = results.CouplingReading(
                coupling=coupling, scene_coupling=coupling == scene.fem.coupling, error=None,
                mesh_sizes_mm=[1e3 * h for h in sizes], fem_limit_hz=None,
                fem_finest_error_percent=None, fem_finest_gci_percent=None, models=None)
            try:
                refinement = fem_refinement(variant, geometry, cache, sizes)
            except (ValueError, RuntimeError) as exc:
                entry["error"] = " ".join(str(exc).split())
                readings.append(entry)
                continue
            limit = np.asarray(refinement["extrapolated_hz"])
            entry["fem_limit_hz"] = limit.tolist()
            entry["fem_finest_error_percent"] = refinement["estimated_error_percent"][-1]
            entry["fem_finest_gci_percent"] = refinement["gci_percent"][-1]
            finest = fem_case(variant, geometry, cache, sizes[-1])
            readings_of: dict[str, results.ModelReading] = {}
            for label, options in models(variant, chosen_label).items():
                a = analytical_case(variant, case, replace(options, joint_coupling=coupling))
                rows = sorted(error_table(a, finest, count, reference_hz=limit),
                              key=lambda r: r["fem_mode"])
                readings_of[label] = model_reading(rows, "error_vs_reference_percent")
            entry["models"] = readings_of
            readings.append(entry)
        out.append(results.CouplingCase(case=name, readings=readings))
    return out


def run(ctx: Context) -> list[results.CouplingCase]:
    return coupling_study(ctx.scene, ctx.scene.ci_cases, ctx.cache, ctx.chosen_setting,
                          ctx.workers, ctx.scheduler)


STUDY = Study(own("joint_couplings", "scene", section=Section(
    "joint-couplings", "Joint faces: rigid and distributing couplings",
    "both joint-face couplings", OWN_TEMPLATE)), "scene", run)
