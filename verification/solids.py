"""3D benchmark solids meshed the project's way: gmsh (OpenCASCADE) with the project's pinned
options (`meshing.geometry.PINNED_OPTIONS`: Frontal-Delaunay, Netgen optimiser, second order,
one thread), 10-node tetrahedra with geometry-following mid-edge nodes, read into a
`meshing.SolidMesh` and from there through the project's own `discretise`,
`stiffness_and_mass` and `lowest_modes`.

Two bodies: the NAFEMS FV52 plate (two boxes, the lower and the upper half of the thickness,
fragmented so that the mid-plane and its four edge lines are mesh faces and edges) and the
NAFEMS FV41 hollow cylinder. A uniform size h everywhere (MeshSizeMin = MeshSizeMax = h).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from fem_reference.assembly import Material, stiffness_and_mass
from fem_reference.discretisation import Discretisation, discretise
from fem_reference.eigen import lowest_modes
from meshing.geometry import GMSH_TETRA10_TO_MESHIO, GmshFailure, gmsh_session
from meshing.mesh import SolidMesh


def _read_tets(gmsh, body: str) -> SolidMesh:
    """The 10-node tetrahedra of the current gmsh model as one body (unused nodes dropped)."""
    model = gmsh.model
    tags, coords, _ = model.mesh.getNodes()
    tags = np.asarray(tags, np.int64)
    points = np.asarray(coords, float).reshape(-1, 3)
    index = np.full(int(tags.max()) + 1, -1, np.int64)
    index[tags] = np.arange(len(tags))
    types, etags, enodes = model.mesh.getElements(3)
    blocks = [np.asarray(n_, np.int64).reshape(-1, 10) for ty, n_ in zip(types, enodes)
              if ty == 11]
    if not blocks:
        raise GmshFailure(f"{body}: gmsh produced no 10-node tetrahedra")
    tets = index[np.concatenate(blocks)][:, GMSH_TETRA10_TO_MESHIO]
    all_tags = np.concatenate([np.asarray(t_, np.int64) for ty, t_ in zip(types, etags)
                               if ty == 11])
    quality = float(np.min(model.mesh.getElementQualities(all_tags.tolist(), "minSJ")))
    used, inverse = np.unique(tets, return_inverse=True)
    return SolidMesh(points[used], inverse.reshape(tets.shape), np.zeros(len(tets), np.int32),
                     (body,), {}, {"min_scaled_jacobian": quality})


def plate_mesh(a: float, b: float, t: float, size: float) -> SolidMesh:
    """The plate [0, a] x [0, b] x [-t/2, t/2] (m) as two boxes fragmented at z = 0 (one body,
    conforming at the mid-plane), uniform size h = `size`."""
    with gmsh_session({"Mesh.MeshSizeMax": size, "Mesh.MeshSizeMin": size}) as gmsh:
        gmsh.model.add("plate")
        occ = gmsh.model.occ
        lower = occ.addBox(0, 0, -t / 2, a, b, t / 2)
        upper = occ.addBox(0, 0, 0, a, b, t / 2)
        occ.fragment([(3, lower)], [(3, upper)])
        occ.synchronize()
        gmsh.model.mesh.generate(3)
        return _read_tets(gmsh, "plate")


def tube_mesh(inner: float, outer: float, length: float, size: float) -> SolidMesh:
    """The hollow cylinder r in [inner, outer], z in [0, length] (m), uniform size h."""
    with gmsh_session({"Mesh.MeshSizeMax": size, "Mesh.MeshSizeMin": size}) as gmsh:
        gmsh.model.add("tube")
        occ = gmsh.model.occ
        out, _ = occ.cut([(3, occ.addCylinder(0, 0, 0, 0, 0, length, outer))],
                         [(3, occ.addCylinder(0, 0, 0, 0, 0, length, inner))])
        if len([d for d, _ in out if d == 3]) != 1:
            raise GmshFailure("tube: the cut did not give one volume")
        occ.synchronize()
        gmsh.model.mesh.generate(3)
        return _read_tets(gmsh, "tube")


@dataclass
class SolidModes:
    """The lowest modes of a meshed solid: frequencies (Hz, ascending), the vectors on all
    3 n_nodes dofs (3 s + c; held dofs zero), the node positions, the free dof count and the
    consistent mass matrix (for energy fractions)."""

    hz: np.ndarray
    vectors: np.ndarray
    node_xyz: np.ndarray
    dofs: int
    mass: sp.csr_matrix
    min_scaled_jacobian: float


def solve_solid(mesh: SolidMesh, material: Material, n_modes: int,
                held=None) -> SolidModes:
    """Assemble K, M of `mesh` (P2, `stiffness_and_mass`), drop the held dofs (`held(disc)`
    -> dof indices, or None for a free body) and return the `n_modes` lowest modes."""
    disc: Discretisation = discretise(mesh)
    k, m = stiffness_and_mass(disc, material)
    n = disc.n_dofs
    fixed = np.unique(np.asarray(held(disc), np.int64)) if held else np.zeros(0, np.int64)
    free = np.setdiff1d(np.arange(n), fixed)
    modes = lowest_modes(k[free][:, free], m[free][:, free], n_modes)
    vectors = np.zeros((n, n_modes))
    vectors[free] = modes.vectors
    return SolidModes(modes.frequencies_hz, vectors, disc.node_xyz, len(free), m,
                      float(mesh.info["min_scaled_jacobian"]))


def mid_plane_edges(a: float, b: float, tol: float = 1e-9):
    """A `held` function: u_z of the nodes on the four edge lines of the mid-plane z = 0 of the
    plate [0, a] x [0, b] (code_aster SDLS502's BORDS)."""
    def held(disc: Discretisation) -> np.ndarray:
        x, y, z = disc.node_xyz.T
        on_edge = ((np.abs(x) < tol) | (np.abs(x - a) < tol) | (np.abs(y) < tol)
                   | (np.abs(y - b) < tol))
        nodes = np.flatnonzero(on_edge & (np.abs(z) < tol))
        return 3 * nodes + 2
    return held
