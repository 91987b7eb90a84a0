"""3D solid finite-element reference of the 3-RPS manipulator: scikit-fem quadratic
tetrahedra on gmsh meshes of the legs (and optionally the platform), joints as exactly
eliminated multipoint constraints (paper Eqs. 10, 14-17), sparse shift-invert eigen solve,
and the discretisation error from mesh refinement with Richardson extrapolation.

    from fem_reference import FemOptions, FemResult, solve_pose, refinement_study, FemError
"""
from __future__ import annotations

from .convergence import RefinementStudy, richardson
from .model import (
    FemError,
    FemOptions,
    FemResult,
    FemRuntime,
    estimate_raw_dofs,
    solve_pose,
    with_size,
)

__all__ = ["FemError", "FemOptions", "FemResult", "FemRuntime", "RefinementStudy",
           "estimate_raw_dofs", "refinement_study", "richardson", "solve_pose"]


def refinement_study(manipulator, geometry, sizes, options: FemOptions,
                     runtime: FemRuntime | None = None) -> RefinementStudy:
    """Solve the pose at every size (coarse -> fine, m) and extrapolate every frequency.

    Raises FemError for fewer than three sizes or sizes that do not strictly decrease.
    """
    from meshing.bodies import pose_assembly

    from .convergence import sequence_problem, study_from_results

    sizes = [float(s) for s in sizes]
    why = sequence_problem(sizes)
    if why is not None:
        raise FemError(f"sizes = {sizes!r}: {why}")
    results = [solve_pose(manipulator, geometry, with_size(options, h), runtime or FemRuntime())
               for h in sizes]
    volume = pose_assembly(manipulator, geometry,
                           elastic_platform=options.platform == "elastic").volume
    return study_from_results(results, volume)
