"""One call from parameters and pose to natural frequencies: kinematics, synthesis, modal."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kinematics import PoseGeometry, pose_geometry
from .modal import ModalResult, solve_modes
from .params import Manipulator, ModelOptions, Pose
from .substructure import SubstructureModel, assemble


@dataclass(frozen=True)
class Analysis:
    geometry: PoseGeometry
    model: SubstructureModel
    modal: ModalResult

    @property
    def frequencies_hz(self) -> np.ndarray:
        return self.modal.frequencies_hz


def analyse(manipulator: Manipulator, pose: Pose, options: ModelOptions = ModelOptions(),
            geometry: PoseGeometry | None = None) -> Analysis:
    """Natural frequencies and modes of one pose; `geometry` overrides the inverse kinematics."""
    geom = pose_geometry(manipulator, pose) if geometry is None else geometry
    model = assemble(manipulator, geom, options)
    return Analysis(geom, model, solve_modes(model, options.modes))


def natural_frequencies(manipulator: Manipulator, pose: Pose,
                        options: ModelOptions = ModelOptions()) -> np.ndarray:
    """The lowest `options.modes` natural frequencies in Hz, ascending."""
    return analyse(manipulator, pose, options).frequencies_hz
