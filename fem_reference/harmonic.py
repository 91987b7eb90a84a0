"""The solid legs by Fourier harmonics: the same 3D elasticity on a 2D meridian mesh, exactly.

A leg is a solid circular cylinder of radius R and length L whose end faces are tied to joint
centres (`constraints.py`). Its geometry and material do not depend on the polar angle theta
about its axis, so 3D linear elasticity splits exactly into uncoupled Fourier harmonics
(Wilson 1965; Zienkiewicz & Taylor, The Finite Element Method, Vol. 1, "axisymmetric solids
under non-symmetric loading"). In the leg's frame (r, theta, z; z from B_i to A_i), harmonic n
of family "c" is

    u_r = U_r(r, z) cos n theta,  u_theta = U_t(r, z) sin n theta,  u_z = U_z(r, z) cos n theta

and family "s" the same turned by 90 degrees about the axis (its matrices are family c's). For
n = 0, U_t is the torsion field and the weight of every term is 2 pi (pi for n >= 1). The
strains of a harmonic (the cos group rr, tt, zz, rz and the sin group rt, tz) are

    e_rr = U_r,r        e_tt = (U_r + n U_t) / r     e_zz = U_z,z      g_rz = U_r,z + U_z,r
    g_rt = U_t,r - (U_t + n U_r) / r                 g_tz = U_t,z - n U_z / r

and K_n = w_n int B^T D B r dr dz, M_n = w_n rho int N^T N r dr dz on P2 triangles of the
meridian rectangle [0, R] x [0, L] (gmsh, graded toward the two rim corners, where the rigid
face meets the wall: the stress singularity of issue 13, a point here, not an edge).

Why this is exact and not a model: a rigid motion (t, phi) of an end face, written in the
leg's frame, is u_r = t_x cos + t_y sin, u_theta = -t_x sin + t_y cos + phi_z r,
u_z = t_z + r (phi_x sin - phi_y cos): harmonics 0 and 1 only. So a rigid (RBE2) face ties
exactly harmonics 0 and 1 to its joint, and the distributing (RBE3) average of a face reads
harmonics 0 and 1 only. Harmonics n >= 2 of a leg never couple to anything: they are modes of
one leg alone (faces held for rigid coupling, free for distributing), which the solver includes
whenever the lowest of them falls within the range of frequencies solved for (`solve_pose`
checks every leg), so the answer is the 3D solid's.

Regularity on the axis (r = 0), imposed exactly: n = 0: U_r = U_t = 0; n = 1: U_z = 0 and
U_t = -U_r (a single-valued lateral translation); n >= 2: U = 0.

What is shared with the tetrahedral model (`model.py`): the joints and couplings
(`constraints.py`, the same equations in the same global coordinates, paper Eqs. 10, 14-17),
the rigid platform's mass from its own meshed plate (`rigid_platform.py`), the eigen solver
(`eigen.py`). Nothing of `analytical/` but the pose geometry.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
import functools
import hashlib
import math
import time

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from skfem import Basis, ElementTriP2, FacetBasis, LinearForm, MeshTri

from common.rigid_body import skew

from .assembly import lame
from .constraints import COUPLINGS, ConstraintBuilder, distributing_joint, rigid_rotation
from .eigen import EigenError, lowest_modes
from .model import (normalise_signs, reduced_matrices, section_arms, solve_record,
                    station_fractions, twist_from_section)
from .export import write_mesh_vtu, solid_to_meshio, write_mode_collection
from meshing.bodies import platform_plate
from meshing.geometry import GmshFailure, gmsh_session

AXIS_TOL = 1e-12  # relative to R: a node on the axis
FACE_TOL = 1e-12  # relative to L: a node on an end face


class HarmonicError(ValueError):
    """Bad input or a failed step of the harmonic model; one line naming the value."""


# The meridian's grading toward each rim corner: size h (distance / (CORNER_ZONE R)), at least
# CORNER_FACTOR h. Measured on paper.toml case 2 (both couplings alike), max error over f1-f6
# against a 0.15 R mesh graded to 0.005: at h = 0.8 R (40 mm) 0.006 % with 7.8k dofs (0.4 h
# within 0.3 R, the tetrahedra's rim grading: 0.05 %; 0.01 within R: 0.005 % with 11k dofs);
# at h = 0.5 R 0.002 %. In 2D deep grading costs little: a point, not an edge, is refined.
CORNER_FACTOR = 0.05
CORNER_ZONE = 1.0  # leg radii
LOWEST_EXCLUDED_MARGIN = 1.2  # harmonic n + 1 is left out if its lowest mode is this far above


# ---------------------------------------------------------------- meridian mesh (gmsh, 2D)

@functools.lru_cache(maxsize=64)
def meridian_mesh(radius: float, length: float, size: float) -> MeshTri:
    """Linear triangles of the rectangle [0, R] x [0, L] (x = r, y = z), graded toward the rim
    corners (R, 0) and (R, L); the P2 basis adds the mid-edge nodes (straight edges: the
    geometry is exact). Read-only, remembered per process (same leg, same mesh)."""
    h = float(size)
    h_min = h * CORNER_FACTOR
    zone = CORNER_ZONE * radius
    try:
        with gmsh_session({"Mesh.ElementOrder": 1, "Mesh.MeshSizeMax": h,
                           "Mesh.MeshSizeMin": h_min}) as gmsh:
            model = gmsh.model
            model.add("meridian")
            geo = model.geo
            corners = [geo.addPoint(0, 0, 0), geo.addPoint(radius, 0, 0),
                       geo.addPoint(radius, length, 0), geo.addPoint(0, length, 0)]
            lines = [geo.addLine(corners[k], corners[(k + 1) % 4]) for k in range(4)]
            geo.addPlaneSurface([geo.addCurveLoop(lines)])
            geo.synchronize()
            dist = model.mesh.field.add("Distance")
            model.mesh.field.setNumbers(dist, "PointsList", [corners[1], corners[2]])
            graded = model.mesh.field.add("MathEval")
            model.mesh.field.setString(
                graded, "F", f"Max({h_min!r}, Min({h!r}, {h!r} * F{dist} / {zone!r}))")
            model.mesh.field.setAsBackgroundMesh(graded)
            model.mesh.generate(2)
            tags, coords, _ = model.mesh.getNodes()
            types, _, enodes = model.mesh.getElements(2)
            tri = np.concatenate([np.asarray(n_, np.int64).reshape(-1, 3)
                                  for ty, n_ in zip(types, enodes) if ty == 2])
    except GmshFailure as exc:
        raise HarmonicError(f"meridian mesh of R = {radius:g} m, L = {length:g} m: gmsh "
                            f"failed ({exc})") from None
    tags = np.asarray(tags, np.int64)
    index = np.full(int(tags.max()) + 1, -1, np.int64)
    index[tags] = np.arange(len(tags))
    points = np.asarray(coords, float).reshape(-1, 3)[:, :2]
    used, tri = np.unique(index[tri], return_inverse=True)
    tri = tri.reshape(-1, 3)
    p = points[used]
    # snap the boundary exactly (gmsh's nodes on straight lines are exact to round-off)
    for col, lo, hi in ((0, 0.0, radius), (1, 0.0, length)):
        scale = hi - lo
        p[np.abs(p[:, col] - lo) <= 1e-12 * scale, col] = lo
        p[np.abs(p[:, col] - hi) <= 1e-12 * scale, col] = hi
    # counter-clockwise triangles
    a, b, c = (p[tri[:, k]] for k in range(3))
    cross = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    tri[cross < 0] = tri[cross < 0][:, [0, 2, 1]]
    mesh = MeshTri(np.ascontiguousarray(p.T), np.ascontiguousarray(tri.T))
    return mesh


def clear_caches() -> None:
    """Forget the per-process meridian meshes and leg matrices (benchmarks time them)."""
    for cached in (meridian_mesh, meridian, harmonic_stiffness, unit_mass):
        cached.cache_clear()


# ---------------------------------------------------------------- one leg, one harmonic

@dataclass(frozen=True)
class Meridian:
    """The P2 discretisation of one leg's meridian: what every harmonic of it shares."""

    radius: float
    length: float
    basis: Basis  # scalar P2 on the meridian mesh
    node_rz: np.ndarray  # (n_scalar, 2) P2 node positions (r, z)
    axis_nodes: np.ndarray  # scalar nodes at r = 0
    face_nodes: tuple  # (nodes at z = 0, nodes at z = L)
    face_weights: tuple  # per face: (W1, W2) = (int phi r dr, int phi r^2 dr) over the face

    @property
    def n_scalar(self) -> int:
        return len(self.node_rz)


