"""The validation run behind `make`: every case of a scene, both models, studies, into out/.

Outputs are built in a staging directory beside `out/` and swapped in whole only when
everything has been computed (`runtime.outdir`: one run per out/ at a time, one atomic swap),
so an interrupted or failed run leaves the previous outputs intact and nothing half-written,
and no file of an earlier run survives a successful one. Expensive results come from a
content-keyed cache, so a second run with nothing changed takes seconds.
"""
from __future__ import annotations

import datetime as dt
import hashlib
import math
import os
import platform
import shutil
import subprocess
import sys
from importlib import metadata
from pathlib import Path
from typing import Any, Callable, cast

import numpy as np
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

import results as schema
import studies
from analytical.architectures import actuation, leg_length_range, of
from analytical.kinematics import pose_geometry
from common.paths import display_path, distinct_stems, inside
from common.settings import edge_values, spec_of
from fem_reference.export import write_mode_collection
from results.tables import write_tables
from runtime.cache import ROOT, ResultCache
from runtime.outdir import staged_output
from scene import Case, Scene, load_scene
from solvers.compare import STATIONS, analytical_case, error_table, fem_case, with_cache_dir
from solvers.pairing import mac_matrix
from solvers.refinement import fem_refinement, size_index, study_sizes, two_mesh
from studies.fidelity import validate_fidelity
from studies.reachable import check as check_workspace

from .preflight import check_sizes, check_uncertainty

PROJECT = "rps-elastodynamics"


