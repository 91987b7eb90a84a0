"""Analytical elastodynamic model of the 3-RPS manipulator by substructure synthesis
(Gong & Lou, Robotica 2023). Knows nothing of meshing, FEM or the pipeline."""
from .kinematics import PoseError, PoseGeometry, pose_geometry
from .model import analyse, natural_frequencies
from .params import Manipulator, Material, ModelOptions, Pose

__all__ = ["Manipulator", "Material", "ModelOptions", "Pose", "PoseError", "PoseGeometry",
           "pose_geometry", "natural_frequencies", "analyse"]
