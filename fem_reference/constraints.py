"""Joint multipoint constraints of the 3-RPS solid model, eliminated exactly: u = T q.

No penalty and no Lagrange multiplier: every constrained dof is written as a linear function of
independent coordinates q, and the reduced matrices are T^T K T and T^T M T (as the paper's
Q^T K_r Q, Eqs. 20-22). Each leg end face is tied to a reference point at its joint centre (the
face centre): B_i for the base face, A_i for the top face.

Joints (paper Section 3.2), one block per joint of each leg's chain (the kinematics says which
joint sits at which end; the paper's equations put R at B_i and S at A_i, its Section 2 text the
other way round):
- the reference point translates with the joint's body: not at all on the base (Eqs. 14-16),
  with the platform on it, Delta = Delta_p + Phi_p x (x_ref - o) (Eq. 10, rigid platform);
- R joint (Eqs. 16-17): the reference point turns with its body plus one rotation phi_i about
  the joint axis a_i (the regular choice; the paper's Eq. (18) ratio form is singular for some
  layouts);
- S joint (Eq. 10): the reference point's rotation psi_i is free.

Face coupling (how the face nodes follow the reference point):
- "rigid" (RBE2-like, default): every face node moves rigidly with the reference point,
  u_k = u_ref + theta_ref x (x_k - x_ref). All face dofs are eliminated; q holds phi_i (1 per
  leg), psi_i (3 per leg) and the platform's 6 coordinates besides the free nodes.
- "distributing" (RBE3-like): the reference point moves as the face does on average, the face
  itself stays free to warp. "On average" is the L2 projection of the face displacement onto
  rigid motions about the reference point x_ref,
      a = [t; theta] = G^-1 int_face Phi(r)^T u dA,   Phi(r) = [I, -[r x]],  r = x - x_ref,
      G = int_face Phi^T Phi dA,
  a linear map of the face's nodal displacements (weights int N_k dA and int N_k r dA, exact
  on the curved triangle6 faces). The joint then constrains this average: at B_i, t = 0 and the
  two rotation components normal to a_i vanish (5 equations; phi_i = a_i . theta is a result,
  not a coordinate); at A_i, t = platform translation at A_i (3 equations; the rotation is free
  and needs no coordinate). Each constraint set C u_face = D q_joint is solved for as many face
  dofs as it has equations (5 or 3), chosen by QR with column pivoting on C so the eliminated
  block is as well conditioned as possible: u_dep = C_dep^-1 (D q_joint - C_ind u_ind). This is
  an exact elimination, like RBE3's dependent reference point but turned around (the face dofs
  are dependent because the reference point's translation is prescribed by the joint).
  The eliminated dofs couple to the whole face, so T^T K T gets a dense block per face.

Elastic platform: the S joint ties the leg-top reference translation to the volume average
displacement of the plate within a radius d/2 (the leg radius) of A_i - a distributing patch,
chosen so that no artificial rigid spot is added to the plate; the reference rotation stays free.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTri

from common.errors import InputError
from common.joints import COUPLINGS, JOINTS  # COUPLINGS: also read from here (the CLI)
from common.rigid_body import rigid_body_mass, skew

from .discretisation import Discretisation
from .leg_points import (  # rigid_rotation: also read from here
    LegPoints,
    RefPoint,
    needs_phi,
    rigid_rotation,  # noqa: F401  (re-exported: the harmonic legs read it from here)
    tie_distributing,
    tie_rigid,
)

# ---------------------------------------------------------------- face averages (RBE3 weights)

def _tri6_shape(xi: np.ndarray, eta: np.ndarray):
    """Quadratic triangle shape functions (meshio order) and their reference derivatives."""
    l0 = 1.0 - xi - eta
    n = np.stack([l0 * (2 * l0 - 1), xi * (2 * xi - 1), eta * (2 * eta - 1),
                  4 * l0 * xi, 4 * xi * eta, 4 * eta * l0])
    dxi = np.stack([-(4 * l0 - 1), 4 * xi - 1, 0 * xi, 4 * (l0 - xi), 4 * eta, -4 * eta])
    deta = np.stack([-(4 * l0 - 1), 0 * xi, 4 * eta - 1, -4 * xi, 4 * xi, 4 * (l0 - eta)])
    return n, dxi, deta


@dataclass(frozen=True)
class FaceProjection:
    """Rigid-motion L2 projection of one face's displacement about a reference point."""

    nodes: np.ndarray  # (n_f,) scalar nodes
    matrix: np.ndarray  # (6, 3 n_f): a = matrix @ u_face (node-major x, y, z)
    area: float