@dataclass(frozen=True)
class LegHarmonics(Meridian):
    """A leg's meridian with its matrices (module doc): K_n per harmonic n, dofs 3 s + c,
    c = (r, t, z), the theta weight included; M for n >= 1 (weight pi), n = 0 twice it."""

    stiffness: dict = field(default_factory=dict)
    mass: sp.csr_matrix | None = None


@functools.lru_cache(maxsize=64)
def meridian(radius: float, length: float, size: float) -> Meridian:
    """The leg's meridian (read-only, remembered per process: same leg, same mesh)."""
    mesh = meridian_mesh(radius, length, size)
    basis = Basis(mesh, ElementTriP2(), intorder=6)
    locs = basis.doflocs.T  # (n_s, 2)
    axis = np.flatnonzero(locs[:, 0] <= AXIS_TOL * radius)
    faces, weights = [], []
    for z0 in (0.0, length):
        facets = mesh.facets_satisfying(lambda x, z0=z0: np.abs(x[1] - z0) <= FACE_TOL * length)
        fb = FacetBasis(mesh, ElementTriP2(), facets=facets, intorder=6)
        on = np.flatnonzero(np.abs(locs[:, 1] - z0) <= FACE_TOL * length)
        faces.append(on)
        weights.append(tuple(LinearForm(lambda v, p, k=k: v * p.x[0] ** k).assemble(fb)[on]
                             for k in (1, 2)))
    if len(axis) < 3 or any(len(f) < 3 for f in faces):
        raise HarmonicError(f"meridian mesh of R = {radius:g} m, L = {length:g} m: "
                            f"{len(axis)} nodes on the axis, {[len(f) for f in faces]} on the "
                            "faces (expected the boundary lines meshed)")
    return Meridian(radius, length, basis, locs, axis, tuple(faces), tuple(weights))


