"""The run's fidelity step: measure the candidates on the scene's cases, choose, report.

Pure choosing lives in `pipeline.fidelity`; this module runs what the choice is made from:
every case's FEM refinement study (cached solves) and every analytical candidate of the
speed-vs-error set (`studies.speed_settings`) against the FEM limit, timed per pose.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from analytical.kinematics import pose_geometry

from . import studies
from .cache import ResultCache
from .compare import analytical_case, error_table, fem_case
from .fidelity import AnalyticalChoice, FemChoice, choose_analytical, choose_fem_size
from .scene import Scene

SCENE_SETTING = "scene's [analytical]"


@dataclass(frozen=True)
class Fidelity:
    scene: Scene  # the scene with the chosen analytical options and FEM size
    fem: FemChoice
    analytical: AnalyticalChoice
    candidates: dict  # label -> per case {"case", "seconds", "worst_error_percent"}
    refinements: dict  # case name -> refinement study (dict), when refined

    @property
    def met(self) -> bool:
        return self.fem.met and self.analytical.met

    def summary(self) -> dict:
        """results.json's top-level `fidelity` object."""
        opts = self.scene.analytical
        tol = self.scene.fidelity.tolerance_percent
        reason = f"{self.analytical.reason}; {self.fem.reason}."
        if not self.met:
            reason = ("The scene's tolerance is NOT met: " + reason)
        return {
            "modes": self.scene.fidelity.modes,
            "tolerance_percent": tol,
            "met": self.met,
            "analytical": {"beam": opts.beam, "elements": opts.elements,
                           "platform_inertia": opts.platform_inertia,
                           "setting": self.analytical.setting,
                           "chosen": not self.scene.analytical_given,
                           "worst_error_percent": self.analytical.worst_error_percent,
                           "seconds_per_pose": self.analytical.seconds_per_pose,
                           "met": self.analytical.met},
            "fem": {"mesh_size_mm": self.scene.fem.mesh_size * 1e3,
                    "chosen": not self.scene.fem_size_given,
                    "estimated_error_percent": self.fem.worst_error_percent,
                    "seconds_per_pose": _fem_seconds(self),
                    "met": self.fem.met},
            "reason": reason,
            "candidates": [{"setting": label, "worst_error_percent":
                            max(r["worst_error_percent"] for r in rows),
                            "seconds_per_pose": sorted(r["seconds"] for r in rows)[len(rows) // 2]}
                           for label, rows in self.candidates.items()],
        }


def _fem_seconds(fid: Fidelity) -> float | None:
    size = fid.scene.fem.mesh_size
    times = [study["seconds"][study["sizes_m"].index(size)]
             for study in fid.refinements.values() if size in study["sizes_m"]]
    return float(np.median(times)) if times else None


def resolve_fidelity(scene: Scene, case_names, cache: ResultCache, refine: bool,
                     step=lambda text: None) -> Fidelity:
    """Choose (or check) the FEM size and the analytical setting for these cases."""
    from .run import fem_refinement

    tol = scene.fidelity.tolerance_percent
    count = scene.fidelity.modes
    refinements = {}
    if refine:
        sizes = tuple(sorted(set(scene.fem_study.refinement) | (
            {scene.fem.mesh_size} if scene.fem_size_given else set()), reverse=True))
        for name in case_names:
            step(f"{name}: FEM refinement study")
            case = scene.case(name)
            refinements[name] = fem_refinement(scene, case,
                                               pose_geometry(scene.manipulator, case.pose),
                                               cache, sizes)
        errors = [study["estimated_error_percent"] for study in refinements.values()]
        if scene.fem_size_given:
            k = sizes.index(scene.fem.mesh_size)
            worst = max(max(e[k]) for e in errors)
            fem = FemChoice(scene.fem.mesh_size, worst, worst <= 0.2 * tol,
                            f"h = {scene.fem.mesh_size * 1e3:.3g} mm as the scene asks, "
                            f"estimated error {worst:.3g} %")
        else:
            fem = choose_fem_size(list(sizes), errors, tol)
    else:
        size = scene.fem.mesh_size if scene.fem_size_given else scene.fem_study.ci_mesh_size
        fem = FemChoice(size, None, True,
                        f"h = {size * 1e3:.3g} mm without a refinement study (CI profile): "
                        "the FEM's own error is not estimated")
    sized = replace(scene, fem=scene.fem.with_size(fem.size))

    candidates = dict(studies.speed_settings(sized))
    if scene.analytical_given:
        candidates = {SCENE_SETTING: scene.analytical} | candidates
    rows: dict[str, list[dict]] = {label: [] for label in candidates}
    for name in case_names:
        step(f"{name}: analytical candidates")
        case = sized.case(name)
        fem_result = fem_case(sized, pose_geometry(sized.manipulator, case.pose), cache,
                              fem.size)
        reference = (np.asarray(refinements[name]["extrapolated_hz"]) if name in refinements
                     else np.asarray(fem_result["frequencies_hz"][:count]))
        for label, opts in candidates.items():
            a = analytical_case(sized, case, opts)
            table = error_table(a, fem_result, count, None, reference)
            rows[label].append({
                "case": name,
                "seconds": studies.time_model(sized, case, opts),
                "worst_error_percent": max(abs(r["error_vs_reference_percent"])
                                           for r in table)})
    if scene.analytical_given:
        mine = rows[SCENE_SETTING]
        worst = max(r["worst_error_percent"] for r in mine)
        seconds = sorted(r["seconds"] for r in mine)[len(mine) // 2]
        analytical = AnalyticalChoice(SCENE_SETTING, worst, seconds, worst <= tol,
                                      f"the scene's own analytical setting is off by up to "
                                      f"{worst:.2f} % (tolerance {tol:g} %)")
        chosen_opts = scene.analytical
    else:
        analytical = choose_analytical(rows, tol)
        chosen_opts = candidates[analytical.setting]
    chosen = replace(sized, analytical=replace(chosen_opts, modes=count))
    return Fidelity(chosen, fem, analytical, rows, refinements)
