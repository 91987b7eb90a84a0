"""The solid end zone of a leg, reduced to a 12 x 12 superelement (static condensation).

A leg's end zone is a solid circular cylinder of diameter d and length l_z, meshed with the FEM
reference's own machinery (gmsh P2 tetrahedra, scikit-fem stiffness and consistent mass):

- the joint face (x = 0) is tied to the joint point at its centre as the FEM ties it
  (`fem_reference.constraints`): "rigid", every face node follows the point rigidly (RBE2);
  "distributing", the point moves as the face does on average (the L2 projection of the face
  displacement onto rigid motions, RBE3-like), the face free to warp;
- the interface section (x = l_z), where the Timoshenko middle of the leg begins, is tied to a
  beam node by the same distributing projection, so the coupling adds no stiffening of its own:
  the section keeps its warping and Poisson contraction, only its mean rigid motion is the beam
  node's (the measurement in joint_ends/README.md compares it with a rigid interface);
- static condensation (Guyan) onto the twelve coordinates [t_joint, theta_joint, t_interface,
  theta_interface]: the constraint modes Psi minimise the strain energy for each unit master
  motion (a saddle-point solve with the coupling equations as constraints), and
  K = Psi^T K_solid Psi, M = Psi^T M_solid Psi. The zone's first fixed-interface mode
  (`ZoneModel.first_interior_hz`) says how far below it the condensed mass is exact.

A hollow part's zone is a tube, and there the distributing interface is a model of its own
with a measured cost: the interface section of a thin wall is free to ovalise (its harmonics
n >= 2 meet no beam), so the zone is softer than the tube it ends. Measured, a clamped 100/70 mm
steel tube 0.6 m long (harmonic solid 233.12 Hz): beam + zone -0.17 % (-0.13 % with a zone of
one diameter), beam + zone with a rigid interface +0.70 %; a 0.3 m one -0.99 % and +1.5 %; a
solid 100 mm cylinder -0.002 %. On scenes/actuator-legs.toml the beam-and-zone models stay
within 0.12 % of the FEM (issue 23's note).

The local frame: x along the leg axis from the joint towards the middle, y and z across. The
continuum is invariant under rotations about x and under the mirror y -> -y; the mesh is not
quite, so the condensed matrices are averaged over the dihedral group D4 of those symmetries
(exact for the second-rank blocks of a 12 x 12 superelement: a block invariant under the
quarter turn is invariant under every turn), which removes the mesh's directional noise and
makes the superelement exactly independent of how the leg is turned about its axis.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from common.errors import InputError
from common.joints import COUPLINGS
from common.rigid_body import skew
from common.settings import check_settings, setting

JOINT_FACE, INTERFACE = "zone_base", "zone_top"


@dataclass(frozen=True)
class ZoneMesh:
    """How finely an end zone is meshed, in leg diameters d (chosen by the convergence study in
    joint_ends/README.md)."""

    size: float = setting(0.125, doc="global element size, in leg diameters", minimum=0.0,
                          exclusive_minimum=True, maximum=1.0)
    rim_factor: float = setting(0.25, doc="element size at the face rims, as a fraction of "
                                "the global size", minimum=0.0, exclusive_minimum=True,
                                maximum=1.0)
    rim_zone: float = setting(0.2, doc="distance over which the size grows back from the "
                              "rims, in leg diameters", minimum=0.0)

    def __post_init__(self):
        check_settings(self)


class Solid(NamedTuple):
    """The zone's isotropic material as the FEM assembly reads it
    (`fem_reference.assembly.Material`), SI."""

    youngs_modulus: float  # Pa
    shear_modulus: float  # Pa
    density: float  # kg/m^3


@dataclass(frozen=True)
class ZoneModel:
    """The condensed end zone in its local frame (x from the joint towards the middle)."""

    stiffness: np.ndarray  # (12, 12) on [t_J, theta_J, t_I, theta_I], SI
    mass: np.ndarray  # (12, 12)
    length: float  # l_z, m
    raw_dofs: int  # dofs of the solid sub-model
    first_interior_hz: float  # lowest mode with both ends held (Craig-Bampton's first)


def cylinder_mesh(diameter: float, length: float, mesh: ZoneMesh, inner_diameter: float = 0.0):
    """The solid cylinder (0, 0, 0) -> (length, 0, 0) of this diameter (a tube with a bore of
    `inner_diameter`), meshed (faces JOINT_FACE at x = 0 and INTERFACE at x = length)."""
    from meshing.bodies import Assembly, Cylinder
    from meshing.geometry import MeshSettings, build_mesh

    if inner_diameter:
        cylinder = Cylinder("zone", (0.0, 0.0, 0.0), (float(length), 0.0, 0.0), diameter / 2,
                            inner_radius=inner_diameter / 2)
    else:
        cylinder = Cylinder("zone", (0.0, 0.0, 0.0), (float(length), 0.0, 0.0), diameter / 2)
    # a tube's elements are as thick as its wall (quadratic through it): measured on a 100/70 mm
    # zone under a clamped 0.6 m tube, f1 -0.162 % from the harmonic solid against -0.165 % at
    # 12.5 mm and -0.170 % at 6.25 mm (the zone model's own error, module doc; its mesh adds
    # under 0.01 %), at 8 s against 20 s and 100 s a zone
    size = mesh.size * diameter
    if inner_diameter:
        size = (diameter - inner_diameter) / 2
    settings = MeshSettings(size=size, rim_factor=mesh.rim_factor,
                            rim_zone=mesh.rim_zone * diameter)
    return build_mesh(Assembly((cylinder,)), settings)


def _face_dofs(nodes: np.ndarray) -> np.ndarray:
    return (3 * nodes[:, None] + np.arange(3)).ravel()


def rigid_motion(points: np.ndarray, reference) -> np.ndarray:
    """(3 n, 6): displacements of `points` under unit translations and rotations about
    `reference`, u = t + theta x r (node-major)."""
    r = np.asarray(points, float) - np.asarray(reference, float)
    out = np.zeros((len(r), 3, 6))
    out[:, :, :3] = np.eye(3)
    out[:, :, 3:] = -skew(r)
    return out.reshape(-1, 6)


def condense(k: sp.spmatrix, m: sp.spmatrix, constraints: np.ndarray,
             constrained_dofs: np.ndarray, transform: sp.spmatrix | None = None):
    """Guyan constraint modes of u = T x under B x = a (B: 12 rows on the dofs of x listed in
    `constrained_dofs`): Psi = argmin x^T K x / 2 subject to B x = a for each unit a, from
    [[K, B^T], [B, 0]] [Psi; Lambda] = [0; I].

    Returns (K_red, M_red, Psi, K_x, M_x, LU): the condensed matrices, the constraint modes,
    the matrices on x and the factorised saddle-point matrix."""
    kx = k if transform is None else (transform.T @ k @ transform)
    mx = m if transform is None else (transform.T @ m @ transform)
    n, c = kx.shape[0], constraints.shape[0]
    rows = np.repeat(np.arange(c), len(constrained_dofs))
    b = sp.csr_matrix((constraints.ravel(), (rows, np.tile(constrained_dofs, c))), shape=(c, n))
    saddle = sp.bmat([[kx, b.T], [b, None]], format="csc")
    rhs = np.zeros((n + c, c))
    rhs[n:] = np.eye(c)
    lu = sla.splu(saddle)
    psi = lu.solve(rhs)[:n]
    k_red = psi.T @ (kx @ psi)
    m_red = psi.T @ (mx @ psi)
    return 0.5 * (k_red + k_red.T), 0.5 * (m_red + m_red.T), psi, kx, mx, lu


def first_held_mode_hz(kx, mx, lu) -> float:
    """Lowest natural frequency with the master coordinates held (B x = 0): shift-invert
    Lanczos at sigma = 0 whose inverse is the saddle-point solve of `condense` (its solutions
    satisfy B x = 0, so the iteration stays in the held space)."""
    n = kx.shape[0]
    extra = lu.shape[0] - n

    def solve(v):
        return lu.solve(np.concatenate([np.ravel(v), np.zeros(extra)]))[:n]

    op = sla.LinearOperator((n, n), matvec=solve, dtype=float)
    v0 = np.random.default_rng(1).standard_normal(n)
    w = sla.eigsh(kx, k=1, M=mx, sigma=0.0, which="LM", OPinv=op, v0=solve(mx @ v0),
                  tol=1e-8, return_eigenvectors=False)
    return float(np.sqrt(w[0]) / (2 * np.pi))


def _dihedral_average(a: np.ndarray) -> np.ndarray:
    """Mean of Q^T A Q over the symmetries of a cylinder about x that fix the section
    (quarter turns about x and the mirror y -> -y); translations transform as vectors,
    rotations as pseudovectors (times det R)."""
    out = np.zeros_like(a)
    turn = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])
    mirror = np.diag([1.0, -1.0, 1.0])
    group = [np.linalg.matrix_power(turn, k) @ s for k in range(4) for s in (np.eye(3), mirror)]
    for r in group:
        node = la.block_diag(r, np.linalg.det(r) * r)
        q = la.block_diag(node, node)
        out += q.T @ a @ q
    return out / len(group)


def build_zone(diameter: float, length: float, youngs_modulus: float, shear_modulus: float,
               density: float, coupling: str, mesh: ZoneMesh = ZoneMesh(),
               interface: str = "distributing", inner_diameter: float = 0.0) -> ZoneModel:
    """Mesh, assemble and condense one end zone (see the module docstring). SI units.

    `coupling` ties the joint face to the joint point, `interface` the interface section to
    the beam node ("distributing"; "rigid" only to measure what a rigid section would add)."""
    from fem_reference.assembly import stiffness_and_mass
    from fem_reference.discretisation import discretise

    for name, value in (("coupling", coupling), ("interface", interface)):
        if value not in COUPLINGS:
            raise InputError(f"{name} = {value!r}: expected one of {', '.join(COUPLINGS)}")
    disc = discretise(cylinder_mesh(diameter, length, mesh, inner_diameter))
    k, m = stiffness_and_mass(disc, Solid(youngs_modulus, shear_modulus, density))
    ends = ((JOINT_FACE, np.zeros(3), coupling), (INTERFACE, np.array([length, 0.0, 0.0]),
                                                   interface))
    transform, b, dofs = _couplings(disc, ends)
    k_red, m_red, _, kx, mx, lu = condense(k, m, b, dofs, transform)
    # the lowest mode with the twelve master coordinates held: far above the frequencies of
    # interest, the condensed (Guyan) mass is exact enough without interior modes
    return ZoneModel(_dihedral_average(k_red), _dihedral_average(m_red), float(length),
                     disc.n_dofs, first_held_mode_hz(kx, mx, lu))


def _couplings(disc, ends):
    """u = T x and B x = a for the two ends [(face, reference point, coupling)]: a rigid face
    is substituted (its dofs follow six master coordinates appended to x, B selects them), a
    distributing one constrained by its rigid-motion projection (B holds the projection)."""
    from fem_reference.constraints import face_projection

    n = disc.n_dofs
    rigid = [(face, ref) for face, ref, how in ends if how == "rigid"]
    dependent = np.concatenate([_face_dofs(disc.face_nodes[f]) for f, _ in rigid]
                               + [np.zeros(0, int)])
    kept = np.setdiff1d(np.arange(n), dependent)
    position = np.full(n, -1)
    position[kept] = np.arange(len(kept))
    rows, cols, vals = [kept], [np.arange(len(kept))], [np.ones(len(kept))]
    masters = {}
    for j, (face, ref) in enumerate(rigid):
        nodes = disc.face_nodes[face]
        first = len(kept) + 6 * j
        masters[face] = first + np.arange(6)
        rows.append(np.repeat(_face_dofs(nodes), 6))
        cols.append(first + np.tile(np.arange(6), 3 * len(nodes)))
        vals.append(rigid_motion(disc.node_xyz[nodes], ref).ravel())
    size = len(kept) + 6 * len(rigid)
    transform = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                      np.concatenate(cols))), shape=(n, size))
    blocks, dofs = [], []
    for face, ref, how in ends:
        if how == "rigid":
            blocks.append(np.eye(6))
            dofs.append(masters[face])
            continue
        proj = face_projection(disc, face, ref)
        where = position[_face_dofs(proj.nodes)]
        if np.any(where < 0):
            raise InputError("the joint face and the interface section share nodes")
        blocks.append(proj.matrix)
        dofs.append(where)
    return transform, la.block_diag(*blocks), np.concatenate(dofs)