def face_projection(disc: Discretisation, name: str, ref: np.ndarray) -> FaceProjection:
    """a = [t; theta] = G^-1 int Phi^T u dA over the (curved, isoparametric) triangle6 face."""
    tri = disc.face_triangles[name]
    nodes = disc.face_nodes[name]
    local = np.searchsorted(nodes, tri)  # (nt, 6) positions in `nodes`
    x = disc.node_xyz[tri] - np.asarray(ref, float)  # (nt, 6, 3), relative to x_ref
    qp, qw = get_quadrature(RefTri, 4)
    n, dxi, deta = _tri6_shape(qp[0], qp[1])  # (6, nq)
    pos = np.einsum("tkc,kq->tqc", x, n)
    j1, j2 = np.einsum("tkc,kq->tqc", x, dxi), np.einsum("tkc,kq->tqc", x, deta)
    da = np.linalg.norm(np.cross(j1, j2), axis=-1) * qw[None, :]  # (nt, nq)
    area = float(da.sum())
    g = rigid_body_mass(pos.reshape(-1, 3), da.ravel())  # int Phi^T Phi dA
    w = np.zeros(len(nodes))
    m = np.zeros((len(nodes), 3))
    np.add.at(w, local, np.einsum("tq,kq->tk", da, n))
    np.add.at(m, local, np.einsum("tq,kq,tqc->tkc", da, n, pos))
    b = np.zeros((6, len(nodes), 3))
    b[:3] = w[None, :, None] * np.eye(3)[:, None, :]
    b[3:] = skew(m).transpose(1, 0, 2)  # [m_k x] u_k
    return FaceProjection(nodes, la.solve(g, b.reshape(6, -1), assume_a="pos"), area)


# ---------------------------------------------------------------- the constraint map


@dataclass
class ConstraintMap:
    """u = T q, and where the named joint coordinates sit in q."""

    T: sp.csr_matrix  # (n_raw, n_q)
    n_raw: int
    retained: np.ndarray  # raw dofs kept as their own coordinate, in column order
    columns: dict[str, np.ndarray] = field(default_factory=dict)  # e.g. "phi", "psi", "platform"
    projections: dict[str, FaceProjection] = field(default_factory=dict)  # face -> projection
    references: dict[str, np.ndarray] = field(default_factory=dict)  # face -> reference point
    springs: sp.csr_matrix | None = None  # the springs' stiffness on q (leg_points), or None

    @property
    def n_free(self) -> int:
        return int(self.T.shape[1])

    def reference_motion(self, face: str, u: np.ndarray) -> np.ndarray:
        """(6, ...) rigid motion [t; theta] of the face's reference point for raw fields u
        (n_raw,) or (n_raw, k): the face's rigid-motion projection (exact for rigid coupling)."""
        p = self.projections[face]
        dofs = (3 * p.nodes[:, None] + np.arange(3)).ravel()
        return p.matrix @ u[dofs]


