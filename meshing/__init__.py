"""gmsh geometry and second-order tetrahedral meshes of the 3-RPS bodies for one pose, with a
content-keyed mesh cache. Uses the pose geometry of `analytical.kinematics`; knows no FEM."""
from .bodies import (
           Assembly,
           Cylinder,
           GeometryError,
           Plate,
           leg_cylinders,
           pose_assembly,
)
from .cache import MeshCache, cache_key, cached_mesh
from .geometry import GmshFailure, MeshSettings, build_mesh
from .mesh import MeshFormatError, SolidMesh

__all__ = ["Assembly", "Cylinder", "Plate", "GeometryError", "GmshFailure", "MeshSettings",
           "MeshCache", "MeshFormatError", "SolidMesh", "build_mesh", "cache_key", "cached_mesh",
           "leg_cylinders", "pose_assembly"]
