"""Bodies of revolution by circumferential harmonics: the project's own meridian matrices
(`fem_reference.meridian.meridian_stiffness(basis, lam, mu, n)`, `meridian_mass(basis)`) on a
P2 mesh of the meridian, solved with the project's `lowest_modes`.

The meridian is a rectangle [r0, r1] x [z0, z1] (x = r, y = z) away from the axis (r0 > 0: a
tube, a ring), cut into nr x nz cells of size close to h, two triangles each (skfem
`MeshTri.init_tensor`), or the half annulus of a hollow sphere, a <= rho <= b, 0 <= phi <= pi,
meshed in (rho, phi) and mapped with its mid-edge nodes (`MeshTri2`: isoparametric P2, both
circles exact at the nodes), which meets the axis: there harmonic 0 is regular with U_r = U_t
= 0 (`solve_harmonic(axis=True)`, the project's own rule, `fem_reference.harmonic`).
Dofs 3 s + c, c = (r, t, z); for n = 0 the stiffness carries the weight 2 pi and the mass is
twice `meridian_mass` (pi).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from skfem import Basis, ElementTriP2, MeshTri, MeshTri2

from fem_reference.assembly import Material, lame
from fem_reference.eigen import lowest_modes
from fem_reference.meridian import meridian_mass, meridian_stiffness


def rectangle_basis(r0: float, r1: float, z0: float, z1: float, size: float) -> Basis:
    """The scalar P2 basis on the rectangle [r0, r1] x [z0, z1] cut into cells no larger than
    `size` (m) per side (at least one per side), two triangles per cell."""
    nr = max(1, math.ceil((r1 - r0) / size - 1e-9))
    nz = max(1, math.ceil((z1 - z0) / size - 1e-9))
    mesh = MeshTri.init_tensor(np.linspace(r0, r1, nr + 1), np.linspace(z0, z1, nz + 1))
    return Basis(mesh, ElementTriP2(), intorder=6)


def shell_basis(inner: float, outer: float, size: float) -> Basis:
    """The scalar P2 basis on the meridian of a hollow sphere (radii `inner` < `outer`): the
    (rho, phi) rectangle [inner, outer] x [0, pi] in cells no larger than `size` (m; along phi
    at the mean radius), each node mapped to r = rho sin phi, z = -rho cos phi (positive
    orientation), so the elements are curved and both spheres exact at the nodes."""
    nr = max(1, math.ceil((outer - inner) / size - 1e-9))
    nphi = max(2, math.ceil(math.pi * 0.5 * (inner + outer) / size - 1e-9))
    flat = MeshTri2.from_mesh(MeshTri.init_tensor(np.linspace(inner, outer, nr + 1),
                                                  np.linspace(0.0, math.pi, nphi + 1)))
    rho, phi = flat.doflocs
    rz = np.vstack([rho * np.sin(phi), -rho * np.cos(phi)])
    rz[0][np.abs(rz[0]) <= 1e-12 * outer] = 0.0  # sin(pi) is not 0 in floating point
    return Basis(MeshTri2(rz, flat.t), ElementTriP2(), intorder=6)


@dataclass
class HarmonicModes:
    """The lowest modes of one harmonic n on a meridian: frequencies (Hz, ascending), vectors
    on all 3 N dofs (3 s + c, c = (r, t, z); dofs not solved are zero), the free dof count and
    the mass matrix (for energy fractions by component)."""

    hz: np.ndarray
    vectors: np.ndarray
    dofs: int
    mass: sp.csr_matrix


def solve_harmonic(basis: Basis, material: Material, n: int, n_modes: int,
                   components=(0, 1, 2), axis: bool = False) -> HarmonicModes:
    """The `n_modes` lowest modes of harmonic n on `basis`, keeping only the displacement
    `components` (0 = r, 1 = t, 2 = z; for n = 0 (r, z) and (t,) decouple exactly); `axis`:
    the meridian meets the axis r = 0, where harmonic 0 is regular with U_r = U_t = 0."""
    if axis and n != 0:
        raise ValueError(f"harmonic {n}: only harmonic 0's regularity on the axis is built here")
    lam, mu = lame(material)
    k = meridian_stiffness(basis, lam, mu, n)
    m = (2.0 if n == 0 else 1.0) * material.density * meridian_mass(basis)
    n_all = k.shape[0]
    keep = np.sort(np.concatenate([np.arange(c, n_all, 3) for c in components]))
    if axis:
        r = basis.doflocs[0]
        on_axis = np.flatnonzero(np.abs(r) <= 1e-12 * np.abs(r).max())
        keep = np.setdiff1d(keep, np.concatenate([3 * on_axis, 3 * on_axis + 1]))
    modes = lowest_modes(k[keep][:, keep], m[keep][:, keep], n_modes)
    vectors = np.zeros((n_all, n_modes))
    vectors[keep] = modes.vectors
    return HarmonicModes(modes.frequencies_hz, vectors, len(keep), m)


def area_effective_size(basis: Basis, area: float) -> float:
    """(A / nodes)^(1/2): the effective size of a P2 meridian mesh of area A (m)."""
    return math.sqrt(area / basis.N)