class ConstraintBuilder:
    """Collects T (u = T q) in COO form: rows are raw dofs, columns free coordinates.

    A raw dof marked in `dependent` is eliminated; every other one is kept as its own
    coordinate. Named extra coordinates (the joints' rotations, the rigid platform's six) are
    added with `add_extra`; `entries` records T[rows, cols]; `finish` numbers the columns
    (kept raw dofs first, then the extras) and returns (T, kept dofs, extra columns by name).
    Shared by the tetrahedral legs (`build_constraints`) and the harmonic ones."""

    def __init__(self, n_raw: int):
        self.n_raw = n_raw
        self.rows: list[np.ndarray] = []
        self.cols: list[np.ndarray] = []
        self.vals: list[np.ndarray] = []
        self.dependent = np.zeros(n_raw, bool)
        self.n_extra = 0
        self.extra: dict[str, np.ndarray] = {}
        # (extra coordinates, stiffness matrix on them): leg_points
        self.springs: list[tuple[np.ndarray, np.ndarray]] = []
        self.n_retained = 0

    def add_extra(self, name: str, count: int) -> np.ndarray:
        idx = np.arange(self.n_extra, self.n_extra + count)
        self.n_extra += count
        self.extra[name] = idx
        return idx

    def entries(self, rows, cols, vals, extra: bool):
        """Record T[rows, cols] = vals; cols index extra coordinates (extra=True) or raw dofs."""
        rows, cols, vals = (np.asarray(a).ravel() for a in (rows, cols, vals))
        self.rows.append(rows)
        self.cols.append(np.where(extra, -1 - cols, cols))  # negative: extra coordinate
        self.vals.append(vals)

    def finish(self) -> tuple[sp.csr_matrix, np.ndarray, dict]:
        retained = np.flatnonzero(~self.dependent)
        col_of_raw = np.full(self.n_raw, -1, np.int64)
        col_of_raw[retained] = np.arange(len(retained))
        rows = [retained]
        cols = [np.arange(len(retained))]
        vals = [np.ones(len(retained))]
        for r, c, v in zip(self.rows, self.cols, self.vals):
            is_extra = c < 0
            mapped = np.where(is_extra, len(retained) + (-1 - c), col_of_raw[np.maximum(c, 0)])
            if np.any(mapped < 0):
                raise AssertionError("a constraint refers to an eliminated dof")
            rows.append(r)
            cols.append(mapped)
            vals.append(v)
        t = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(self.n_raw, len(retained) + self.n_extra))
        t.sum_duplicates()
        t.eliminate_zeros()
        columns = {k: len(retained) + v for k, v in self.extra.items()}
        self.n_retained = len(retained)
        return t, retained, columns

    def spring_matrix(self) -> sp.csr_matrix | None:
        """The springs' stiffness on the reduced coordinates q (after `finish`), or None when
        there is no spring: 1/2 q^T S q is the springs' energy (`leg_points`)."""
        if not self.springs:
            return None
        n = self.n_retained + self.n_extra
        rows, cols, vals = [], [], []
        for idx, k in self.springs:
            c = self.n_retained + np.asarray(idx)
            rows.append(np.repeat(c, len(c)))
            cols.append(np.tile(c, len(c)))
            vals.append(np.asarray(k, float).ravel())
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                     np.concatenate(cols))), shape=(n, n))


def distributing_joint(bld: ConstraintBuilder, face_dofs: np.ndarray, projection: np.ndarray,
                       joint, t_cols, t_vals, t_extra: bool, plat: np.ndarray | None,
                       candidates: np.ndarray | None = None) -> None:
    """The joint on a distributing face, whose rigid-motion projection a = projection @ u_face
    (6 x n, global) is constrained: its translation is the body's at the joint centre
    (t_vals @ q[t_cols], none on the base), and so are the rotations the joint ties to its
    body, `tied_rotations(axis)` of its declaration (`common.joints.JOINTS`; none for S, the
    two normal to the axis for R). Eliminated for as many face dofs as equations
    (`leg_points.eliminate`). A joint without springs: `leg_points.LegPoints` builds the
    general point (springs, junctions) that `leg_points.tie_distributing` ties."""
    tied = JOINTS[joint.type].tied_rotations(joint.axis)  # (k, 3)
    rhs: tuple | None  # RefPoint.distributing
    if len(tied) and joint.body == "platform":  # the platform's rotation reaches the tied ones
        rhs = (plat, np.vstack([t_vals, np.hstack([np.zeros((len(tied), 3)), tied])]), True)
    else:
        rhs = (t_cols, t_vals, t_extra) if t_cols is not None else None
    point = RefPoint(np.asarray(joint.centre, float), None, None, tied, rhs)
    tie_distributing(bld, face_dofs, projection, point, candidates)


def patch_weights(disc: Discretisation, body: str, centre: np.ndarray, radius: float):
    """Nodes and weights of the volume average of a body's displacement within `radius` of
    `centre`: u_avg = sum_k w_k u_k, w_k = int_patch N_k dV / V_patch."""
    b = disc.basis
    ib = disc.bodies.index(body)
    x = disc.node_xyz[b.element_dofs[:4]].mean(axis=0)  # vertex centroids (ne, 3)
    inside = (disc.tet_body == ib) & (np.linalg.norm(x - centre, axis=1) <= radius)
    if not inside.any():
        raise InputError(f"no {body} element within {radius:g} m of {np.round(centre, 6)}")
    values = np.stack([np.asarray(phi[0]) for phi in b.basis])  # (10, ne, nq)
    local = np.einsum("aeq,eq->ae", values[:, inside], b.dx[inside])
    nodes, inv = np.unique(b.element_dofs[:, inside], return_inverse=True)
    w = np.bincount(inv.ravel(), local.ravel(), minlength=len(nodes))
    return nodes, w / w.sum()


