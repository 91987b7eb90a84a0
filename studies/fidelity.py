"""The run's fidelity step: measure the candidates on the scene's cases, choose, report.

Pure choosing lives in `studies.choice`; this module runs what the choice is made from:
every case's FEM refinement study (cached solves) and every analytical candidate of the
speed-vs-error set (`solvers.settings.speed_settings`) against the FEM limit, timed per pose.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

import results
from analytical.kinematics import pose_geometry
from analytical.params import Pose
from runtime.cache import ResultCache
from scene import Scene
from solvers.compare import analytical_case, error_table, fem_case, reference_error
from solvers.refinement import coarse_size, prefetch_fem, size_index, sizes_m, study_sizes
from solvers.settings import Settings, model_variants, speed_settings
from solvers.timing import seconds_per_pose
from studies.choice import (
    FEM_ERROR_SHARE,
    AnalyticalChoice,
    FemChoice,
    Measured,
    Places,
    Rows,
    Where,
    choose_analytical,
    choose_fem_size,
)

from . import workspace_validation as wv

SCENE_SETTING = "scene's [analytical]"


@dataclass(frozen=True)
class Fidelity:
    scene: Scene  # the scene with the chosen analytical options and FEM size
    fem: FemChoice
    analytical: AnalyticalChoice
    candidates: Rows  # label -> per case {"case", "seconds", "worst_error_percent"}
    refinements: dict[str, results.Refinement]  # case name -> its study, when refined
    batched: results.BatchedModel | None = None  # the chosen solid legs as maps solve them

    @property
    def met(self) -> bool:
        return self.fem.met and self.analytical.met

    def summary(self) -> results.Fidelity:
        """results.json's top-level `fidelity` object."""
        opts = self.scene.analytical
        tol = self.scene.fidelity.tolerance_percent
        reason = f"{self.analytical.reason}; {self.fem.reason}."
        if not self.met:
            reason = ("The scene's tolerance is NOT met: " + reason)
        analytical = results.AnalyticalChoice(
            beam=opts.beam, shear=opts.shear, joint_ends=opts.joint_ends, legs=opts.legs,
            elements=opts.elements, platform_inertia=opts.platform_inertia,
            setting=self.analytical.setting, chosen=not self.scene.analytical_given,
            worst_error_percent=self.analytical.worst_error_percent,
            seconds_per_pose=self.analytical.seconds_per_pose, met=self.analytical.met)
        if self.batched is not None:
            analytical["batched"] = self.batched
        return results.Fidelity(
            modes=self.scene.fidelity.modes, tolerance_percent=tol, met=self.met,
            analytical=analytical,
            fem=results.FemChoice(
                mesh_size_mm=self.scene.fem.mesh_size * 1e3,
                chosen=not self.scene.fem_size_given,
                estimated_error_percent=self.fem.worst_error_percent,
                seconds_per_pose=_fem_seconds(self), met=self.fem.met),
            reason=reason,
            candidates=[results.Candidate(
                setting=label, worst_error_percent=max(r["worst_error_percent"] for r in rows),
                seconds_per_pose=sorted(r["seconds"] for r in rows)[len(rows) // 2])
                for label, rows in self.candidates.items()])


def _fem_seconds(fid: Fidelity) -> float | None:
    size = fid.scene.fem.mesh_size
    found = [(study, size_index(sizes_m(study), size)) for study in fid.refinements.values()]
    times = [study["seconds"][k] for study, k in found if k is not None]
    return float(np.median(times)) if times else None


def choose_fem(scene: Scene, case_names, cache: ResultCache, refine: bool,
               step=lambda text: None, workers: int = 1, scheduler: str | None = None
               ) -> tuple[Scene, FemChoice, dict[str, results.Refinement]]:
    """The FEM size (chosen, or the scene's checked), the scene at that size, and every
    case's refinement study (when refined)."""
    from solvers.refinement import fem_refinement

    tol = scene.fidelity.tolerance_percent
    refinements: dict[str, results.Refinement] = {}
    if refine:
        sizes = study_sizes(scene.fem_study.refinement,
                            scene.fem.mesh_size if scene.fem_size_given else None)
        step("FEM refinement studies")
        prefetch_fem(scene, [pose_geometry(scene.manipulator, scene.case(n).pose)
                             for n in case_names], sizes, cache, workers, scheduler)
        for name in case_names:
            step(f"{name}: FEM refinement study")
            case = scene.case(name)
            refinements[name] = fem_refinement(scene,
                                               pose_geometry(scene.manipulator, case.pose),
                                               cache, sizes)
        errors = [study["estimated_error_percent"] for study in refinements.values()]
        if scene.fem_size_given:
            k = size_index(sizes, scene.fem.mesh_size)
            assert k is not None  # study_sizes put it there
            worst = max(max(e[k]) for e in errors)
            fem = FemChoice(scene.fem.mesh_size, worst, worst <= FEM_ERROR_SHARE * tol,
                            f"h = {scene.fem.mesh_size * 1e3:.3g} mm as the scene asks, "
                            f"estimated error {worst:.3g} %")
        else:
            fem = choose_fem_size(list(sizes), errors, tol)
    else:
        size = scene.fem.mesh_size if scene.fem_size_given else scene.fem_study.ci_mesh_size
        fem = FemChoice(size, None, True,
                        f"h = {size * 1e3:.3g} mm without a refinement study (CI profile): "
                        "not chosen by its error; each case states a two-mesh estimate")
    return replace(scene, fem=scene.fem.with_size(fem.size)), fem, refinements


def candidate_settings(scene: Scene) -> Settings:
    """Every analytical setting the choice is made among (the scene's own first, if given)."""
    candidates = dict(speed_settings(scene))
    if scene.analytical_given:
        candidates = {SCENE_SETTING: scene.analytical} | candidates
    return candidates


def choose_model(scene: Scene, sized: Scene, fem: FemChoice, case_names, cache: ResultCache,
                 refinements: dict[str, results.Refinement], step=lambda text: None,
                 extra_rows: Places | None = None) -> Fidelity:
    """The analytical setting (chosen, or the scene's checked) over every case, plus
    `extra_rows` (label -> rows, e.g. the workspace study's worst pose)."""
    tol = scene.fidelity.tolerance_percent
    count = scene.fidelity.modes
    candidates = candidate_settings(scene)
    rows: Rows = {label: [] for label in candidates}
    for name in case_names:
        step(f"{name}: analytical candidates")
        case = sized.case(name)
        fem_result = fem_case(sized, pose_geometry(sized.manipulator, case.pose), cache,
                              fem.size)
        reference = (np.asarray(refinements[name]["extrapolated_hz"]) if name in refinements
                     else np.asarray(fem_result.record["frequencies_hz"][:count]))
        for label, opts in candidates.items():
            a = analytical_case(sized, case, opts)
            table = error_table(a, fem_result, count, None, reference)
            rows[label].append(Measured(
                case=name, seconds=seconds_per_pose(sized, case, opts, cache),
                worst_error_percent=max(abs(reference_error(r)) for r in table)))
    for label, extra in (extra_rows or {}).items():
        if label in rows:
            seconds = sorted(r["seconds"] for r in rows[label])[len(rows[label]) // 2]
            rows[label] += [Measured(**r, seconds=seconds) for r in extra]
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
    return Fidelity(chosen, fem, analytical, rows, refinements,
                    batched_model(chosen, [sized.case(n).pose for n in case_names]))


def batched_model(scene: Scene, poses: list[Pose]) -> results.BatchedModel | None:
    """The chosen solid legs as maps solve them (`analytical.batch_model.leg_reduction`), and
    their error against the per-pose model at `poses` (None: nothing reduced)."""
    from analytical.batch_model import assemble_batch, leg_reduction
    from analytical.batch_solve import frequencies
    from analytical.model import natural_frequencies
    from analytical.pose_batch import pose_batch

    m, options = scene.manipulator, scene.analytical
    chosen = leg_reduction(m, options)
    if not chosen.modes or not poses:
        return None
    count = min(options.modes, chosen.coordinates[1] - 1)
    batch = pose_batch(m, [p.height for p in poses], [p.azimuth for p in poses],
                       [p.tilt for p in poses])
    batched = frequencies(assemble_batch(m, batch, options), count)
    per_pose = np.array([natural_frequencies(m, p, replace(options, modes=count))
                         for p in poses])
    return results.BatchedModel(
        part_modes=chosen.modes, coordinates=chosen.coordinates[1],
        coordinates_kept=chosen.coordinates[0],
        error_percent=100.0 * float(np.max(np.abs(batched / per_pose - 1.0))),
        check_error_percent=100.0 * chosen.error, check_poses=chosen.poses)


def validate_fidelity(scene: Scene, case_names, cache: ResultCache, full: bool,
                      workers: int = 2, scheduler: str | None = None, console=None,
                      step=lambda text: None
                      ) -> tuple[Fidelity, results.WorkspaceValidation]:
    """The fidelity step of a run, with the workspace validation study in between: the FEM
    size from the cases' refinement studies; then the study over the workspace (every
    candidate at every pose); then the analytical setting over the cases AND each candidate's
    worst study pose (beam models are worst at compact poses, which two cases may miss)."""

    sized, fem, refinements = choose_fem(scene, case_names, cache, full, step, workers,
                                         scheduler)
    models = candidate_settings(scene) | {
        wv.PAPER_MODEL: model_variants(scene)[wv.PAPER_MODEL]}
    coarse = coarse_size(scene, fem.size)
    seconds = _fem_seconds_of(refinements, fem.size, coarse)

    def announce(plan):
        if console is not None and console.is_terminal and plan.to_compute:  # a failure
            # later is one line on stderr: progress is for a person watching, as the bar
            eta = "" if plan.estimated_seconds is None else \
                f", about {plan.estimated_seconds:.0f} s on {workers} worker(s)"
            console.print(f"workspace validation: {plan.to_compute} of {plan.total} poses to "
                          f"solve ({2 * plan.to_compute} FEM solves{eta})")

    study = wv.run_study(sized, models, cache, coarse, wv.FULL if full else wv.SMALL,
                         workers=workers, scheduler=scheduler, announce=announce,
                         progress=lambda done, total: step(f"workspace pose {done}/{total}"),
                         seconds_per_pose=seconds)
    extra = worst_pose_rows(scene, sized, study, cache, full, step, workers, scheduler)
    fidelity = choose_model(scene, sized, fem, case_names, cache, refinements, step, extra)
    return fidelity, wv.summarise(study, fidelity.analytical.setting)


def _fem_seconds_of(refinements: dict[str, results.Refinement], *sizes) -> float | None:
    """The median over the cases of the seconds of the FEM solves at `sizes` together; None
    when a study lacks one of the sizes."""
    total = []
    for study in refinements.values():
        where = [size_index(sizes_m(study), h) for h in sizes]
        if any(k is None for k in where):
            return None
        total.append(sum(study["seconds"][k] for k in where if k is not None))
    return float(np.median(total)) if total else None


def worst_pose_rows(scene: Scene, sized: Scene, study: results.ValidationSweep,
                    cache: ResultCache, full: bool, step=lambda text: None, workers: int = 1,
                    scheduler: str | None = None) -> Places:
    """Every candidate's error at the study's worst pose, against the FEM limit there.

    The worst pose is where the candidate that is best over the study (least largest error)
    is worst. In a full run the FEM is refined at that pose (the scene's sequence) and the
    candidates are compared with the extrapolated limit, like the cases; in the CI profile
    with the FEM of the study. A second row per candidate is its largest error over every
    study pose, so a candidate cannot be chosen on poses where it happens to be good."""
    from solvers.refinement import fem_refinement

    labels = list(candidate_settings(scene))
    ok = [p for p in study["poses"] if p["models"]]
    worst = None if not ok else wv.worst_pose(ok, min(labels, key=lambda lb: max(
        wv.worst_error((p["models"] or {})[lb]) for p in ok)))
    if worst is None:
        return {}
    pose = Pose(worst["height_mm"] * 1e-3, math.radians(worst["azimuth_deg"]),
                math.radians(worst["tilt_deg"]))
    case = wv._PoseCase(pose, "workspace worst pose")
    count = scene.fidelity.modes
    geometry = pose_geometry(sized.manipulator, pose)
    fem_result = fem_case(sized, geometry, cache, sized.fem.mesh_size)
    reference = np.asarray(fem_result.record["frequencies_hz"][:count])
    if full:
        step("workspace worst pose: FEM refinement study")
        sizes = study_sizes(scene.fem_study.refinement, sized.fem.mesh_size)
        prefetch_fem(sized, [geometry], sizes, cache, workers, scheduler)
        reference = np.asarray(fem_refinement(sized, geometry, cache, sizes)["extrapolated_hz"])
    where = (f"workspace worst pose (z = {worst['height_mm']:.0f} mm, tilt = "
             f"{worst['tilt_deg']:.1f} deg, {worst['kind']})")
    everywhere = f"workspace validation ({len(ok)} poses, each against its FEM limit)"
    out: Places = {}
    for label, opts in candidate_settings(scene).items():
        a = analytical_case(sized, case, opts)
        table = error_table(a, fem_result, count, None, reference)
        out[label] = [Where(case=where, worst_error_percent=max(
                          abs(reference_error(r)) for r in table)),
                      # and the candidate's own worst pose, which need not be the best's
                      Where(case=everywhere, worst_error_percent=max(
                          wv.worst_error((p["models"] or {})[label]) for p in ok))]
    return out
