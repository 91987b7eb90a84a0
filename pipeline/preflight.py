"""What a validation run can check before its first expensive step, beyond the scene's values.

`check_sizes` asks the FEM's DOF and memory guard (`fem_reference.guard.check_mesh_size`, a
second or so) about every mesh size the run will solve with: in the full profile the scene's
refinement sequence (and its mesh_size_mm, if given), in the CI profile the CI mesh (or the
given mesh_size_mm), each at every case's pose and at the level pose at the top of the level
band (the longest legs the workspace study meets). A size the guard refuses is named by the
scene key that set it (`fem.ci_mesh_size_mm = 0.2: ...`), or as the default it came from.
"""
from __future__ import annotations

from analytical.kinematics import pose_geometry
from analytical.params import Pose
from analytical.reach import WorkspaceError, level_band
from common.errors import InputError
from fem_reference.model import FemError, check_mesh_size
from meshing.bodies import pose_assembly
from scene import Scene
from scene.load import GEOMETRY_DEFAULTS_TEXT
from solvers.compare import fem_options, fem_runtime


def planned_sizes(scene: Scene, profile: str) -> list[tuple[float, str]]:
    """(size, the scene key and value that set it) of every mesh the run solves with, finest
    first."""
    given = scene.raw.get("fem", {})

    def named(key: str, size: float) -> str:
        value = f"{size * 1e3:g}" if key in given else \
            f"{size * 1e3:g} (its default, {GEOMETRY_DEFAULTS_TEXT[key.removesuffix('_mm')]})"
        return f"fem.{key} = {value}"

    sizes = []
    if scene.fem_size_given:
        sizes.append((scene.fem.mesh_size, f"fem.mesh_size_mm = {scene.fem.mesh_size * 1e3:g}"))
    if profile == "full":
        shown = [float(f"{h * 1e3:.6g}") for h in scene.fem_study.refinement]
        sizes += [(h, f"fem.refinement_mm = {shown}" + ("" if "refinement_mm" in given else
                                                        " (its default)")
                   + f", its {h * 1e3:g} mm mesh") for h in scene.fem_study.refinement]
    elif not scene.fem_size_given:
        sizes.append((scene.fem_study.ci_mesh_size,
                      named("ci_mesh_size_mm", scene.fem_study.ci_mesh_size)))
    return sorted(sizes)


def check_sizes(scene: Scene, profile: str) -> None:
    """InputError naming the scene key of the first planned mesh the guard refuses."""
    m = scene.manipulator
    poses = [case.pose for case in scene.cases.values()]
    try:
        poses.append(Pose(level_band(m).high))
    except WorkspaceError:
        pass  # the workspace check names it
    geometries = [pose_geometry(m, pose) for pose in poses]
    runtime = fem_runtime(scene)
    for size, key in planned_sizes(scene, profile):
        options = fem_options(scene, size)
        for geometry in geometries:
            assembly = pose_assembly(m, geometry, elastic_platform=options.platform == "elastic")
            try:
                check_mesh_size(assembly, options, runtime)
            except FemError as exc:
                text = str(exc)
                tail = text.split(": ", 1)[1] if text.startswith("mesh_size_mm = ") else text
                raise InputError(f"{key}: {tail}") from None


def check_uncertainty(scene: Scene, profile: str) -> None:
    """The scene's uncertain inputs at their two ends as whole machines (the plausibility
    rules), before any work: a full run propagates them (studies/uncertainty.py)."""
    if scene.uncertainty is None or profile != "full":
        return
    from scene import parse_scene
    from scene.uncertainty import check_ends

    check_ends(scene.uncertainty, scene.raw, scene.path, parse_scene)
