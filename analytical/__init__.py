"""Analytical elastodynamic model of the 3-RPS manipulator by substructure synthesis
(Gong & Lou, Robotica 2023). Knows nothing of meshing, FEM or the pipeline."""
from .params import Manipulator, Material, ModelOptions, Pose
from .kinematics import PoseError, PoseGeometry, pose_geometry
from .model import natural_frequencies, analyse

__all__ = ["Manipulator", "Material", "ModelOptions", "Pose", "PoseError", "PoseGeometry",
           "pose_geometry", "natural_frequencies", "analyse"]
