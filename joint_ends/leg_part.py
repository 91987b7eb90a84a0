"""A whole leg part condensed from its solid of revolution onto section nodes (`legs = "solid"`).

A part (a uniform leg, a housing or a rod: a solid or hollow circular cylinder of length L) is
meshed on its meridian and solved in Fourier harmonics in the polar angle, as the FEM
reference's harmonic legs are (`fem_reference.meridian`: P2 triangles graded toward the coupled
rims, K_n and M per harmonic). A rigid motion of a section is harmonics 0 and 1 only, and so is
every coupling below, so harmonics n >= 2 meet no master and the condensation is exact with
n = 0 and n = 1 (cos and sin) alone: no mesh in the polar angle, no averaging over turns.

The masters are s + 1 section nodes at x_k = k L / s (x along the axis from the part's first
face), each with a translation and a rotation in the part's frame (x along the axis, y and z
across, as a frame element's):

- the two end faces (k = 0 and k = s) are tied to their node as the FEM ties a coupled face
  (`couplings`): "rigid", every face node follows the node rigidly (harmonics 0 and 1 of the
  face, `fem_reference.harmonic_faces.rigid_face_coefficients`; n >= 2 held); "distributing",
  the node is the face's L2 rigid-motion projection;
- every interior station is a section of the continuing solid, its node the section's L2
  rigid-motion projection (the definition of a section's motion both models use): the solid
  runs through it untouched, only its mean rigid motion is named.

Static condensation (Guyan) onto the 6 (s + 1) masters: the constraint modes minimise the
strain energy for each unit master motion (one saddle-point solve with the couplings and the
projections as constraints, as `zone.condense` does for an end zone's twelve), K = Psi^T K Psi
and M = Psi^T M Psi. The part's
inertia between stations is carried by the static shapes, so the model converges from above as
s grows (measured in joint_ends/README.md, "Solid legs").

Why a whole part and not a beam with end zones: on a short thick tube (a 110/80 mm housing
3-5 diameters long) no beam with any end springs reproduces the solid under a distributed
(inertial) load; the measurements are in docs/legs.md.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from common.errors import InputError
from common.joints import COUPLINGS
from common.settings import check_settings, setting

# the harmonic frame (x, y across, z along the axis) from the part's frame (x along the axis):
# h = (l_y, l_z, l_x), a proper rotation, so translations and rotations map alike
_TO_HARMONIC = np.kron(np.eye(2), np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]))
_FAMILIES = ((0, "c"), (1, "c"), (1, "s"))


@dataclass(frozen=True)
class PartMesh:
    """How finely a condensed leg part's meridian is meshed (chosen by the convergence study in
    joint_ends/README.md, "Solid legs")."""

    size: float = setting(1.0, doc="meridian element size, in outer radii of the part (a "
                          "tube's wall always gets at least two P2 elements across: "
                          "fem_reference.meridian.part_size)", minimum=0.0,
                          exclusive_minimum=True, maximum=2.0)

    def __post_init__(self):
        check_settings(self)


@dataclass(frozen=True)
class PartModel:
    """The condensed part in its frame: nodes k = 0..s at x_k = k L / s, each (t, theta)."""

    stiffness: np.ndarray  # (6 (s + 1), 6 (s + 1)), SI
    mass: np.ndarray  # (6 (s + 1), 6 (s + 1))
    length: float  # L, m
    raw_dofs: int  # dofs of the harmonic solid (harmonics 0, 1c, 1s)


def build_part(outer: float, inner: float, length: float, stations: int,
               youngs_modulus: float, shear_modulus: float, density: float,
               couplings: tuple[str, str], mesh: PartMesh = PartMesh()) -> PartModel:
    """Mesh, assemble and condense one leg part onto `stations` + 1 section nodes (module
    doc). SI units; `inner` 0 for a solid part; `couplings` ties the face at x = 0 and the one
    at x = L."""
    system = _part_system(outer, inner, length, stations, youngs_modulus, shear_modulus,
                          density, couplings, mesh)
    k, m = system.condensed(1.0)
    return PartModel(k, m, float(length), system.raw_dofs)


@dataclass(frozen=True)
class _PartSystem:
    """A part's harmonic solid on one meridian mesh, stretchable along its axis: K(sigma) =
    sigma K_a + K_b + K_c / sigma and M(sigma) = sigma M (`meridian_stiffness_terms`), with
    its ties C_u u = C_a a, which the stretch leaves alone (they weigh the faces and sections
    in r only)."""

    terms: tuple  # (K_a, K_b, K_c), sparse, harmonics (0c, 1c, 1s)
    mass: sp.csc_matrix  # M at sigma = 1
    c_u: sp.csc_matrix
    c_a: sp.csr_matrix

    @property
    def raw_dofs(self) -> int:
        return self.mass.shape[0]

    def condensed(self, sigma: float) -> tuple[np.ndarray, np.ndarray]:
        """Guyan K and M of the part stretched by `sigma`, on its 6 (s + 1) masters."""
        import scipy.sparse.linalg as sla

        k_a, k_b, k_c = self.terms
        k = (sigma * k_a + k_b + k_c / sigma).tocsc()
        # Guyan constraint modes: Psi minimises the strain energy subject to C_u u = C_a a for
        # each unit master motion a, [[K, C_u^T], [C_u, 0]] [Psi; Lambda] = [0; C_a]. The
        # constraint rows are scaled to the stiffness (the multipliers' units): the saddle
        # point is then balanced and the rigid-body modes come out to round-off, not to 1e-6.
        diagonal = k.diagonal()
        scale = float(np.median(np.abs(diagonal[diagonal != 0.0])))
        saddle = sp.bmat([[k, scale * self.c_u.T], [scale * self.c_u, None]], format="csc")
        rhs = np.vstack([np.zeros((k.shape[0], self.c_a.shape[1])),
                         scale * self.c_a.toarray()])
        psi = sla.splu(saddle).solve(rhs)[:k.shape[0]]
        k_red, m_red = psi.T @ (k @ psi), sigma * (psi.T @ (self.mass @ psi))
        return 0.5 * (k_red + k_red.T), 0.5 * (m_red + m_red.T)


def _part_system(outer, inner, length, stations, youngs_modulus, shear_modulus, density,
                 couplings, mesh: PartMesh) -> _PartSystem:
    from fem_reference.assembly import lame
    from fem_reference.meridian import (
        meridian,
        meridian_mass,
        meridian_stiffness_terms,
        part_size,
    )

    from .zone import Solid

    for name, value in zip(("first face", "last face"), couplings):
        if value not in COUPLINGS:
            raise InputError(f"{name} coupling = {value!r}: expected one of "
                             f"{', '.join(COUPLINGS)}")
    if not (stations >= 1 and length > 0.0 and outer > inner >= 0.0):
        raise InputError(f"leg part of {outer * 1e3:g}/{inner * 1e3:g} mm, {length * 1e3:g} mm "
                         f"long, {stations} stations: not a part")
    radius, bore = outer / 2.0, inner / 2.0
    lam, mu = lame(Solid(youngs_modulus, shear_modulus, density))
    sections = tuple(float(length) * k / stations for k in range(1, stations))
    part = meridian(radius, float(length), part_size(mesh.size * radius, radius, bore), bore,
                    sections)
    per_n = {n: meridian_stiffness_terms(part.basis, lam, mu, n) for n in (0, 1)}
    terms = tuple(sp.block_diag([per_n[0][j], per_n[1][j], per_n[1][j]], format="csc")
                  for j in range(3))
    unit = meridian_mass(part.basis)
    m = density * sp.block_diag([2.0 * unit, unit, unit], format="csc")
    c_u, c_a = _constraints(part, couplings, stations)
    return _PartSystem(terms, m, c_u.tocsc(), c_a)


# A piece of a part's stroke: the part meshed once at the geometric middle of [lo, hi] and
# stretched to every length in it (its matrices exact in the stretch, `_PartSystem`), its
# condensed K and M interpolated in the length on PIECE_NODES Chebyshev points. Pieces are
# a fixed geometric grid of ratio PIECE_RATIO from PIECE_ANCHOR, so a piece is the same for
# every machine with that part (a cache entry names the part, not the machine). The ratio is
# the stretch the mesh takes: at 1.25 (sigma within 0.89-1.12 of the meshed length) the
# frequencies of a stretched part are those of a fresh mesh to the mesh's own error (measured
# in joint_ends/README.md, "Solid legs over the stroke").
PIECE_RATIO = 1.25
PIECE_ANCHOR = 1e-3  # m
PIECE_NODES = 12
PIECE_TAIL = 1e-9  # largest last-two-coefficients size, relative to the matrices', accepted


def piece_index(length) -> np.ndarray:
    """The grid piece holding each length (`PIECE_RATIO`)."""
    return np.floor(np.log(np.asarray(length, float) / PIECE_ANCHOR)
                    / math.log(PIECE_RATIO)).astype(int)


def piece_bounds(index: int) -> tuple[float, float]:
    lo = PIECE_ANCHOR * PIECE_RATIO ** int(index)
    return lo, lo * PIECE_RATIO


# One condensation of a part (the saddle point's sparse LU and its 6 (s + 1) solves), seconds
# per raw dof as estimated before meshing (`piece_seconds`, whose node count is an upper
# bound: 0.4-0.8 of it are meshed): on one core of the development machine (AMD EPYC) the
# actuator-legs scene's whole build (seven rod pieces, the housing, the reduction's choice)
# took 9.1-9.2 s against 28 s estimated at 2.5e-5, so 1e-5 says it with a margin of ~1.2.
SECONDS_PER_RAW_DOF = 1e-5


def piece_seconds(outer: float, inner: float, index: int, mesh: PartMesh = PartMesh()
                  ) -> float:
    """About how long `build_piece` takes for grid piece `index` of this part (its raw dofs
    estimated before meshing, `fem_reference.meridian.estimate_nodes`)."""
    from fem_reference.meridian import estimate_nodes

    lo, hi = piece_bounds(index)
    radius = outer / 2.0
    nodes = estimate_nodes(radius, math.sqrt(lo * hi), mesh.size * radius, inner / 2.0)
    return PIECE_NODES * SECONDS_PER_RAW_DOF * 9.0 * nodes  # 3 components x (0c, 1c, 1s)


@dataclass(frozen=True)
class PartPiece:
    """A part's condensed K and M over the lengths [lo, hi]: Chebyshev coefficients in
    x = (2 L - lo - hi) / (hi - lo), T_0 first."""

    lo: float
    hi: float
    stiffness: np.ndarray  # (PIECE_NODES, 6 (s + 1), 6 (s + 1))
    mass: np.ndarray
    tail: float  # the last two coefficients' size relative to the matrices': the error estimate
    raw_dofs: int

    def at(self, lengths) -> tuple[np.ndarray, np.ndarray]:
        """K and M (*lengths.shape, d, d) at lengths within [lo, hi]."""
        lengths = np.asarray(lengths, float)
        x = (2.0 * lengths - self.lo - self.hi) / (self.hi - self.lo)
        if np.any(np.abs(x) > 1.0 + 1e-9):
            raise ValueError(f"lengths {lengths.min():.9g}-{lengths.max():.9g} m outside the "
                             f"piece [{self.lo:.9g}, {self.hi:.9g}] m")
        t = np.polynomial.chebyshev.chebvander(np.clip(x, -1.0, 1.0).ravel(),
                                               len(self.stiffness) - 1).reshape(*x.shape, -1)
        return (np.tensordot(t, self.stiffness, axes=1), np.tensordot(t, self.mass, axes=1))


def build_piece(outer: float, inner: float, index: int, stations: int, youngs_modulus: float,
                shear_modulus: float, density: float, couplings: tuple[str, str],
                mesh: PartMesh = PartMesh()) -> PartPiece:
    """The part over grid piece `index` (`piece_bounds`): meshed at the piece's geometric
    middle, condensed at PIECE_NODES Chebyshev lengths, interpolated (`PartPiece`)."""
    lo, hi = piece_bounds(index)
    middle = math.sqrt(lo * hi)
    system = _part_system(outer, inner, middle, stations, youngs_modulus, shear_modulus,
                          density, couplings, mesh)
    x = np.polynomial.chebyshev.chebpts1(PIECE_NODES)
    lengths = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x
    values = [system.condensed(length / middle) for length in lengths]
    out = []
    for which in (0, 1):
        stacked = np.stack([v[which] for v in values])  # (p, d, d)
        coefficients = np.polynomial.chebyshev.chebfit(x, stacked.reshape(len(x), -1),
                                                       PIECE_NODES - 1)
        out.append(coefficients.reshape(stacked.shape))
    tail = max(float(np.abs(c[-2:]).max() / np.abs(c[0]).max()) for c in out)
    return PartPiece(lo, hi, out[0], out[1], tail, system.raw_dofs)


def _constraints(part, couplings, stations: int):
    """(C_u, C_a): C_u u = C_a a for every tie of the part (module doc) and the regularity of
    harmonics 0 and 1 on the axis of a solid part; u in blocks (0c, 1c, 1s) of 3 n_s dofs,
    a the 6 (s + 1) masters in the part's frame."""
    from fem_reference.harmonic_faces import (
        face_projection_coefficients,
        rigid_face_coefficients,
    )

    n3 = 3 * part.n_scalar
    base = {family: j * n3 for j, family in enumerate(_FAMILIES)}
    rows_u: list[tuple] = []  # (row, column, value) of C_u
    rows_a: list[tuple] = []  # (row, master, value) of C_a
    count = 0
    rigid_nodes = []
    for station in range(stations + 1):
        nodes = part.face_nodes[station]
        how = (couplings[0] if station == 0 else couplings[1] if station == stations
               else "distributing")
        masters = 6 * station + np.arange(6)
        if how == "rigid":
            rigid_nodes.append(nodes)
            rho = part.node_rz[nodes, 0]
            for family in _FAMILIES:
                h = rigid_face_coefficients(*family, rho) @ _TO_HARMONIC  # (nf, 3, 6)
                for c in range(3):
                    dofs = base[family] + 3 * nodes + c
                    for j, dof in enumerate(dofs):
                        rows_u.append((count, dof, 1.0))
                        rows_a.extend((count, masters[q], h[j, c, q]) for q in range(6)
                                      if h[j, c, q] != 0.0)
                        count += 1
            continue
        projection = np.hstack([face_projection_coefficients(part, station, *f).reshape(6, -1)
                                for f in _FAMILIES])
        projection = _TO_HARMONIC.T @ projection  # the part's frame
        dofs = np.concatenate([(base[f] + 3 * nodes[:, None] + np.arange(3)).ravel()
                               for f in _FAMILIES])
        for q in range(6):
            used = np.flatnonzero(projection[q])
            rows_u.extend((count, dofs[j], projection[q, j]) for j in used)
            rows_a.append((count, masters[q], 1.0))
            count += 1
    axis = part.axis_nodes
    if len(axis) and rigid_nodes:  # a rigid face's own rule holds its axis node
        axis = np.setdiff1d(axis, np.concatenate(rigid_nodes))
    for node in axis:  # n = 0: U_r = U_t = 0; n = 1: U_z = 0, U_t = -U_r
        zero = base[(0, "c")] + 3 * node
        for dof in (zero, zero + 1):
            rows_u.append((count, dof, 1.0))
            count += 1
        for family in _FAMILIES[1:]:
            one = base[family] + 3 * node
            rows_u.append((count, one + 2, 1.0))
            count += 1
            rows_u.extend([(count, one + 1, 1.0), (count, one, 1.0)])
            count += 1
    shape_u, shape_a = (count, 3 * n3), (count, 6 * (stations + 1))
    c_u = _coo(rows_u, shape_u)
    c_a = _coo(rows_a, shape_a)
    return c_u, c_a


def _coo(entries, shape) -> sp.csr_matrix:
    if not entries:
        return sp.csr_matrix(shape)
    r, c, v = (np.asarray(x) for x in zip(*entries))
    return sp.csr_matrix((v.astype(float), (r.astype(int), c.astype(int))), shape=shape)


def part_mass(outer: float, inner: float, length: float, density: float) -> float:
    """rho pi (D^2 - d^2) L / 4: what the condensed mass must carry as a rigid body."""
    return density * math.pi * (outer**2 - inner**2) * length / 4.0