def _element_arrays(basis: Basis):
    values = np.stack([np.asarray(phi[0]) for phi in basis.basis])  # (6, ne, nq)
    grads = np.stack([phi[0].grad for phi in basis.basis])  # (6, 2, ne, nq)
    r = np.asarray(basis.global_coordinates())[0]  # (ne, nq)
    return values, grads, r, r * basis.dx  # the last: r dr dz


def _strain_operator(values, grads, r, n: int) -> np.ndarray:
    """B (ne, nq, 6 strains, 18 = 6 nodes x 3 components), strains (rr, tt, zz, rt, tz, rz),
    components (r, t, z) node-major."""
    ne, nq = r.shape
    nloc = values.shape[0]
    b = np.zeros((ne, nq, 6, nloc, 3))
    phi = values.transpose(1, 2, 0)  # (ne, nq, a)
    dr = grads[:, 0].transpose(1, 2, 0)
    dz = grads[:, 1].transpose(1, 2, 0)
    over_r = phi / r[..., None]
    b[:, :, 0, :, 0] = dr
    b[:, :, 1, :, 0] = over_r
    b[:, :, 1, :, 1] = n * over_r
    b[:, :, 2, :, 2] = dz
    b[:, :, 3, :, 1] = dr - over_r
    b[:, :, 3, :, 0] = -n * over_r
    b[:, :, 4, :, 1] = dz
    b[:, :, 4, :, 2] = -n * over_r
    b[:, :, 5, :, 0] = dz
    b[:, :, 5, :, 2] = dr
    return b.reshape(ne, nq, 6, 3 * nloc)


def _sparse(element_dofs: np.ndarray, blocks: np.ndarray, n: int) -> sp.csr_matrix:
    """Sum element matrices (ne, d, d) on the element dofs (d, ne) into an n x n CSR."""
    ed = element_dofs.T
    rows = np.repeat(ed[:, :, None], ed.shape[1], axis=2)
    cols = np.repeat(ed[:, None, :], ed.shape[1], axis=1)
    out = sp.csr_matrix((blocks.ravel(), (rows.ravel(), cols.ravel())), shape=(n, n))
    out.sum_duplicates()
    out.data.setflags(write=False)
    return out


@functools.lru_cache(maxsize=256)
def harmonic_stiffness(radius: float, length: float, size: float, lam: float, mu: float,
                       n: int) -> sp.csr_matrix:
    """K_n = w_n int B^T D B r dr dz of one leg (read-only, remembered per process)."""
    m = meridian(radius, length, size)
    values, grads, r, w = _element_arrays(m.basis)
    d = np.zeros((6, 6))
    d[:3, :3] = lam
    d[[0, 1, 2], [0, 1, 2]] += 2 * mu
    d[[3, 4, 5], [3, 4, 5]] = mu
    b = _strain_operator(values, grads, r, n)
    weight = 2 * math.pi if n == 0 else math.pi
    ke = weight * np.einsum("eqsa,st,eqtb,eq->eab", b, d, b, w, optimize=True)
    nodes = m.basis.element_dofs  # (6, ne) scalar nodes -> (18, ne) dofs 3 s + c, node-major
    dofs = (3 * nodes[:, None, :] + np.arange(3)[None, :, None]).reshape(-1, nodes.shape[1])
    return _sparse(dofs, ke, 3 * m.n_scalar)


@functools.lru_cache(maxsize=64)
def unit_mass(radius: float, length: float, size: float) -> sp.csr_matrix:
    """pi int N^T N r dr dz on dofs 3 s + c, density 1 (read-only, remembered per process):
    the scalar P2 mass times the 3 x 3 identity."""
    m = meridian(radius, length, size)
    values, _, _, w = _element_arrays(m.basis)
    scalar = _sparse(m.basis.element_dofs,
                     np.einsum("aeq,beq,eq->eab", values, values, w, optimize=True), m.n_scalar)
    out = math.pi * sp.kron(scalar, sp.identity(3), format="csr")
    out.data.setflags(write=False)
    return out


def leg_harmonics(radius: float, length: float, lam: float, mu: float, density: float,
                  size: float, harmonics: tuple) -> LegHarmonics:
    """One leg's meridian with K_n (n in `harmonics`) and M, from the per-process caches."""
    m = meridian(radius, length, size)
    return LegHarmonics(**{f: getattr(m, f) for f in Meridian.__dataclass_fields__},
                        stiffness={n: harmonic_stiffness(radius, length, size, lam, mu, n)
                                   for n in harmonics},
                        mass=density * unit_mass(radius, length, size))


# ---------------------------------------------------------------- the face's rigid motions

