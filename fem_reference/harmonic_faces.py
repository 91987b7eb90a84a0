"""How the harmonic legs meet their joints: a joint face read from harmonics 0 and 1.

A rigid motion (t, phi) of an end face, in the leg's frame, is harmonics 0 and 1 only
(`harmonic.py`'s docstring), so a rigidly coupled (RBE2) face ties exactly those harmonics of
its nodes to its joint (`rigid_face_coefficients`), and a distributing (RBE3) face's average
rigid motion reads exactly those (`face_projection_coefficients`, the harmonic form of
`constraints.face_projection`). `harmonic_constraints` builds u = T q for the pose with the
tetrahedral model's own joint equations (`constraints.rigid_rotation`,
`constraints.distributing_joint`, read from `common.joints`).
"""
from __future__ import annotations

import math

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp

from common.rigid_body import skew

from .constraints import ConstraintBuilder
from .leg_points import LegPoints, needs_phi, tie_distributing, tie_rigid_map
from .meridian import Meridian, families


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


def section_constants(leg: Meridian) -> tuple[float, float, float]:
    """(A, I_xx, I_zz) of the part's section: a circle, or an annulus of a tube."""
    r, ri = leg.radius, leg.inner
    if not ri:
        return math.pi * r**2, math.pi * r**4 / 4, math.pi * r**4 / 2
    return (math.pi * (r**2 - ri**2), math.pi * (r**4 - ri**4) / 4,
            math.pi * (r**4 - ri**4) / 2)


def face_projection_coefficients(leg: Meridian, face: int, n: int, family: str
                                 ) -> np.ndarray:
    """(6, len(face nodes), 3): the L2 projection of the face's displacement onto rigid
    motions about its centre, a = G^-1 int Phi^T u dA (constraints.face_projection), read from
    harmonic (n, family) of the face's nodal values, in the leg frame."""
    w1, w2 = leg.face_weights[face]
    area, i_xx, i_zz = section_constants(leg)
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


def harmonic_constraints(parts: list, offsets: list, harmonics: tuple, geometry, coupling: str,
                         n_raw: int, stiffness=None) -> tuple[sp.csr_matrix, dict, object]:
    """(T, columns by name, springs) of u = T q for the legs' parts `parts`
    (`meridian.PartHarmonics`, leg by leg, base joint first) whose raw dofs start at `offsets`,
    in blocks `families(harmonics)`: the regularity of every harmonic on the axis of a solid
    part, then each end face tied to its reference point (`leg_points`: the joints, a stepped
    leg's junction, the springs of `stiffness`; rigid: harmonics 0 and 1 of its nodes follow
    the point, n >= 2 held; distributing: its projected rigid motion is constrained). The
    rigid platform's six coordinates are columns["platform"]; `springs` the springs'
    stiffness on q (None without springs)."""
    fams = families(harmonics)
    bld = ConstraintBuilder(n_raw)
    o = np.asarray(geometry.platform_centre, float)
    legs = geometry.leg_count
    per_leg = sum(p.index == 0 for p in parts)
    phi: np.ndarray = np.zeros(0, np.int64)
    psi: np.ndarray = np.zeros(0, np.int64)
    if coupling == "rigid":
        if needs_phi(stiffness, geometry):
            phi = bld.add_extra("phi", legs)
        psi = bld.add_extra("psi", 3 * legs).reshape(legs, 3)
    plat = bld.add_extra("platform", 6)
    points = LegPoints(bld, geometry, coupling, stiffness, per_leg)
    tied_to = []
    for i in range(legs):
        ref = np.asarray(geometry.leg_joints(i)[1].centre, float)
        body = (plat, np.hstack([np.eye(3), -skew(ref - o)]), True)  # Eq. (10)
        starts = [p.start for p in parts if p.index == i]
        tied_to += points.face_points(i, starts, phi, psi, plat, body)
    for part, offset, ends in zip(parts, offsets, tied_to):
        leg, frame = part.leg, part.frame
        n3 = 3 * leg.n_scalar
        e6 = la.block_diag(frame.T, frame.T)  # global (t, theta) -> leg frame
        base = {fam: offset + k * n3 for k, fam in enumerate(fams)}
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
        for face_index, point in enumerate(ends):
            nodes = leg.face_nodes[face_index]
            if coupling == "rigid":
                rho = leg.node_rz[nodes, 0]
                for n, fam in fams:
                    dofs = base[(n, fam)] + 3 * nodes[:, None] + np.arange(3)  # (nf, 3)
                    bld.dependent[dofs.ravel()] = True
                    if n >= 2:  # held
                        continue
                    h = rigid_face_coefficients(n, fam, rho) @ e6  # (nf, 3, 6), global a
                    tie_rigid_map(bld, dofs, h, point)
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
            tie_distributing(bld, face_dofs, proj, point, candidates)
    t_map, _, columns = bld.finish()
    return t_map, columns, bld.spring_matrix()
