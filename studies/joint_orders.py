"""Both joint orders of the paper side by side: its equations (R at the base, S at the
platform, Eqs. 10-17) and its Section 2 text (S at the base, R at the platform).

The same machine and poses are solved in each order by both models (the paper-faithful and the
best beam model, and the FEM at the scene's mesh size), modes paired by shape. It shows that
the seam between kinematics and models holds for either order: the two models should agree
with each other as closely in one order as in the other. A 3-PRS has one order (its R joint
on the slider, `Architecture.joint_orders`): the study shows it alone.
"""
from __future__ import annotations

from dataclasses import replace
from typing import Any

import results
from analytical.architectures import of
from analytical.kinematics import pose_geometry
from runtime.cache import ResultCache
from scene import Scene
from solvers.compare import analytical_case, error_table, model_reading
from solvers.refinement import two_mesh

from .registry import OWN_TEMPLATE, Context, Section, Study, own

MODELS: dict[str, dict[str, Any]] = {"EB, s=3": dict(beam="euler-bernoulli", elements=3),
          "Timoshenko, s=3": dict(beam="timoshenko", elements=3)}


def with_joints(m, base: str, top: str):
    """The scene's springs for a joint order: a rotational spring is the R joint's (the S joint
    constrains no rotation), so it moves with it; translational springs stay with their body."""
    k = m.stiffness
    if (base, top) == (m.base_joint, m.platform_joint):
        return k
    return replace(k, base_joint_rotational=k.platform_joint_rotational,
                   platform_joint_rotational=k.base_joint_rotational)


def joint_order_study(scene: Scene, case_names,
                      cache: ResultCache) -> list[results.JointOrderCase]:
    """Per case and joint order: FEM frequencies and each beam model's error vs the FEM."""
    count = scene.analytical.modes
    out = []
    for name in case_names:
        case = scene.case(name)
        readings = []
        for base, top in of(scene.manipulator).joint_orders:
            m = replace(scene.manipulator, base_joint=base, platform_joint=top,
                        stiffness=with_joints(scene.manipulator, base, top))
            ordered = replace(scene, manipulator=m)
            entry = results.JointOrderReading(
                base_joint=base, platform_joint=top,
                scene_order=(base, top) == (scene.manipulator.base_joint,
                                            scene.manipulator.platform_joint),
                error=None, fem_hz=None, fem_estimated_error_percent=None,
                fem_gci_percent=None, models=None)
            try:
                geometry = pose_geometry(m, case.pose)
                both = two_mesh(ordered, geometry, cache, scene.fem.mesh_size, count)
            except (ValueError, RuntimeError) as exc:
                entry["error"] = " ".join(str(exc).split())
                readings.append(entry)
                continue
            fem = both.fine
            entry["fem_hz"] = fem.record["frequencies_hz"][:count]
            entry["fem_estimated_error_percent"] = both.estimated_error_percent
            entry["fem_gci_percent"] = both.gci_percent
            entry["models"] = {
                label: model_reading(error_table(analytical_case(
                    ordered, case, replace(scene.analytical, **settings)), fem, count))
                for label, settings in MODELS.items()}
            readings.append(entry)
        out.append(results.JointOrderCase(case=name, readings=readings))
    return out


def run(ctx: Context) -> list[results.JointOrderCase]:
    return joint_order_study(ctx.scene, ctx.scene.ci_cases, ctx.cache)


STUDY = Study(own("joint_orders", "scene", section=Section(
    "joint-orders", "Joint orders", "both joint orders", OWN_TEMPLATE)), "scene", run)