def rigid_face_coefficients(n: int, family: str, rho: np.ndarray) -> np.ndarray:
    """(len(rho), 3 components, 6): the face dofs (U_r, U_t, U_z) at radii rho of harmonic
    (n, family) as linear functions of the face's rigid motion (t_x, t_y, t_z, phi_x, phi_y,
    phi_z) in the leg frame (module docstring); zero for n >= 2."""
    h = np.zeros((len(rho), 3, 6))
    if n == 0:
        h[:, 1, 5] = rho  # U_t = phi_z r
        h[:, 2, 2] = 1.0  # U_z = t_z
    elif n == 1 and family == "c":
        h[:, 0, 0] = 1.0  # U_r = t_x
        h[:, 1, 0] = -1.0  # U_t = -t_x
        h[:, 2, 4] = -rho  # U_z = -phi_y r
    elif n == 1:
        h[:, 0, 1] = 1.0  # V_r = t_y
        h[:, 1, 1] = -1.0  # V_t = -t_y
        h[:, 2, 3] = rho  # V_z = phi_x r
    return h


def face_projection_coefficients(leg: LegHarmonics, face: int, n: int, family: str
                                 ) -> np.ndarray:
    """(6, len(face nodes), 3): the L2 projection of the face's displacement onto rigid
    motions about its centre, a = G^-1 int Phi^T u dA (constraints.face_projection), read from
    harmonic (n, family) of the face's nodal values, in the leg frame."""
    w1, w2 = leg.face_weights[face]
    r = leg.radius
    area, i_xx, i_zz = math.pi * r**2, math.pi * r**4 / 4, math.pi * r**4 / 2
    p = np.zeros((6, len(w1), 3))
    if n == 0:
        p[2, :, 2] = 2 * math.pi * w1 / area  # t_z
        p[5, :, 1] = 2 * math.pi * w2 / i_zz  # phi_z
    elif n == 1 and family == "c":
        p[0, :, 0] = math.pi * w1 / area  # t_x = pi/A int (U_r - U_t) r dr
        p[0, :, 1] = -math.pi * w1 / area
        p[4, :, 2] = -math.pi * w2 / i_xx  # phi_y = -pi/I int U_z r^2 dr
    elif n == 1:
        p[1, :, 0] = math.pi * w1 / area
        p[1, :, 1] = -math.pi * w1 / area
        p[3, :, 2] = math.pi * w2 / i_xx
    return p


def families(harmonics) -> list[tuple[int, str]]:
    """(n, family) blocks of a leg's raw dofs, in order: n = 0 once, n >= 1 twice (c, s)."""
    return [(n, f) for n in harmonics for f in (("c",) if n == 0 else ("c", "s"))]


# ---------------------------------------------------------------- the assembled pose

