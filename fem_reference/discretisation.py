"""From a `meshing.SolidMesh` to scikit-fem: the quadratic (curved, isoparametric) tetrahedral
mesh, the scalar P2 basis with its quadrature, and the node/dof numbering.

Degrees of freedom: the displacement component c (x, y, z) at scalar P2 node s is dof 3 s + c
(node-major), with s in scikit-fem's P2 numbering (vertices, then edges). `node_xyz[s]` is the
node position, `node_body[s]` its body (bodies share no node), `face_nodes[name]` the nodes of a
joint face and `face_triangles[name]` its triangle6 connectivity (for surface integrals).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from skfem import Basis, ElementTetP2, MeshTet2

from meshing.mesh import SolidMesh


@dataclass
class Discretisation:
    mesh: MeshTet2
    basis: Basis  # scalar P2 on the curved mesh
    node_xyz: np.ndarray  # (n_nodes, 3)
    node_body: np.ndarray  # (n_nodes,)
    bodies: tuple[str, ...]
    face_nodes: dict[str, np.ndarray]
    face_triangles: dict[str, np.ndarray]
    tet_body: np.ndarray  # (n_elements,)

    @property
    def n_nodes(self) -> int:
        return int(self.node_xyz.shape[0])

    @property
    def n_dofs(self) -> int:
        return 3 * self.n_nodes

    def body_nodes(self, name: str) -> np.ndarray:
        return np.flatnonzero(self.node_body == self.bodies.index(name))


def discretise(solid: SolidMesh, intorder: int = 4) -> Discretisation:
    """Build the skfem mesh and scalar P2 basis. `intorder` 4 integrates the P2 mass exactly on
    straight elements and the stiffness with margin on the curved ones next to the surface."""
    # meshio/VTK tetra10 edge order (01, 12, 02, 03, 13, 23) is scikit-fem's MeshTet2 order
    mesh = MeshTet2(np.ascontiguousarray(solid.points.T), np.ascontiguousarray(solid.tets.T))
    scalar_dofs = mesh.dofs.element_dofs  # (10, ne), skfem numbering
    node_to_s = np.full(solid.n_nodes, -1, np.int64)
    node_to_s[solid.tets.T.ravel()] = scalar_dofs.ravel()
    basis = Basis(mesh, ElementTetP2(), intorder=intorder)
    n_scalar = mesh.nvertices + mesh.nedges
    node_xyz = np.empty((n_scalar, 3))
    known = node_to_s >= 0
    node_xyz[node_to_s[known]] = solid.points[known]
    node_body = np.full(n_scalar, -1, np.int64)
    node_body[scalar_dofs] = solid.tet_body[None, :]
    face_triangles = {name: node_to_s[tri] for name, tri in solid.faces.items()}
    face_nodes = {name: np.unique(tri) for name, tri in face_triangles.items()}
    return Discretisation(mesh, basis, node_xyz, node_body, solid.bodies, face_nodes,
                          face_triangles, solid.tet_body)
