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

What is shared with the tetrahedral model (`tetrahedra.py`): the joints and couplings
(`constraints.py`, the same equations in the same global coordinates, paper Eqs. 10, 14-17),
the rigid platform's mass from its own meshed plate (`rigid_platform.py`, via
`reduction.reduced_matrices`), the eigen solver (`eigen.py`). Nothing of `analytical/` but the
pose geometry.

Where it lives: `meridian.py` (a leg's meridian mesh and K_n, M), `harmonic_faces.py` (the
faces tied to the joints, u = T q), `harmonic_sections.py` (the section harmonics n >= 2
checked by inertia), `harmonic_result.py` (`HarmonicResult`); this module solves a pose.
"""
from __future__ import annotations

import hashlib
import math
import time

import numpy as np
import scipy.sparse as sp

from common.joints import COUPLINGS
from meshing.bodies import platform_plate

from .answer import normalise_signs
from .eigen import EigenError, lowest_modes
from .harmonic_faces import harmonic_constraints
from .harmonic_result import HarmonicResult
from .harmonic_sections import (
    lowest_leg_harmonic,
    modes_below,
    section_blocks,
    section_modes_above,
)
from .meridian import (
    HarmonicError,
    clear_caches,
    estimate_raw_dofs,
    families,
    leg_data,
    leg_harmonics,
    meridian_mesh,
    mesh_quality,
    part_data,
    part_size,
    pose_parts,
)
from .reduction import reduced_matrices

__all__ = ["HarmonicError", "HarmonicResult", "LOWEST_EXCLUDED_MARGIN", "clear_caches",
           "estimate_raw_dofs", "leg_data", "leg_harmonics", "lowest_leg_harmonic",
           "modes_below", "section_blocks", "solve_pose_harmonic"]

LOWEST_EXCLUDED_MARGIN = 1.2  # harmonic n + 1 is left out if its lowest mode is this far above


def solve_pose_harmonic(manipulator, geometry, options, max_dofs: int | None = None,
                        keep_system: bool = False
                        ) -> HarmonicResult:
    """Natural frequencies and modes of the pose's solid model (rigid platform) with the legs
    by harmonics (module docstring). Harmonics 0 and 1 always; n = 2, 3, ... are added while
    the lowest mode of the next harmonic, over the legs, is not LOWEST_EXCLUDED_MARGIN times
    above the highest frequency solved for (the lowest mode of a cylinder's harmonic rises with
    n: more circumferential strain; measured 23, 36, 47, 58 kHz for n = 2-5 of the paper's
    legs). Runs in this process (2D: a fraction of a second; its per-leg caches serve the next
    pose); `max_dofs` refuses larger raw models once meshed (guard.check_mesh_size refuses by
    estimate before)."""
    if options.platform != "rigid":
        raise HarmonicError(f"platform = {options.platform!r}: harmonic legs need the rigid "
                            "platform (legs = 'tetrahedra' meshes an elastic plate)")
    if options.coupling not in COUPLINGS:
        raise HarmonicError(f"coupling = {options.coupling!r}: expected one of "
                            f"{', '.join(COUPLINGS)}")
    t0 = time.perf_counter()
    size = float(options.mesh.size)
    harmonics: tuple[int, ...] = (0, 1)
    while True:
        result = _solve(manipulator, geometry, options, harmonics, t0, max_dofs, keep_system)
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


def _solve(manipulator, geometry, options, harmonics, t0, max_dofs,
           keep_system: bool = False) -> HarmonicResult:
    size, coupling = float(options.mesh.size), options.coupling
    for parts in pose_parts(manipulator, geometry):  # the meshes first: "mesh" times them alone
        for p in parts:
            radius, inner = 0.5 * float(p.outer), 0.5 * float(p.inner)
            length = float(p.end) if p.start == 0.0 else round(float(p.end - p.start), 12)
            h = part_size(size, radius, inner)
            if inner:
                meridian_mesh(radius, length, h, inner)
            else:
                meridian_mesh(radius, length, h)
    t_mesh = time.perf_counter()
    legs = part_data(manipulator, geometry, size, harmonics)
    fams = families(harmonics)
    offsets, n_raw = [], 0
    for part in legs:
        offsets.append(n_raw)
        n_raw += len(fams) * 3 * part.leg.n_scalar
    if max_dofs is not None and n_raw > max_dofs:
        raise HarmonicError(f"mesh_size_mm = {size * 1e3:g}: {n_raw} harmonic dofs, above "
                            f"max_dofs = {max_dofs}")
    t_map, columns, springs = harmonic_constraints(legs, offsets, harmonics, geometry, coupling,
                                                   n_raw, getattr(manipulator, "stiffness",
                                                                  None))
    k_blocks, m_blocks = [], []
    for part in legs:
        mass = part.leg.mass
        if mass is None:  # leg_harmonics always sets it
            raise TypeError(f"{part.name}: a leg part without its mass matrix")
        for n, _ in fams:
            k_blocks.append(part.leg.stiffness[n])
            m_blocks.append(mass * (2.0 if n == 0 else 1.0))
    plate = platform_plate(manipulator, geometry)
    kq, mq = reduced_matrices(sp.block_diag(k_blocks, format="csr"),
                              sp.block_diag(m_blocks, format="csr"), t_map,
                              columns["platform"], plate, manipulator, geometry, options,
                              springs)
    t_asm = time.perf_counter()
    try:
        found = lowest_modes(kq, mq, options.modes)
    except EigenError as exc:
        raise HarmonicError(f"mesh_size_mm = {size * 1e3:g}: eigensolver failed ({exc})") from None
    t_end = time.perf_counter()
    v = normalise_signs(found.vectors)
    digest = hashlib.sha256()
    for part in legs:
        digest.update(np.ascontiguousarray(part.leg.basis.mesh.p).tobytes())
        digest.update(np.ascontiguousarray(part.leg.basis.mesh.t).tobytes())
    return HarmonicResult(
        frequencies_hz=found.frequencies_hz, dofs=int(kq.shape[0]), raw_dofs=n_raw,
        mesh_size=size,
        timings={"mesh": t_mesh - t0, "assemble": t_asm - t_mesh, "solve": t_end - t_asm},
        clusters=[list(map(int, c)) for c in found.clusters], mesh_digest=digest.hexdigest(),
        n_elements=int(sum(p.leg.basis.mesh.t.shape[1] for p in legs)), options=options,
        min_quality=min(mesh_quality(p.leg.basis.mesh) for p in legs),
        harmonics=tuple(harmonics), excluded_above_hz=math.nan, geometry=geometry,
        modes_q=v, modes_raw=t_map @ v, columns=columns,
        legs=[(p, off) for p, off in zip(legs, offsets)], plate=plate,
        system=(kq, mq) if keep_system else None)