@dataclass
class HarmonicResult:
    """One pose solved with harmonic legs; the interface of `model.FemResult` (frequencies,
    leg-axis and platform motions, VTU, record) so the pipeline takes either."""

    frequencies_hz: np.ndarray  # (modes,) ascending
    dofs: int  # free coordinates after the joints (and the axis) are eliminated
    raw_dofs: int  # harmonic dofs of the legs
    mesh_size: float  # m, the meridian's element size h
    timings: dict  # seconds: mesh, assemble, solve, total
    clusters: list
    mesh_digest: str
    n_elements: int  # meridian triangles over the legs
    options: object  # model.FemOptions
    min_quality: float  # smallest triangle quality 4 sqrt(3) area / sum of squared edges
    harmonics: tuple  # harmonic orders included
    excluded_above_hz: float  # no mode of the first harmonic left out lies below this
    geometry: object = field(repr=False)
    modes_q: np.ndarray = field(repr=False)
    modes_raw: np.ndarray = field(repr=False)
    columns: dict = field(repr=False)
    legs: list = field(repr=False)  # per leg: (LegHarmonics, frame E (3, 3), raw offset)
    plate: object = field(default=None, repr=False)
    cache_hit: bool = False

    @property
    def platform_motion(self) -> np.ndarray:
        """(6, n_modes): translation of o and rotation of the rigid platform."""
        return self.modes_q[self.columns["platform"]].copy()

    def _blocks(self, leg_index: int) -> dict:
        leg, _, offset = self.legs[leg_index]
        n3 = 3 * leg.n_scalar
        return {fam: self.modes_raw[offset + k * n3: offset + (k + 1) * n3]
                for k, fam in enumerate(families(self.harmonics))}

    def face_motion(self, leg_index: int, face: int) -> np.ndarray:
        """(6, n_modes): the face's projected rigid motion (t, phi) in the leg frame (its
        joint's reference point, as `FemResult` reads it); harmonics 0 and 1 carry it."""
        leg = self.legs[leg_index][0]
        nodes = leg.face_nodes[face]
        out = 0.0
        for (n, fam), block in self._blocks(leg_index).items():
            if n <= 1:
                values = block.reshape(-1, 3, block.shape[1])[nodes]
                projection = face_projection_coefficients(leg, face, n, fam).reshape(6, -1)
                out = out + projection @ values.reshape(-1, block.shape[1])
        return out

    def local_displacements(self, leg_index: int, r, theta, z) -> np.ndarray:
        """(n_points, 3, n_modes): the 3D displacement at points (r, theta, z) of a leg, in
        the leg's frame (e1, e2, axis), summed over the harmonics (module docstring)."""
        leg = self.legs[leg_index][0]
        r, theta, z = (np.asarray(a, float).ravel() for a in (r, theta, z))
        eps = 1e-9  # points on the boundary, nudged inside for the element search
        probe = leg.basis.probes(np.vstack([np.clip(r, eps * leg.radius, (1 - eps) * leg.radius),
                                            np.clip(z, eps * leg.length, (1 - eps) * leg.length)]))
        ur = np.zeros((len(r), self.modes_raw.shape[1]))
        ut, uz = ur.copy(), ur.copy()
        for (n, fam), block in self._blocks(leg_index).items():
            vr, vt, vz = (probe @ block[c::3] for c in range(3))
            cos, sin = np.cos(n * theta)[:, None], np.sin(n * theta)[:, None]
            if n == 0:  # u_t = U_t, the torsion field (cos 0 = 1 on every component)
                ur, ut, uz = ur + vr, ut + vt, uz + vz
            elif fam == "c":  # (cos, sin, cos)
                ur, ut, uz = ur + vr * cos, ut + vt * sin, uz + vz * cos
            else:  # (sin, -cos, sin): family c turned by 90 / n degrees
                ur, ut, uz = ur + vr * sin, ut - vt * cos, uz + vz * sin
        c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
        return np.stack([ur * c - ut * s, ur * s + ut * c, uz], axis=1)

    def leg_axis_displacements(self, fractions) -> np.ndarray:
        """Translation of the leg axis points B_i + t (A_i - B_i) per mode, base coordinates:
        (3 legs, len(fractions), 3, n_modes). At t = 0 and 1 the face's projected rigid
        motion (its joint's reference point, as `FemResult`), inside the axis itself."""
        t = station_fractions(fractions)
        out = np.zeros((len(self.legs), len(t), 3, self.modes_raw.shape[1]))
        for i, (leg, frame, _) in enumerate(self.legs):
            out[i] = np.einsum("ab,tbm->tam", frame, self.local_displacements(
                i, np.zeros_like(t), np.zeros_like(t), t * leg.length))
            for face, end in ((0, 0.0), (1, 1.0)):
                sel = np.abs(t - end) <= 1e-9
                if sel.any():
                    out[i, sel] = (frame @ self.face_motion(i, face)[:3])[None]
        return out

    def leg_axis_twists(self, fractions) -> np.ndarray:
        """Rotation of each leg's sections about its axis (rad) at fractions t, per mode:
        (3 legs, len(fractions), n_modes), as `FemResult.leg_axis_twists`: inside, the mean
        rotation of six points at half the radius; at the joint centres the face's projected
        rigid rotation."""
        t = station_fractions(fractions)
        axis = np.array([0.0, 0.0, 1.0])  # in the leg frame
        out = np.zeros((len(self.legs), len(t), self.modes_raw.shape[1]))
        for i, (leg, _, _) in enumerate(self.legs):
            arms = section_arms(axis, 0.5 * leg.radius)
            theta = np.arctan2(arms[:, 1], arms[:, 0])
            u = self.local_displacements(i, np.repeat(0.5 * leg.radius, len(t) * len(arms)),
                                         np.tile(theta, len(t)),
                                         np.repeat(t * leg.length, len(arms)))
            out[i] = twist_from_section(axis, arms, u.reshape(len(t), len(arms), 3, -1))
            for face, end in ((0, 0.0), (1, 1.0)):
                sel = np.abs(t - end) <= 1e-9
                if sel.any():
                    out[i, sel] = self.face_motion(i, face)[5][None]  # phi_z, the twist
        return out

    def display_mesh(self, rings: int = 3, sectors: int = 24):
        """Points, meshio cell blocks and body ids of a structured display of the legs (wedges
        around the axis, hexahedra outside), and the modes' displacements at the points."""
        points, wedges, hexes, u, body_w, body_h = [], [], [], [], [], []
        start = 0
        for i, (leg, frame, _) in enumerate(self.legs):
            layers = max(8, int(math.ceil(leg.length / leg.radius)))
            z = np.linspace(0.0, leg.length, layers + 1)
            theta = 2 * math.pi * np.arange(sectors) / sectors
            rr = leg.radius * np.arange(1, rings + 1) / rings
            # per layer: the axis point, then rings x sectors
            r_pts = np.concatenate([[0.0], np.repeat(rr, sectors)])
            t_pts = np.concatenate([[0.0], np.tile(theta, rings)])
            per = len(r_pts)
            rz = np.tile(r_pts, layers + 1)
            tz = np.tile(t_pts, layers + 1)
            zz = np.repeat(z, per)
            base = np.asarray(self.geometry.base_points[i], float)
            local = np.stack([rz * np.cos(tz), rz * np.sin(tz), zz], axis=1)
            points.append(base + local @ frame.T)
            u.append(np.einsum("ab,pbm->pam", frame, self.local_displacements(i, rz, tz, zz)))
            k = np.arange(sectors)
            nxt = (k + 1) % sectors
            for layer in range(layers):
                lo, hi = start + layer * per, start + (layer + 1) * per
                ring1 = 1 + k
                ring1n = 1 + nxt
                wedges.append(np.column_stack([np.full(sectors, lo), lo + ring1n, lo + ring1,
                                               np.full(sectors, hi), hi + ring1n, hi + ring1]))
                for j in range(rings - 1):
                    a, b = 1 + j * sectors + k, 1 + j * sectors + nxt
                    c, d = 1 + (j + 1) * sectors + nxt, 1 + (j + 1) * sectors + k
                    hexes.append(np.column_stack([lo + a, lo + d, lo + c, lo + b,
                                                  hi + a, hi + d, hi + c, hi + b]))
            body_w.append(np.full(layers * sectors, i, np.int32))
            body_h.append(np.full(layers * sectors * (rings - 1), i, np.int32))
            start += per * (layers + 1)
        cells = [("wedge", np.vstack(wedges)), ("hexahedron", np.vstack(hexes))]
        return (np.vstack(points), cells, [np.concatenate(body_w), np.concatenate(body_h)],
                np.concatenate(u))

    def write_vtu(self, path, pvd: bool = False) -> None:
        """Mode shapes for ParaView: the legs' 3D displacement on a structured display mesh
        (from the harmonics) and the rigid platform, as `FemResult.write_vtu`."""
        points, cells, body, u = self.display_mesh()
        write_mesh_vtu(path, solid_to_meshio(points, cells, body, len(self.legs), u,
                                               self.frequencies_hz, self.plate,
                                               self.platform_motion))
        if pvd:
            write_mode_collection(path)

    def to_dict(self) -> dict:
        return solve_record(self, harmonics=list(self.harmonics),
                            excluded_harmonics_above_hz=self.excluded_above_hz)


