"""The models' modes at a test pose, as fields a test node can be sampled from
(`placement.ModeField`): the analytical model at the scene's (or the run's chosen) settings,
and the solid FEM at the pose as an option."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from analytical.kinematics import PoseGeometry
from analytical.modal import leg_axis_displacements, leg_axis_twists, platform_motion
from analytical.model import Analysis, analyse
from analytical.params import Manipulator, ModelOptions, Pose
from analytical.substructure import model_coordinates

from .placement import ModeField


@dataclass(frozen=True)
class AnalyticalField:
    """One pose of the substructure model, read as a mode field."""

    analysis: Analysis

    @property
    def frequencies_hz(self) -> np.ndarray:
        return self.analysis.frequencies_hz

    @property
    def platform_motion(self) -> np.ndarray:
        return platform_motion(self.analysis.model, self.analysis.modal.shapes)

    def leg_axis_displacements(self, fractions) -> np.ndarray:
        a = self.analysis
        return leg_axis_displacements(a.model, a.geometry.leg_frames, a.modal.shapes, fractions)

    def leg_axis_twists(self, fractions) -> np.ndarray:
        a = self.analysis
        return leg_axis_twists(a.model, a.geometry.leg_frames, a.modal.shapes, fractions)


def model_modes(manipulator: Manipulator, options: ModelOptions, wanted: int) -> int:
    """The modes solved: `wanted`, at most the model's coordinates."""
    return min(wanted, model_coordinates(manipulator, options))


def analytical_field(manipulator: Manipulator, pose: Pose, geometry: PoseGeometry,
                     options: ModelOptions, modes: int) -> AnalyticalField:
    """The analytical model's lowest `modes` modes at this pose."""
    opts = replace(options, modes=model_modes(manipulator, options, modes))
    return AnalyticalField(analyse(manipulator, pose, opts, geometry=geometry))


def fem_field(scene, geometry: PoseGeometry, modes: int, cache=None) -> ModeField:
    """The scene's solid FEM at this pose (its default mesh size), `modes` modes and the
    pairing's extra ones; its meshes kept in `cache` (a runtime.cache.ResultCache) if given."""
    from fem_reference import solve_pose
    from solvers.compare import fem_options, fem_runtime

    options = fem_options(scene, modes=modes)
    return solve_pose(scene.manipulator, geometry, options, fem_runtime(scene, cache))
