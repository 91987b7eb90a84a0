"""One leg part of the harmonic model: its 2D meridian mesh and the matrices of its harmonics.

The meridian rectangle [r_in, R] x [0, L] of a part (a solid cylinder, r_in = 0, or a tube;
gmsh, linear triangles graded toward the rim corners, P2 on them: (R, 0) and (R, L), and for a
tube (r_in, 0) and (r_in, L) too), K_n and M of harmonic n on it, and the layout of a
part's raw dofs: blocks (n, family), n = 0 once and n >= 1 twice (c, s), each 3 s + c with
c = (r, t, z). The equations are in `harmonic.py`'s docstring. Everything here is remembered
per process (same leg, same mesh). Also the estimate of a leg's raw dofs before meshing, the
DOF guard's number (`guard.check_mesh_size`).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from skfem import Basis, ElementTriP2, FacetBasis, LinearForm, MeshTri

from common.errors import InputError
from meshing.geometry import GmshFailure, gmsh_session

from .assembly import lame

AXIS_TOL = 1e-12  # relative to R: a node on the axis
FACE_TOL = 1e-12  # relative to L: a node on an end face


class HarmonicError(InputError):
    """Bad input or a failed step of the harmonic model; one line naming the value."""


# The meridian's grading toward each rim corner: size h (distance / (CORNER_ZONE R)), at least
# CORNER_FACTOR h. Measured on paper.toml case 2 (both couplings alike), max error over f1-f6
# against a 0.15 R mesh graded to 0.005: at h = 0.8 R (40 mm) 0.006 % with 7.8k dofs (0.4 h
# within 0.3 R, the tetrahedra's rim grading: 0.05 %; 0.01 within R: 0.005 % with 11k dofs);
# at h = 0.5 R 0.002 %. In 2D deep grading costs little: a point, not an edge, is refined.
CORNER_FACTOR = 0.05
CORNER_ZONE = 1.0  # walls: the radius of a solid part, R - r_in of a tube


def part_size(size: float, radius: float, inner: float = 0.0) -> float:
    """The meridian's element size of a part. A solid part: the global size h (the guard keeps
    h below the leg's diameter). A tube of wall w = R - r_in and outer diameter D = 2 R:
    min(h, w / 2, w h / D): at least two P2 elements span the wall at any h (a thin wall bends
    through its thickness), and for h <= D / 2 (every refinement study's sizes) the size is
    proportional to h, so a study refines the wall too (min(h, w / 2) alone would freeze the
    wall's mesh for every h above w / 2, and the study would see no change and state none)."""
    if inner <= 0.0:
        return float(size)
    wall = radius - inner
    return min(float(size), 0.5 * wall, wall * float(size) / (2.0 * radius))


# ---------------------------------------------------------------- meridian mesh (gmsh, 2D)

@functools.lru_cache(maxsize=64)
def meridian_mesh(radius: float, length: float, size: float, inner: float = 0.0,
                  sections: tuple = ()) -> MeshTri:
    """Linear triangles of the rectangle [r_in, R] x [0, L] (x = r, y = z), graded toward the
    rim corners (R, 0) and (R, L) (and (r_in, 0), (r_in, L) of a tube: every end face of a
    part is coupled); the P2 basis adds the mid-edge nodes (straight edges: the geometry is
    exact). `sections`: interior heights 0 < z < L where the mesh has a line of nodes across
    the wall (the stations of a condensed part, `joint_ends.leg_part`). `size` is the part's
    (`part_size`). Read-only, remembered per process."""
    h = float(size)
    h_min = h * CORNER_FACTOR
    zone = CORNER_ZONE * (radius - inner)
    heights = [0.0, *sorted(float(z) for z in sections), float(length)]
    try:
        with gmsh_session({"Mesh.ElementOrder": 1, "Mesh.MeshSizeMax": h,
                           "Mesh.MeshSizeMin": h_min}) as gmsh:
            model = gmsh.model
            model.add("meridian")
            geo = model.geo
            if not sections:  # one rectangle (the FEM's legs: the same mesh as always)
                corners = [geo.addPoint(inner, 0, 0), geo.addPoint(radius, 0, 0),
                           geo.addPoint(radius, length, 0), geo.addPoint(inner, length, 0)]
                lines = [geo.addLine(corners[k], corners[(k + 1) % 4]) for k in range(4)]
                geo.addPlaneSurface([geo.addCurveLoop(lines)])
            else:  # rectangles stacked on the section lines
                inside = [geo.addPoint(inner, z, 0) for z in heights]
                outside = [geo.addPoint(radius, z, 0) for z in heights]
                across = [geo.addLine(a, b) for a, b in zip(inside, outside)]
                for k in range(len(heights) - 1):
                    up_out = geo.addLine(outside[k], outside[k + 1])
                    up_in = geo.addLine(inside[k + 1], inside[k])
                    geo.addPlaneSurface([geo.addCurveLoop([across[k], up_out, -across[k + 1],
                                                           up_in])])
                corners = [inside[0], outside[0], outside[-1], inside[-1]]
            geo.synchronize()
            dist = model.mesh.field.add("Distance")
            rims = corners if inner > 0 else [corners[1], corners[2]]
            model.mesh.field.setNumbers(dist, "PointsList", rims)
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
    for col, lo, hi in ((0, float(inner), radius), (1, 0.0, length)):
        scale = hi - lo
        p[np.abs(p[:, col] - lo) <= 1e-12 * scale, col] = lo
        p[np.abs(p[:, col] - hi) <= 1e-12 * scale, col] = hi
    for z in heights[1:-1]:
        p[np.abs(p[:, 1] - z) <= 1e-12 * length, 1] = z
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
    axis_nodes: np.ndarray  # scalar nodes at r = 0 (none for a tube)
    face_nodes: tuple  # (nodes at z = 0, nodes at z = L)
    face_weights: tuple  # per face: (W1, W2) = (int phi r dr, int phi r^2 dr) over the face
    inner: float = 0.0  # bore radius r_in (0: a solid part)

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
def meridian(radius: float, length: float, size: float, inner: float = 0.0,
             sections: tuple = ()) -> Meridian:
    """The part's meridian (read-only, remembered per process: same part, same mesh). With
    interior `sections` (heights, `meridian_mesh`), `face_nodes` and `face_weights` hold every
    line across the wall in z order: the face at z = 0, the sections, the face at z = L."""
    if sections:
        mesh = meridian_mesh(radius, length, size, inner, tuple(sections))
    else:
        mesh = meridian_mesh(radius, length, size, inner) if inner else meridian_mesh(
            radius, length, size)
    basis = Basis(mesh, ElementTriP2(), intorder=6)
    locs = basis.doflocs.T  # (n_s, 2)
    axis = (np.flatnonzero(locs[:, 0] <= AXIS_TOL * radius) if not inner
            else np.zeros(0, np.int64))
    faces, weights = [], []
    for z0 in (0.0, *sorted(sections), length):
        facets = mesh.facets_satisfying(lambda x, z0=z0: np.abs(x[1] - z0) <= FACE_TOL * length)
        fb = FacetBasis(mesh, ElementTriP2(), facets=facets, intorder=6)
        on = np.flatnonzero(np.abs(locs[:, 1] - z0) <= FACE_TOL * length)
        faces.append(on)
        weights.append(tuple(LinearForm(lambda v, p, k=k: v * p.x[0] ** k).assemble(fb)[on]
                             for k in (1, 2)))
    if (len(axis) < 3 and not inner) or any(len(f) < 3 for f in faces):
        raise HarmonicError(f"meridian mesh of R = {radius:g} m, L = {length:g} m: "
                            f"{len(axis)} nodes on the axis, {[len(f) for f in faces]} on the "
                            "faces (expected the boundary lines meshed)")
    if inner:
        return Meridian(radius, length, basis, locs, axis, tuple(faces), tuple(weights),
                        float(inner))
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


def _meridian(radius: float, length: float, size: float, inner: float) -> Meridian:
    return meridian(radius, length, size, inner) if inner else meridian(radius, length, size)


@functools.lru_cache(maxsize=256)
def harmonic_stiffness(radius: float, length: float, size: float, lam: float, mu: float,
                       n: int, inner: float = 0.0) -> sp.csr_matrix:
    """K_n = w_n int B^T D B r dr dz of one part (read-only, remembered per process)."""
    return meridian_stiffness(_meridian(radius, length, size, inner).basis, lam, mu, n)


def _elasticity(lam: float, mu: float) -> np.ndarray:
    d = np.zeros((6, 6))
    d[:3, :3] = lam
    d[[0, 1, 2], [0, 1, 2]] += 2 * mu
    d[[3, 4, 5], [3, 4, 5]] = mu
    return d


def _vector_dofs(basis: Basis) -> np.ndarray:
    nodes = basis.element_dofs  # (6, ne) scalar nodes -> (18, ne) dofs 3 s + c, node-major
    return (3 * nodes[:, None, :] + np.arange(3)[None, :, None]).reshape(-1, nodes.shape[1])


def meridian_stiffness(basis: Basis, lam: float, mu: float, n: int) -> sp.csr_matrix:
    """K_n = w_n int B^T D B r dr dz of harmonic n on any meridian (a P2 basis on a mesh of
    r >= 0, x = r, y = z): dofs 3 s + c, c = (r, t, z); w_0 = 2 pi, w_n = pi."""
    values, grads, r, w = _element_arrays(basis)
    b = _strain_operator(values, grads, r, n)
    weight = 2 * math.pi if n == 0 else math.pi
    ke = weight * np.einsum("eqsa,st,eqtb,eq->eab", b, _elasticity(lam, mu), b, w,
                            optimize=True)
    return _sparse(_vector_dofs(basis), ke, 3 * basis.N)


def meridian_stiffness_terms(basis: Basis, lam: float, mu: float, n: int
                             ) -> tuple[sp.csr_matrix, sp.csr_matrix, sp.csr_matrix]:
    """(K_a, K_b, K_c) of harmonic n such that the meridian stretched along its axis by sigma
    (z -> sigma z, its nodes moved with it) has K_n(sigma) = sigma K_a + K_b + K_c / sigma
    exactly, and M(sigma) = sigma M (`meridian_mass`). The strains split into B_a, the terms
    without a z-derivative (rr, tt, rt, and the u / r and d/dr terms of tz and rz), and B_z,
    the terms with one, which the stretch divides by sigma; the volume r dr dz is multiplied by
    sigma. K_a = int B_a^T D B_a, K_b the two cross terms, K_c = int B_z^T D B_z, each with
    w_n as `meridian_stiffness`: their sum is K_n at sigma = 1."""
    values, grads, r, w = _element_arrays(basis)
    across = grads.copy()
    across[:, 1] = 0.0  # d/dz removed: the strains that do not scale with the stretch
    b_a = _strain_operator(values, across, r, n)
    b_z = _strain_operator(values, grads, r, n) - b_a  # linear in the gradients
    weight = 2 * math.pi if n == 0 else math.pi
    d = _elasticity(lam, mu)
    dofs, size = _vector_dofs(basis), 3 * basis.N

    def term(left, right):
        return _sparse(dofs, weight * np.einsum("eqsa,st,eqtb,eq->eab", left, d, right, w,
                                                optimize=True), size)

    cross = weight * np.einsum("eqsa,st,eqtb,eq->eab", b_a, d, b_z, w, optimize=True)
    return (term(b_a, b_a), _sparse(dofs, cross + np.swapaxes(cross, 1, 2), size),
            term(b_z, b_z))


@functools.lru_cache(maxsize=64)
def unit_mass(radius: float, length: float, size: float, inner: float = 0.0) -> sp.csr_matrix:
    """pi int N^T N r dr dz on dofs 3 s + c, density 1 (read-only, remembered per process):
    the scalar P2 mass times the 3 x 3 identity."""
    return meridian_mass(_meridian(radius, length, size, inner).basis)


def meridian_mass(basis: Basis) -> sp.csr_matrix:
    """pi int N^T N r dr dz on dofs 3 s + c of any meridian, density 1 (harmonic n >= 1's
    mass; n = 0's is twice it)."""
    values, _, _, w = _element_arrays(basis)
    scalar = _sparse(basis.element_dofs,
                     np.einsum("aeq,beq,eq->eab", values, values, w, optimize=True), basis.N)
    out = math.pi * sp.kron(scalar, sp.identity(3), format="csr")
    out.data.setflags(write=False)
    return out


def leg_harmonics(radius: float, length: float, lam: float, mu: float, density: float,
                  size: float, harmonics: tuple, inner: float = 0.0) -> LegHarmonics:
    """One part's meridian with K_n (n in `harmonics`) and M, from the per-process caches
    (`size`: the part's own, `part_size`)."""
    m = _meridian(radius, length, size, inner)
    extra = (inner,) if inner else ()
    return LegHarmonics(**{f: getattr(m, f) for f in Meridian.__dataclass_fields__},
                        stiffness={n: harmonic_stiffness(radius, length, size, lam, mu, n,
                                                         *extra) for n in harmonics},
                        mass=density * unit_mass(radius, length, size, *extra))


def families(harmonics) -> list[tuple[int, str]]:
    """(n, family) blocks of a leg's raw dofs, in order: n = 0 once, n >= 1 twice (c, s)."""
    return [(n, f) for n in harmonics for f in (("c",) if n == 0 else ("c", "s"))]


def leg_frame(geometry, leg: int) -> np.ndarray:
    """(3, 3) columns e1, e2, e3: e3 along the leg from B_i to A_i, e1 and e2 the limb frame's
    other two axes (a right-handed turn of its columns)."""
    f = np.asarray(geometry.leg_frames[leg], float)
    return np.column_stack([f[:, 1], f[:, 2], f[:, 0]])


def leg_material(manipulator) -> tuple[float, float, float]:
    """(lambda, mu, density) of the legs' material."""
    lam, mu = lame(manipulator.material)
    return float(lam), float(mu), float(manipulator.material.density)


def leg_lengths(geometry) -> np.ndarray:
    """|A_i - B_i|, rounded so that one leg length is one cache key."""
    return np.round(np.linalg.norm(np.asarray(geometry.platform_points, float)
                                   - np.asarray(geometry.base_points, float), axis=1), 12)


@dataclass(frozen=True)
class PartHarmonics:
    """One part of one leg in a pose: its harmonics, the leg's frame, which leg, where along
    it the part starts (m from B_i) and its name ("leg" for a uniform leg)."""

    leg: LegHarmonics
    frame: np.ndarray
    index: int
    start: float
    name: str = "leg"


def pose_parts(manipulator, geometry) -> list[list]:
    """Per leg, its parts (`common.leg_profile.LegPart`, base joint first) at the pose's leg
    length (rounded, `leg_lengths`: one leg length, one cache key); a part's length is rounded
    the same way."""
    lengths = leg_lengths(geometry)
    profile = getattr(manipulator, "leg_parts", None)
    out = []
    for length in lengths:
        if profile is None:
            from common.leg_profile import LegPart
            out.append([LegPart("leg", 0.0, float(length), float(manipulator.leg_diameter))])
        else:
            out.append(list(profile(float(length))))
    return out


def part_data(manipulator, geometry, size: float, harmonics,
              longest_only: bool = False) -> list[PartHarmonics]:
    """Every part of every leg (base joint first, leg by leg), or, `longest_only`, for each
    part of the profile the longest leg's only (a longer part with held faces holds a shorter
    one's admissible fields: its modes are lower, min-max)."""
    lam, mu, rho = leg_material(manipulator)
    parts = pose_parts(manipulator, geometry)
    chosen = [(i, k) for i in range(geometry.leg_count) for k in range(len(parts[i]))]
    if longest_only:
        chosen = [(int(np.argmax([round(parts[i][k].end - parts[i][k].start, 12)
                                  for i in range(geometry.leg_count)])), k)
                  for k in range(len(parts[0]))]
    out = []
    for i, k in chosen:
        p = parts[i][k]
        length = float(p.end) if p.start == 0.0 else round(float(p.end - p.start), 12)
        radius, inner = 0.5 * float(p.outer), 0.5 * float(p.inner)
        h = part_size(size, radius, inner)
        out.append(PartHarmonics(leg_harmonics(radius, length, lam, mu, rho, h,
                                               tuple(harmonics), inner),
                                 leg_frame(geometry, i), i, float(p.start), p.name))
    return out


def leg_data(manipulator, geometry, size: float, harmonics,
             longest_only: bool = False) -> list:
    """Per leg part (`part_data`; one per leg for uniform legs): (LegHarmonics, frame)."""
    return [(p.leg, p.frame) for p in part_data(manipulator, geometry, size, harmonics,
                                                longest_only)]


def mesh_quality(mesh: MeshTri) -> float:
    """Smallest triangle quality 4 sqrt(3) area / sum of squared edges (1: equilateral)."""
    p = mesh.p[:, mesh.t]  # (2, 3, nt)
    e = [p[:, (k + 1) % 3] - p[:, k] for k in range(3)]
    area = 0.5 * np.abs(e[0][0] * e[1][1] - e[0][1] * e[1][0])
    return float((4 * math.sqrt(3) * area / sum((v ** 2).sum(axis=0) for v in e)).min())


# P2 nodes of a leg's graded meridian: NODES_PER_AREA R L / h^2 + NODES_PER_CORNER (R / h)^2
# + NODES_MIN, fitted on 36 meshes (R 15-75 mm, L 0.3-1 m, h 0.2-1.6 R), then raised by 1.5 so
# that no mesh has more (actual / estimate 0.37-0.84 on the five scenes' legs, 0.1-0.8 d).
# A tube: its wall w = R - r_in for R, at its own size h' = min(h, w / 2) (`part_size`), and
# its four graded corners twice the two of a solid part.
NODES_PER_AREA, NODES_PER_CORNER, NODES_MIN = 7.8, 70.0, 255.0


def estimate_raw_dofs(assembly, size: float, harmonics=(0, 1)) -> int:
    """Raw harmonic dofs of the legs' parts of `assembly` (meshing.bodies.Assembly: its
    cylinders and tubes), estimated before meshing (the DOF guard's number,
    guard.check_mesh_size)."""
    nodes = sum(estimate_nodes(c.radius, c.length, size, c.inner_radius)
                for c in assembly.cylinders)
    return int(3 * len(families(harmonics)) * nodes)


def estimate_nodes(radius: float, length: float, size: float, inner: float = 0.0) -> float:
    """P2 nodes of one part's graded meridian, estimated before meshing (the fit above; `size`
    the global one, the part's own from `part_size`)."""
    wall = radius - inner
    h = part_size(size, radius, inner)
    corners = 2.0 if inner > 0 else 1.0
    return (NODES_PER_AREA * wall * length / h**2 + corners * NODES_PER_CORNER * (wall / h) ** 2
            + NODES_MIN)