def leg_frame(geometry, leg: int) -> np.ndarray:
    """(3, 3) columns e1, e2, e3: e3 along the leg from B_i to A_i, e1 and e2 the limb frame's
    other two axes (a right-handed turn of its columns)."""
    f = np.asarray(geometry.leg_frames[leg], float)
    return np.column_stack([f[:, 1], f[:, 2], f[:, 0]])


def _material(manipulator):
    lam, mu = lame(manipulator.material)
    return float(lam), float(mu), float(manipulator.material.density)


def _leg_lengths(geometry) -> np.ndarray:
    """|A_i - B_i|, rounded so that one leg length is one cache key."""
    return np.round(np.linalg.norm(np.asarray(geometry.platform_points, float)
                                   - np.asarray(geometry.base_points, float), axis=1), 12)


def _leg_data(manipulator, geometry, size: float, harmonics,
              longest_only: bool = False) -> list:
    """Per leg (or the longest alone): (LegHarmonics, frame)."""
    radius = 0.5 * float(manipulator.leg_diameter)
    lam, mu, rho = _material(manipulator)
    lengths = _leg_lengths(geometry)
    legs = [int(np.argmax(lengths))] if longest_only else range(geometry.leg_count)
    return [(leg_harmonics(radius, float(lengths[i]), lam, mu, rho, float(size),
                           tuple(harmonics)), leg_frame(geometry, i)) for i in legs]


def _section_blocks(manipulator, geometry, size: float, coupling: str, n: int):
    """(K, M) of harmonic n >= 2 of each leg alone, faces held (rigid coupling) or free
    (distributing), the axis regular; both families share them. Rigid: the longest leg only
    (faces held, a longer leg's admissible fields hold a shorter one's: its modes are lower,
    min-max)."""
    legs = _leg_data(manipulator, geometry, size, (n,),
                     longest_only=coupling == "rigid")
    for leg, _ in legs:
        k, m = leg.stiffness[n], leg.mass
        fixed = [3 * leg.axis_nodes[:, None] + np.arange(3)]
        if coupling == "rigid":
            fixed += [3 * f[:, None] + np.arange(3) for f in leg.face_nodes]
        free = np.setdiff1d(np.arange(k.shape[0]), np.concatenate(fixed).ravel())
        yield k[free][:, free], m[free][:, free]


def lowest_leg_harmonic(manipulator, geometry, size: float, coupling: str, n: int) -> float:
    """Lowest frequency (Hz) of harmonic n >= 2 over the legs (`_section_blocks`)."""
    lowest = math.inf
    for k, m in _section_blocks(manipulator, geometry, size, coupling, n):
        w = lowest_modes(k, m, 1, extra=1).eigenvalues
        lowest = min(lowest, math.sqrt(max(float(w[0]), 0.0)) / (2 * math.pi))
    return lowest