def build_constraints(disc: Discretisation, geometry, assembly, coupling: str = "rigid",
                      platform: str = "rigid", patch_radius: float | None = None,
                      stiffness=None) -> ConstraintMap:
    """T for the joints of every leg on the meshed legs (and plate), see the module docstring.

    `geometry` is an `analytical.kinematics.PoseGeometry` (its chain of joints per leg);
    `assembly` the `meshing.bodies.Assembly` that was meshed (its legs' parts name the faces);
    `stiffness` a `common.stiffness.Stiffness` (None: every joint and drive rigid): its springs,
    a stepped leg's junction (`leg_points`) and the springs' matrix (`ConstraintMap.springs`).
    With platform="rigid" the first six extra coordinates after the joints' are the platform's
    (Delta_p, Phi_p) at o, Eq. (7).
    """
    if coupling not in COUPLINGS:
        raise InputError(f"coupling = {coupling!r}: expected one of {', '.join(COUPLINGS)}")
    n_raw = disc.n_dofs
    bld = ConstraintBuilder(n_raw)
    xyz = disc.node_xyz
    o = np.asarray(geometry.platform_centre, float)
    projections, references = {}, {}
    legs = assembly.legs
    if len(legs) != geometry.leg_count:
        raise InputError(f"{len(legs)} meshed legs for a pose of {geometry.leg_count}")
    if platform != "rigid" and JOINTS[geometry.platform_joint].follows_body:
        raise InputError(f"platform = 'elastic' with {geometry.platform_joint} joints on the "
                         "platform: the rotation of an elastic plate at a joint is not defined "
                         "here (use a rigid platform)")
    phi: np.ndarray = np.zeros(0, np.int64)
    psi: np.ndarray = np.zeros(0, np.int64)
    if coupling == "rigid":
        if needs_phi(stiffness, geometry):
            phi = bld.add_extra("phi", len(legs))  # one rotation per R joint
        psi = bld.add_extra("psi", 3 * len(legs)).reshape(len(legs), 3)  # three per S joint
    plat = bld.add_extra("platform", 6) if platform == "rigid" else None
    points = LegPoints(bld, geometry, coupling, stiffness, len(legs[0]))
    for i, parts in enumerate(legs):
        # the translation of the platform joint's body at its centre: the rigid platform's
        # motion there, Eq. (10), or the elastic plate's patch average
        ref = np.asarray(geometry.leg_joints(i)[1].centre, float)
        if platform == "rigid":
            body = (plat, np.hstack([np.eye(3), -skew(ref - o)]), True)
        else:
            radius = patch_radius if patch_radius is not None else parts[-1].radius
            pn, pw = patch_weights(disc, "platform", ref, radius)
            t_vals = np.zeros((3, 3 * len(pn)))
            for c in range(3):
                t_vals[c, c * len(pn):(c + 1) * len(pn)] = pw
            body = ((3 * pn[None, :] + np.arange(3)[:, None]).ravel(), t_vals, False)
        b = np.asarray(geometry.base_points[i], float)
        starts = [float(np.linalg.norm(np.subtract(c.start, b))) for c in parts]
        starts[0] = 0.0
        tied_to = points.face_points(i, starts, phi, psi, plat, body)
        for part, ends in zip(parts, tied_to):
            for face, point in zip((part.start_face, part.end_face), ends):
                projections[face] = face_projection(disc, face, point.centre)
                references[face] = point.centre
                if coupling == "rigid":
                    nodes = disc.face_nodes[face]
                    tie_rigid(bld, 3 * nodes[:, None] + np.arange(3), xyz[nodes] - point.centre,
                              point)
                    continue
                proj = projections[face]
                fd = (3 * proj.nodes[:, None] + np.arange(3)).ravel()
                tie_distributing(bld, fd, proj.matrix, point)
    t, retained, columns = bld.finish()
    return ConstraintMap(t, n_raw, retained, columns, projections, references,
                         bld.spring_matrix())