def environment() -> schema.Environment:
    versions: dict[str, str | None] = {}
    for dist in ("numpy", "scipy", "gmsh", "scikit-fem", "meshio", "pyvista", "matplotlib",
                 "jinja2", "weasyprint"):
        try:
            versions[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            versions[dist] = None
    try:
        version = metadata.version(PROJECT)
    except metadata.PackageNotFoundError:
        version = None
    return schema.Environment(
        project_version=version,
        git_commit=git_commit(),
        python=sys.version.split()[0],
        platform=platform.platform(),
        machine=platform.machine(),
        cpu_count=os.cpu_count(),
        date=dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        versions=versions,
    )


def git_commit() -> str | None:
    """The commit of the source tree the run used, marked when it had local changes; None
    outside a git checkout."""
    def git(*args) -> str:
        return subprocess.run(["git", "-C", str(ROOT), *args], capture_output=True, text=True,
                              check=True, timeout=20).stdout.strip()
    try:
        commit = git("rev-parse", "HEAD")
        changed = git("status", "--porcelain", "--untracked-files=no")
    except (OSError, subprocess.SubprocessError):
        return None
    return commit + (" + local changes" if changed else "")


def scene_summary(scene: Scene, path: str) -> schema.SceneSummary:
    m = scene.manipulator
    act = actuation(m)
    return schema.SceneSummary(
        name=scene.name,
        path=display_path(path),
        sha256=hashlib.sha256(Path(path).read_bytes()).hexdigest(),
        # every declared value in its edge unit, converted by its own declaration (the record's
        # keys are the scene's: checked against the schema when written)
        manipulator=cast(schema.Manipulator, {
            **edge_values(m, ("base_radius", "platform_radius", "leg_diameter",
                              "platform_thickness", "platform_shape", "leg_angles",
                              "architecture", "s_joint_max", "r_joint_max", "base_joint",
                              "platform_joint")),
            "actuator": act.quantity,
            "actuator_range_mm": [edge(m, "actuator_min", x) for x in (act.low, act.high)],
            "leg_length_range_mm": [edge(m, "leg_length", x) for x in leg_length_range(m)],
            "rail_angle_deg": edge(m, "rail_angle", m.rail_angle) if of(m).rails else None,
            **edge_values(m.material), "poisson_ratio": m.material.poisson_ratio,
            "payload": edge_values(m.payload), "leg": edge_values(m.leg),
            "stiffness": edge_values(m.stiffness)}),
        analytical=schema.AnalyticalSettings(
            elements=scene.analytical.elements, beam=scene.analytical.beam,
            platform_inertia=scene.analytical.platform_inertia, modes=scene.analytical.modes),
        fem=schema.FemSettings(
            mesh_size_mm=scene.fem.mesh_size * 1e3,
            refinement_mm=[s * 1e3 for s in scene.fem_study.refinement],
            rim_factor=scene.fem.mesh.rim_factor, rim_zone_mm=scene.fem.mesh.rim_zone * 1e3,
            platform=scene.fem.platform, coupling=scene.fem.coupling, legs=scene.fem.legs),
        calibrated=[] if scene.calibrated_height is None else [schema.Calibrated(
            name="platform height z", value=f"{scene.calibrated_height * 1e3:.1f} mm",
            reason=" ".join(scene.calibration_reason.split()))] + (
            [schema.Calibrated(name="platform shape", value=m.platform_shape,
                               reason=" ".join(scene.platform_shape_reason.split()))]
            if scene.platform_shape_reason else []),
        warnings=list(scene.warnings),
    )


def edge(obj, name: str, value: float) -> float:
    """`value` (SI) in the edge unit of `obj`'s declared setting `name`."""
    return spec_of(obj, name).edge(value)


def pose_summary(scene: Scene, case: Case) -> schema.Pose:
    g = pose_geometry(scene.manipulator, case.pose)
    return schema.Pose(
        height_mm=case.pose.height * 1e3,
        height_origin=case.height_origin,
        azimuth_deg=math.degrees(case.pose.azimuth),
        tilt_deg=math.degrees(case.pose.tilt),
        centre_mm=(g.platform_centre * 1e3).tolist(),
        base_points_mm=(g.base_points * 1e3).tolist(),
        platform_points_mm=(g.platform_points * 1e3).tolist(),
        leg_lengths_mm=(g.leg_lengths * 1e3).tolist(),
        actuation_mm=(g.actuation * 1e3).tolist(),
        s_joint_angles_deg=np.degrees(g.s_joint_angles).tolist(),
        r_joint_angles_deg=np.degrees(g.r_joint_angles).tolist(),
    )


def paper_rows(case: Case) -> schema.Paper | None:
    if case.paper_theory_hz is None and case.paper_fea_hz is None:
        return None
    recomputed = None
    if case.paper_fea_hz and case.paper_theory_hz:
        recomputed = [100 * (t / f - 1) for t, f in zip(case.paper_theory_hz, case.paper_fea_hz)]
    notes = []
    for k, (printed, ours) in enumerate(zip(case.paper_error_percent or (), recomputed or ())):
        # printed values carry two decimals; inputs carry two decimals in Hz
        if abs(printed - ours) > 0.015:
            notes.append(f"f{k + 1}: printed {printed:.2f} %, (theory/FEA - 1) gives "
                         f"{ours:.2f} %")
    return schema.Paper(
        fea_hz=None if case.paper_fea_hz is None else list(case.paper_fea_hz),
        theory_hz=None if case.paper_theory_hz is None else list(case.paper_theory_hz),
        error_percent=recomputed,
        printed_error_percent=(None if case.paper_error_percent is None
                               else list(case.paper_error_percent)),
        printed_error_note=("The paper's printed errors do not all follow from its own "
                            "frequencies: " + "; ".join(notes) + ".") if notes else None)


def run_case(ctx: studies.Context, case: Case, refinement: tuple[float, ...] | None,
             profile: schema.Profile, progress=None) -> tuple[schema.Case, Path | None]:
    """Everything the report needs about one case (a results.Case), and the FEM's mode file:
    both models at the case's pose, the FEM's refinement study (when `refinement` sizes are
    given), and the registered case studies of `profile`."""
    scene, cache, mesh_size = ctx.scene, ctx.cache, ctx.scene.fem.mesh_size
    count = scene.analytical.modes
    geometry = pose_geometry(scene.manipulator, case.pose)
    step = (lambda text: progress(f"{case.name}: {text}")) if progress else (lambda text: None)

    step("FEM reference")
    fem = fem_case(scene, geometry, cache, mesh_size)
    fem_error = fem_gci = reference = None
    refinement_study = None
    if refinement:
        step("FEM refinement study")
        # the run's own size is one of the study's (as the fidelity step's), so its error is
        # the study's statement for it
        sizes = study_sizes(refinement, mesh_size)
        refinement_study = fem_refinement(scene, geometry, cache, sizes)
        reference = np.asarray(refinement_study["extrapolated_hz"])
        k = size_index(sizes, mesh_size)
        assert k is not None  # study_sizes put it there
        fem_error = np.asarray(refinement_study["estimated_error_percent"][k])
        fem_gci = refinement_study["gci_percent"][k]
    else:  # no refinement study (the CI profile): the run's size and the next coarser one
        step("FEM at a coarser size")
        both = two_mesh(scene, geometry, cache, mesh_size, count)
        fem_error, fem_gci = np.asarray(both.estimated_error_percent), both.gci_percent
        reference = np.asarray(both.limit_hz)

    step("analytical models")
    analytical = analytical_case(scene, case, scene.analytical)
    core = schema.CaseCore(
        name=case.name,
        description=case.description,
        pose=pose_summary(scene, case),
        analytical=schema.CaseAnalytical(
            **analytical.reported(count), leg_axis_stations=STATIONS.tolist(),
            leg_axis_shapes=analytical.leg_axis_shapes(count)),
        fem=schema.CaseFem(**fem.reported(count), vtu=None, pvd=None),  # set when written
        pairs=error_table(analytical, fem, count, fem_error, reference),
        paper=paper_rows(case),
        mac_matrix=mac_matrix(analytical.station_shapes[:, :count],
                              fem.station_shapes[:, :count]).tolist(),
        fem_estimated_error_percent=None if fem_error is None else fem_error.tolist(),
        fem_gci_percent=fem_gci,
        fem_reference_hz=None if reference is None else reference.tolist(),
        fem_refinement=refinement_study,
    )
    held = schema.stub(studies.RECORDS, "case")  # every case study's record, empty until run
    given = studies.CaseContext(case, geometry, fem, fem_error, reference, refinement_study, step)
    for study in studies.at("case", profile):
        held[study.key] = study.compute(ctx, given)
    # the registry's keys beside the core: checked against the schema when written
    return cast(schema.Case, {**core, **held}), fem.vtu


Report = Callable[[Path, Path, Path, int], object]  # (results.json, folder, cache dir, workers)


def validate(scene_path: str, out: Path, cache_dir: Path, profile: schema.Profile = "full",
             report: Report | None = None, workers: int | None = None,
             scheduler: str | None = None) -> schema.Results:
    """Validate a scene into `out` (swapped in whole). `report`, when given, renders the report
    into the staging folder before the swap (the command line passes
    `reports.build.render_report`: the run itself never imports the report)."""
    scene = load_scene(scene_path)
    case_names = list(scene.cases) if profile == "full" else list(scene.ci_cases)
    # every case and the workspace the studies take their poses from, before any expensive work
    reachable_workspace = check_workspace(scene, profile)
    check_sizes(scene, profile)  # every mesh the run plans, against the DOF and memory guard
    check_uncertainty(scene, profile)  # the uncertain inputs' ends as machines
    cache = ResultCache(cache_dir)
    scene = with_cache_dir(scene, cache.directory)  # solid end zones beside the other entries
    workers = workers or min(os.cpu_count() or 1, 8)
    console = Console(stderr=True)
    summary, started = scene_summary(scene, scene_path), environment()  # at the run's start
    # every registered scene study's record, empty until it runs (the registry's stub)
    held: dict[str, Any] = {**schema.stub(studies.RECORDS, "scene"),
                            "reachable_workspace": reachable_workspace}
    cases: list[schema.Case] = []
    with staged_output(out) as stage:  # locked for the run; swapped in whole at the end
        mode_files: dict[str, Path | None] = {}
        # on a terminal only, and transient: a failure is one line on stderr, nothing before
        with Progress(TextColumn("{task.description}"), BarColumn(), TimeElapsedColumn(),
                      console=console, transient=True, disable=not console.is_terminal) as bar:
            task = bar.add_task("validation", total=len(case_names) + 1)
            fidelity, workspace = validate_fidelity(
                scene, case_names, cache, full=profile == "full", workers=workers,
                scheduler=scheduler, console=console,
                step=lambda text: bar.update(task, description=f"fidelity: {text}"))
            scene = fidelity.scene
            held["workspace_validation"] = workspace
            bar.advance(task)
            ctx = studies.Context(scene, cache, workers, scheduler, fidelity.analytical.setting)
            geometries = [pose_geometry(scene.manipulator, scene.case(n).pose)
                          for n in case_names]
            for study in studies.at("case", profile):  # every case's solves on the workers
                if study.prefetch is not None:
                    study.prefetch(ctx, geometries)
            for name in case_names:
                entry, mode_files[name] = run_case(
                    ctx, scene.case(name),
                    scene.fem_study.refinement if profile == "full" else None, profile,
                    progress=lambda text: bar.update(task, description=text))
                cases.append(entry)
                bar.advance(task)
        for study in studies.at("scene", profile):
            held[study.key] = study.compute(ctx)
        results = _write_outputs(schema.Results(
            schema=schema.SCHEMA_VERSION, profile=profile, scene=summary,
            environment=started, fidelity=fidelity.summary(), cases=cases,
            studies=cast(schema.Studies, held),  # the registry's keys: checked when written
            fixture_note=None), mode_files, stage)
        if report is not None:
            from common.worker import stoppable
            stoppable(report, stage / "results.json", stage,  # stops at once on a signal
                      cache.directory, workers)
    console.print(f"fidelity: {results['fidelity']['reason']}", soft_wrap=True)
    console.print(f"wrote {out}/results.json" + (", report.html, report.pdf"
                                                  if report else ""), soft_wrap=True)
    return results


def _write_outputs(results: schema.Results, mode_files: dict[str, Path | None],
                   stage: Path) -> schema.Results:
    """Copy the FEM mode files in, check the results against the schema and write them with
    their tables; the checked results are returned. Case names become file names only through
    `common.paths` (their stems, and every path checked to stay inside the staging folder)."""
    stems = distinct_stems((case["name"] for case in results["cases"]), "case name")
    modes = inside(stage, "modes")
    modes.mkdir(exist_ok=True)
    for case in results["cases"]:
        source = mode_files.get(case["name"])
        if source is not None and source.is_file():
            stem = stems[case["name"]]
            target = inside(stage, "modes", f"{stem}_fem.vtu")
            # write_mode_collection writes these two beside the VTU
            inside(stage, "modes", f"{stem}_fem.pvd")
            inside(stage, "modes", f"{stem}_fem_modes")
            shutil.copyfile(source, target)
            case["fem"]["vtu"] = target.relative_to(stage).as_posix()
            case["fem"]["pvd"] = write_mode_collection(target).relative_to(stage).as_posix()
    results = schema.validated(results, studies.RECORDS)
    inside(stage, "results.json").write_text(schema.dumps(results))
    write_tables(results, stage, studies.RECORDS)
    return results