def modes_below(k: sp.spmatrix, m: sp.spmatrix, frequency_hz: float) -> int | None:
    """How many eigenvalues of (K, M) lie below (2 pi f)^2, by Sylvester's law of inertia: the
    negative pivots of K - mu M factorised with symmetric (diagonal) pivots, LDL^T. None when
    SuperLU had to pivot off the diagonal (then the count is not the inertia)."""
    mu = (2 * math.pi * frequency_hz) ** 2
    lu = sla.splu(sp.csc_matrix(k - mu * m), permc_spec="MMD_AT_PLUS_A",
                  diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    if not np.array_equal(lu.perm_r, lu.perm_c):
        return None
    return int(np.count_nonzero(lu.U.diagonal() < 0))


def section_modes_above(manipulator, geometry, size: float, coupling: str, n: int,
                        frequency_hz: float) -> bool:
    """Does harmonic n >= 2 of every leg have no mode below `frequency_hz`? Counted by
    inertia (a few ms a leg; ARPACK crawls in the dense band of section modes of a long leg),
    or by its lowest mode where the inertia count is not available."""
    for k, m in _section_blocks(manipulator, geometry, size, coupling, n):
        count = modes_below(k, m, frequency_hz)
        if count is None:
            w = lowest_modes(k, m, 1, extra=1).eigenvalues[0]
            count = int(w < (2 * math.pi * frequency_hz) ** 2)
        if count:
            return False
    return True


# P2 nodes of a leg's graded meridian: NODES_PER_AREA R L / h^2 + NODES_PER_CORNER (R / h)^2
# + NODES_MIN, fitted on 36 meshes (R 15-75 mm, L 0.3-1 m, h 0.2-1.6 R), then raised by 1.5 so
# that no mesh has more (actual / estimate 0.37-0.84 on the five scenes' legs, 0.1-0.8 d)
NODES_PER_AREA, NODES_PER_CORNER, NODES_MIN = 7.8, 70.0, 255.0


def estimate_raw_dofs(assembly, size: float, harmonics=(0, 1)) -> int:
    """Raw harmonic dofs of the legs of `assembly` (meshing.bodies.Assembly), estimated before
    meshing (the DOF guard's number, model.check_mesh_size)."""
    nodes = sum(NODES_PER_AREA * c.radius * c.length / size**2
                + NODES_PER_CORNER * (c.radius / size) ** 2 + NODES_MIN
                for c in assembly.cylinders)
    return int(3 * len(families(harmonics)) * nodes)


def solve_pose_harmonic(manipulator, geometry, options, max_dofs: int | None = None
                        ) -> HarmonicResult:
    """Natural frequencies and modes of the pose's solid model (rigid platform) with the legs
    by harmonics (module docstring). Harmonics 0 and 1 always; n = 2, 3, ... are added while
    the lowest mode of the next harmonic, over the legs, is not LOWEST_EXCLUDED_MARGIN times
    above the highest frequency solved for (the lowest mode of a cylinder's harmonic rises with
    n: more circumferential strain; measured 23, 36, 47, 58 kHz for n = 2-5 of the paper's
    legs). Runs in this process (2D: a fraction of a second; its per-leg caches serve the next
    pose); `max_dofs` refuses larger raw models once meshed (model.check_mesh_size refuses by
    estimate before)."""
    if options.platform != "rigid":
        raise HarmonicError(f"platform = {options.platform!r}: harmonic legs need the rigid "
                            "platform (legs = 'tetrahedra' meshes an elastic plate)")
    if options.coupling not in COUPLINGS:
        raise HarmonicError(f"coupling = {options.coupling!r}: expected one of "
                            f"{', '.join(COUPLINGS)}")
    t0 = time.perf_counter()
    size = float(options.mesh.size)
    harmonics = (0, 1)
    while True:
        result = _solve(manipulator, geometry, options, harmonics, t0, max_dofs)
        nxt = harmonics[-1] + 1
        bound = LOWEST_EXCLUDED_MARGIN * float(result.frequencies_hz[-1])
        if section_modes_above(manipulator, geometry, size, options.coupling, nxt, bound):
            result.excluded_above_hz = bound
            break
        if nxt > 24:
            raise HarmonicError(f"leg diameter = {manipulator.leg_diameter:g} m: section modes "
                                f"of harmonic {nxt} still below {bound:.4g} Hz, the modes "
                                "solved for (use legs = 'tetrahedra')")
        harmonics = harmonics + (nxt,)
    result.timings["total"] = time.perf_counter() - t0
    return result


def _quality(mesh: MeshTri) -> float:
    p = mesh.p[:, mesh.t]  # (2, 3, nt)
    e = [p[:, (k + 1) % 3] - p[:, k] for k in range(3)]
    area = 0.5 * np.abs(e[0][0] * e[1][1] - e[0][1] * e[1][0])
    return float((4 * math.sqrt(3) * area / sum((v ** 2).sum(axis=0) for v in e)).min())


def _solve(manipulator, geometry, options, harmonics, t0, max_dofs) -> HarmonicResult:
    size, coupling = float(options.mesh.size), options.coupling
    radius = 0.5 * float(manipulator.leg_diameter)
    for length in _leg_lengths(geometry):  # the meshes first, so that "mesh" times them alone
        meridian_mesh(radius, float(length), size)
    t_mesh = time.perf_counter()
    legs = _leg_data(manipulator, geometry, size, harmonics)
    fams = families(harmonics)
    offsets, n_raw = [], 0
    for leg, _ in legs:
        offsets.append(n_raw)
        n_raw += len(fams) * 3 * leg.n_scalar
    if max_dofs is not None and n_raw > max_dofs:
        raise HarmonicError(f"mesh_size_mm = {size * 1e3:g}: {n_raw} harmonic dofs, above max_dofs = "
                            f"{max_dofs}")
    bld = ConstraintBuilder(n_raw)
    o = np.asarray(geometry.platform_centre, float)
    if coupling == "rigid":
        phi = bld.add_extra("phi", len(legs))
        psi = bld.add_extra("psi", 3 * len(legs)).reshape(len(legs), 3)
    plat = bld.add_extra("platform", 6)
    k_blocks, m_blocks = [], []
    for i, ((leg, frame), offset) in enumerate(zip(legs, offsets)):
        n3 = 3 * leg.n_scalar
        e6 = la.block_diag(frame.T, frame.T)  # global (t, theta) -> leg frame
        base = {fam: offset + k * n3 for k, fam in enumerate(fams)}
        for n, _ in fams:
            k_blocks.append(leg.stiffness[n])
            m_blocks.append(leg.mass * (2.0 if n == 0 else 1.0))
        # regularity on the axis; on a rigid face the face's own rule (which agrees) decides
        on_face = np.concatenate(leg.face_nodes)
        axis = leg.axis_nodes
        regular = axis if coupling == "distributing" else np.setdiff1d(axis, on_face)
        for n, fam in fams:
            start = base[(n, fam)] + 3 * regular
            if n == 0:  # U_r = U_t = 0
                bld.dependent[start] = bld.dependent[start + 1] = True
            elif n == 1:  # U_z = 0, U_t = -U_r
                bld.dependent[start + 2] = bld.dependent[start + 1] = True
                bld.entries(start + 1, start, -np.ones(len(start)), extra=False)
            else:
                for c in range(3):
                    bld.dependent[start + c] = True
        for face_index, joint in enumerate(geometry.leg_joints(i)):
            ref = np.asarray(joint.centre, float)
            nodes = leg.face_nodes[face_index]
            if joint.body == "base":
                t_cols = t_vals = None
            else:  # Eq. (10): the platform's motion at the joint centre
                t_cols, t_vals = plat, np.hstack([np.eye(3), -skew(ref - o)])
            if coupling == "rigid":
                r_cols, r_map = rigid_rotation(joint, i, phi, psi, plat)
                rho = leg.node_rz[nodes, 0]
                for n, fam in fams:
                    dofs = base[(n, fam)] + 3 * nodes[:, None] + np.arange(3)  # (nf, 3)
                    bld.dependent[dofs.ravel()] = True
                    if n >= 2:  # held
                        continue
                    h = rigid_face_coefficients(n, fam, rho) @ e6  # (nf, 3, 6), global a
                    rot = h[:, :, 3:] @ r_map
                    bld.entries(np.repeat(dofs[:, :, None], rot.shape[2], 2),
                                np.broadcast_to(r_cols, rot.shape), rot, extra=True)
                    if t_cols is not None:
                        tr = h[:, :, :3] @ t_vals
                        bld.entries(np.repeat(dofs[:, :, None], tr.shape[2], 2),
                                    np.broadcast_to(t_cols, tr.shape), tr, extra=True)
                continue
            # distributing: the face's projected rigid motion (global) over its free dofs
            cols, mats, movable = [], [], []
            on_axis = np.isin(nodes, axis)
            for n, fam in families((0, 1)):
                p = face_projection_coefficients(leg, face_index, n, fam)  # (6, nf, 3)
                if n == 1:  # U_t = -U_r on the axis: its weight moves onto U_r
                    p[:, on_axis, 0] -= p[:, on_axis, 1]
                dofs = (base[(n, fam)] + 3 * nodes[:, None] + np.arange(3)).ravel()
                keep = ~bld.dependent[dofs]
                cols.append(dofs[keep])
                mats.append(p.reshape(6, -1)[:, keep])
                movable.append(~np.repeat(on_axis, 3)[keep])  # referred to: stay independent
            face_dofs = np.concatenate(cols)
            candidates = np.flatnonzero(np.concatenate(movable))
            proj = la.block_diag(frame, frame) @ np.hstack(mats)  # (6, n) global a
            distributing_joint(bld, face_dofs, proj, joint, t_cols, t_vals, True, plat,
                               candidates)
    t_map, _, columns = bld.finish()
    plate = platform_plate(manipulator, geometry)
    kq, mq = reduced_matrices(sp.block_diag(k_blocks, format="csr"),
                              sp.block_diag(m_blocks, format="csr"), t_map,
                              columns["platform"], plate, manipulator, geometry, options)
    t_asm = time.perf_counter()
    try:
        found = lowest_modes(kq, mq, options.modes)
    except EigenError as exc:
        raise HarmonicError(f"mesh_size_mm = {size * 1e3:g}: eigensolver failed ({exc})") from None
    t_end = time.perf_counter()
    v = normalise_signs(found.vectors)
    digest = hashlib.sha256()
    for leg, _ in legs:
        digest.update(np.ascontiguousarray(leg.basis.mesh.p).tobytes())
        digest.update(np.ascontiguousarray(leg.basis.mesh.t).tobytes())
    return HarmonicResult(
        frequencies_hz=found.frequencies_hz, dofs=int(kq.shape[0]), raw_dofs=n_raw,
        mesh_size=size,
        timings={"mesh": t_mesh - t0, "assemble": t_asm - t_mesh, "solve": t_end - t_asm},
        clusters=[list(map(int, c)) for c in found.clusters], mesh_digest=digest.hexdigest(),
        n_elements=int(sum(leg.basis.mesh.t.shape[1] for leg, _ in legs)), options=options,
        min_quality=min(_quality(leg.basis.mesh) for leg, _ in legs),
        harmonics=tuple(harmonics), excluded_above_hz=math.nan, geometry=geometry,
        modes_q=v, modes_raw=t_map @ v, columns=columns,
        legs=[(leg, frame, off) for (leg, frame), off in zip(legs, offsets)], plate=plate)
