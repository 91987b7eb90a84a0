"""The rigid platform's 6x6 mass at o, integrated over its own meshed plate.

The FEM is the referee of the analytical model, so it does not take the plate's mass and inertia
from the analytical side (nor from a shared closed form): the plate is meshed on its own (gmsh,
10-node curved tetrahedra, the same `meshing` machinery as the legs) in its own frame (centre o
at the origin, normal along z), and the rigid-body mass (the paper's Eqs. 7-9, written for a
body of any shape) is integrated over its elements with the P2 basis's quadrature (scikit-fem,
|det J| w_q on the curved elements):

    m = int rho dV,   S = int rho r dV,   J = int rho (|r|^2 I - r r^T) dV,   r = x - o,
    M = [[m I, -[S x]], [[S x], J]]   on (translation of o, rotation),

then turned into base coordinates, diag(R, R) M diag(R, R)^T. S vanishes for a plate centred
on o (to quadrature accuracy) but is kept: the matrix is the plate's, not an assumed symmetry.
"""
from __future__ import annotations

import functools
from typing import cast

import numpy as np

from common.rigid_body import rigid_body_mass
from meshing.bodies import Assembly, Plate, Point3
from meshing.geometry import MeshSettings, build_mesh

from .discretisation import discretise


def local_plate(plate: Plate, rotation: np.ndarray) -> Plate:
    """The same plate in its own frame: centre at the origin, normal along z."""
    rot = np.asarray(rotation, float)
    o = np.asarray(plate.centre, float)
    # rounded: one key for every pose (a 3x3 rotation of 3D corners: 3D corners)
    corners: tuple[Point3, ...] = () if plate.shape == "disk" else tuple(
        cast(Point3, tuple(float(round(v, 12)) + 0.0 for v in rot.T @ (np.asarray(c) - o)))
        for c in plate.corners)
    return Plate(plate.name, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), plate.thickness, plate.shape,
                 plate.radius, corners)


def meshed_plate_mass(plate: Plate, rotation: np.ndarray, density: float,
                      size: float) -> np.ndarray:
    """6x6 mass of the rigid plate about its centre o in base coordinates (see the module
    docstring); the plate is meshed in its own frame at element size `size` (m)."""
    rot = np.asarray(rotation, float)
    r6 = np.zeros((6, 6))
    r6[:3, :3] = r6[3:, 3:] = rot
    return r6 @ body_frame_mass(local_plate(plate, rot), float(density), float(size)) @ r6.T


@functools.lru_cache(maxsize=16)
def body_frame_mass(local: Plate, density: float, size: float) -> np.ndarray:
    """6x6 mass of a plate given in its own frame, integrated over its mesh (read-only).

    A pure function of its arguments, remembered per process: every pose of a scene has the
    same plate in its own frame, so it is meshed once (~0.1 s), not once per pose; it is not
    written to the mesh cache.
    """
    solid = build_mesh(Assembly((), local), MeshSettings(size=size, rim_factor=1.0,
                                                         rim_zone=0.0))
    basis = discretise(solid).basis
    x = np.asarray(basis.global_coordinates())  # (3, ne, nq)
    out = rigid_body_mass(x.reshape(3, -1).T, density * basis.dx.ravel())
    out.setflags(write=False)
    return out
