"""The reference points a leg's faces are tied to, with the joint and drive springs.

Both leg discretisations tie every end face of every part of a leg to a reference point with
six dofs (three translations t, three rotations theta, base coordinates), by the scene's
coupling (`constraints.py`: rigid, every face node follows the point; distributing, the face's
projected rigid motion does). This module says what those points are, as linear functions of
the model's coordinates q, and which spring energies act on the coordinates it adds (the
idealisation the analytical model carries identically; `common.stiffness`):

- J_b, J_p, the joint centres B_i and A_i (`geometry.leg_joints(i)`). Translation: the body's
  motion at the centre (0 on the base; Delta_p + Phi_p x (A_i - o) on the rigid platform, Eq.
  10; the plate's patch average on an elastic one), plus tau (3 coordinates, energy
  1/2 k_t |tau|^2) when the joint's translational stiffness k_t > 0. Rotation: S, free (psi,
  3 coordinates); R rigid (k_r = 0), the body's rotation plus phi a (today); R with k_r > 0,
  the body's rotation plus rho (3 coordinates in place of phi, energy
  1/2 rho^T k_r (I - a a^T) rho: the rotation about the axis a stays free). A distributing
  face reads no free rotation (a result of the face, not a coordinate: no phi, no psi) and so
  no rotation about an R joint's axis either: there rho is its two components normal to a
  (rho = N^T s, N the joint's tied rows, energy 1/2 k_r |s|^2), since a third, about a, would
  be a coordinate without stiffness and without mass.
- H, the junction of a stepped leg: the point on the axis at housing_length from B_i, 6
  independent coordinates (no mass, no stiffness of its own), to which the housing's top face
  is tied; the rod's bottom face is tied to R = H + delta e (delta: 1 coordinate along the leg
  axis e, energy 1/2 k_a delta^2) when the drive's stiffness k_a > 0, else to H itself.
- F_b, a uniform leg with a drive spring k_a > 0: its base face is tied to J_b + delta e,
  e the drive's direction (`geometry.drive_axes`: the leg's axis, or a 3-PRS's rail, the
  slider's drive acting between the base and the slider that carries J_b).

Every spring is registered on the `ConstraintBuilder` (`springs`: coordinates and matrix);
`ConstraintBuilder.spring_matrix` adds them to the reduced stiffness K_q. Nothing here has
mass: the points move the faces, whose mass is the legs'.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as la

from common.joints import JOINTS
from common.rigid_body import skew
from common.stiffness import joint_spring_matrix


@dataclass
class RefPoint:
    """A reference point's motion as linear maps of coordinates (see the module docstring).

    `translation` (cols, vals 3 x n, extra) and `rotation` (cols, map 3 x n) are what a rigidly
    coupled face follows (the body and the joint); `tied` (k, 3) are the rotation components a
    distributing face's projected rotation is held to, and `distributing` (cols, (3 + k) x n,
    extra) the right-hand side of those 3 + k equations; `additions` are the point's own
    coordinates (tau, rho, delta): (extra cols, 6 x n map on [t; theta])."""

    centre: np.ndarray
    translation: tuple | None
    rotation: tuple | None
    tied: np.ndarray
    distributing: tuple | None
    additions: list = field(default_factory=list)

    def moved(self, cols: np.ndarray, motion: np.ndarray) -> "RefPoint":
        """This point plus `motion` (6 x n) of extra coordinates `cols` (a spring's)."""
        return RefPoint(self.centre, self.translation, self.rotation, self.tied,
                        self.distributing, self.additions + [(cols, motion)])


def spring_columns(stiffness, geometry, coupling: str) -> dict:
    """How many own coordinates per leg each spring needs (0: rigid, none), by name."""
    out = {}
    for end, joint in zip(("base", "platform"), geometry.leg_joints(0)):
        k_t, k_r = stiffness.joint(end) if stiffness is not None else (0.0, 0.0)
        out[f"tau_{end}"] = 3 if k_t > 0 else 0
        if JOINTS[joint.type].has_axis:
            out["rho"] = (3 if coupling == "rigid" else 2) if k_r > 0 else 0
    return out


def needs_phi(stiffness, geometry) -> bool:
    """Does the rigid coupling need phi, one rotation per leg about its R joint's axis? Not
    when that joint has a rotational spring (rho takes its place)."""
    for end, joint in zip(("base", "platform"), geometry.leg_joints(0)):
        if JOINTS[joint.type].has_axis and stiffness is not None and stiffness.joint(end)[1] > 0:
            return False
    return True


class LegPoints:
    """The extra coordinates of every leg's springs and junctions on a `ConstraintBuilder`,
    added after the joints' and the platform's (so a machine without springs or junctions has
    exactly the coordinates it always had), and each leg's reference points."""

    def __init__(self, bld, geometry, coupling: str, stiffness, parts_per_leg: int):
        self.bld, self.geometry, self.coupling = bld, geometry, coupling
        self.stiffness = stiffness
        legs = geometry.leg_count
        self.counts = spring_columns(stiffness, geometry, coupling)
        self.cols = {name: bld.add_extra(name, n * legs).reshape(legs, n)
                     for name, n in self.counts.items() if n}
        k_a = float(stiffness.actuator_axial) if stiffness is not None else 0.0
        self.k_a = k_a
        self.junctions = parts_per_leg - 1
        if self.junctions:
            self.cols["junction"] = bld.add_extra("junction", 6 * self.junctions * legs
                                                  ).reshape(legs, self.junctions, 6)
        if k_a > 0:
            count = max(1, self.junctions)
            self.cols["delta"] = bld.add_extra("delta", count * legs).reshape(legs, count)
        self._springs()

    def _springs(self) -> None:
        for end, joint in zip(("base", "platform"), self.geometry.leg_joints(0)):
            if self.stiffness is None:
                break
            k_t, k_r = self.stiffness.joint(end)
            for i in range(self.geometry.leg_count):
                axis = self.geometry.leg_joints(i)[0 if end == "base" else 1].axis
                block = joint_spring_matrix(joint.type, axis, k_t, k_r)
                if k_t > 0:
                    self.bld.springs.append((self.cols[f"tau_{end}"][i], block[:3, :3]))
                if JOINTS[joint.type].has_axis and k_r > 0:
                    kr = block[3:, 3:]
                    if self.coupling != "rigid":  # rho = N^T s: k_r N (I - a a^T) N^T = k_r I
                        tied = JOINTS[joint.type].tied_rotations(axis)
                        kr = tied @ kr @ tied.T
                    self.bld.springs.append((self.cols["rho"][i], kr))
        if self.k_a > 0:
            for cols in self.cols["delta"]:
                for c in cols:
                    self.bld.springs.append((np.array([c]), np.array([[self.k_a]])))

    def joint_point(self, i: int, end: int, joint, body_translation, phi, psi, plat
                    ) -> RefPoint:
        """J_b (end 0) or J_p (end 1) of leg i; `body_translation` (cols, vals, extra) is the
        body's motion at the joint centre (None on the base). phi, psi: the rigid coupling's
        joint rotations (today's coordinates)."""
        kind = JOINTS[joint.type]
        name = ("base", "platform")[end]
        tied = kind.tied_rotations(joint.axis)
        on_platform = joint.body == "platform"
        has_rho = kind.has_axis and self.counts.get("rho", 0) > 0
        rotation = None
        if self.coupling == "rigid":
            if has_rho:  # the body's rotation; rho is an addition
                if kind.follows_body and on_platform:
                    rotation = (plat[3:], np.eye(3))
            else:
                rotation = rigid_rotation(joint, i, phi, psi, plat)
        if len(tied) and on_platform:  # the platform's rotation reaches the tied ones
            t_vals = body_translation[1]
            distributing = (plat, np.vstack([t_vals, np.hstack([np.zeros((len(tied), 3)),
                                                                tied])]), True)
        else:
            distributing = body_translation
        point = RefPoint(np.asarray(joint.centre, float), body_translation, rotation, tied,
                         distributing)
        if self.counts.get(f"tau_{name}", 0):
            point = point.moved(self.cols[f"tau_{name}"][i], np.vstack([np.eye(3),
                                                                        np.zeros((3, 3))]))
        if has_rho:
            own = np.eye(3) if self.coupling == "rigid" else tied.T
            point = point.moved(self.cols["rho"][i], np.vstack([np.zeros((3, own.shape[1])),
                                                                own]))
        return point

    def axial(self, i: int, k: int) -> tuple:
        """(cols, 6 x 1) of the drive's delta along leg i's drive direction (junction k):
        the leg's axis, or the rail of a 3-PRS (`geometry.drive_axes`)."""
        e = np.asarray(self.geometry.drive_axes[i], float)
        return self.cols["delta"][i][k:k + 1], np.concatenate([e, np.zeros(3)])[:, None]

    def face_points(self, i: int, starts: list, phi, psi, plat, body_translation
                    ) -> list[tuple[RefPoint, RefPoint]]:
        """Per part of leg i (base joint first), the points its start and end faces are tied
        to. `starts`: each part's start along the leg (m from B_i)."""
        joints = self.geometry.leg_joints(i)
        base = self.joint_point(i, 0, joints[0], None, phi, psi, plat)
        top = self.joint_point(i, 1, joints[1], body_translation, phi, psi, plat)
        if self.k_a > 0 and not self.junctions:  # F_b = J_b + delta e
            base = base.moved(*self.axial(i, 0))
        ends = [base]
        b = np.asarray(self.geometry.base_points[i], float)
        e = np.asarray(self.geometry.leg_directions[i], float)
        pairs = []
        for k in range(self.junctions):
            cols = self.cols["junction"][i, k]
            centre = b + float(starts[k + 1]) * e
            h = RefPoint(centre, (cols[:3], np.eye(3), True), (cols[3:], np.eye(3)),
                         np.eye(3), (cols, np.eye(6), True))
            rod = h.moved(*self.axial(i, k)) if self.k_a > 0 else h
            ends.append(h)
            pairs.append(rod)
        starts_points = [ends[0]] + pairs
        end_points = ends[1:] + [top]
        return list(zip(starts_points, end_points))


def rigid_rotation(joint, leg: int, phi: np.ndarray, psi: np.ndarray, plat: np.ndarray | None
                   ) -> tuple[np.ndarray, np.ndarray]:
    """(columns, map): the rotation of a rigidly coupled face's reference point as
    map @ q[columns], read from the joint's declaration (`common.joints.JOINTS`): its free
    rotations, `free_rotations(axis)`, on the leg's coordinates of that many rotations (phi_i,
    one per leg, or psi_i, three per leg), plus the body's rotation when the joint ties some
    rotations to its body and the body is the platform (the base does not turn). S, Eq. (10):
    psi_i, free; R, Eqs. (16)-(17): phi_i about the joint axis plus the platform's rotation."""
    from common.errors import InputError

    kind = JOINTS[joint.type]
    coordinates = {1: phi[leg:leg + 1], 3: psi[leg]}
    if kind.free not in coordinates:
        raise InputError(f"joint {joint.type!r}: {kind.free} free rotations, and the rigid "
                         "coupling has coordinates for 1 or 3")
    cols, rot = coordinates[kind.free], kind.free_rotations(joint.axis)
    if kind.follows_body and joint.body == "platform":
        assert plat is not None  # the rigid platform's coordinates (build_constraints checks)
        cols, rot = np.concatenate([cols, plat[3:]]), np.hstack([rot, np.eye(3)])
    return cols, rot


# ---------------------------------------------------------------- tying a face to a point

def tie_rigid(bld, dofs: np.ndarray, arms: np.ndarray, point: RefPoint) -> None:
    """Face dofs (n_f, 3) whose nodes sit at `arms` (n_f, 3, global, from the point) follow the
    point rigidly, u_k = t + theta x r_k (RBE2); all are eliminated."""
    bld.dependent[dofs.ravel()] = True
    rot = -skew(arms)  # theta x r = -[r x] theta
    if point.rotation is not None:
        cols, rmap = point.rotation
        rr = rot @ rmap  # (n_f, 3, n_r)
        bld.entries(np.repeat(dofs[:, :, None], len(cols), 2), np.broadcast_to(cols, rr.shape),
                    rr, extra=True)
    if point.translation is not None:
        cols, vals, extra = point.translation
        shape = (len(arms), 3, len(cols))
        bld.entries(np.repeat(dofs[:, :, None], len(cols), 2), np.broadcast_to(cols, shape),
                    np.broadcast_to(vals, shape), extra=extra)
    motion = np.concatenate([np.broadcast_to(np.eye(3), (len(arms), 3, 3)), rot], axis=2)
    for cols, add in point.additions:
        a = motion @ add  # (n_f, 3, n): [I, -[r x]] @ add
        bld.entries(np.repeat(dofs[:, :, None], len(cols), 2), np.broadcast_to(cols, a.shape),
                    a, extra=True)


def tie_rigid_map(bld, dofs: np.ndarray, motion: np.ndarray, point: RefPoint) -> None:
    """Face dofs (n, 3) = motion (n, 3, 6) @ [t; theta] of the point (dofs already marked
    dependent): the rotation, the translation, then the point's own coordinates."""
    if point.rotation is not None:
        cols, rmap = point.rotation
        rot = motion[:, :, 3:] @ rmap
        bld.entries(np.repeat(dofs[:, :, None], len(cols), 2), np.broadcast_to(cols, rot.shape),
                    rot, extra=True)
    if point.translation is not None:
        cols, vals, extra = point.translation
        tr = motion[:, :, :3] @ vals
        bld.entries(np.repeat(dofs[:, :, None], len(cols), 2), np.broadcast_to(cols, tr.shape),
                    tr, extra=extra)
    for cols, add in point.additions:
        a = motion @ add
        bld.entries(np.repeat(dofs[:, :, None], len(cols), 2), np.broadcast_to(cols, a.shape),
                    a, extra=True)


def tie_distributing(bld, face_dofs: np.ndarray, projection: np.ndarray, point: RefPoint,
                     candidates: np.ndarray | None = None) -> None:
    """The face's rigid-motion projection a = projection @ u_face (6 x n, global) held to the
    point: its translation, and the rotation components `point.tied` (none for S, the two
    normal to the axis for R, all three at a junction). Eliminated for as many face dofs as
    equations (`eliminate`)."""
    tied = point.tied
    c = np.vstack([projection[:3], tied @ projection[3:]])
    rows = la.block_diag(np.eye(3), tied) if len(tied) else np.hstack([np.eye(3),
                                                                       np.zeros((3, 3))])
    terms = [point.distributing] if point.distributing is not None else []
    terms += [(cols, rows @ add, True) for cols, add in point.additions]
    eliminate(bld, face_dofs, c, terms, candidates)


def eliminate(bld, face_dofs: np.ndarray, c: np.ndarray, terms: list,
              candidates: np.ndarray | None = None) -> None:
    """Solve C u_face = sum D_k q[cols_k] for len(C) face dofs chosen by pivoted QR (among the
    columns `candidates`, default all: a dof that another constraint refers to must stay
    independent); record them in T. `terms`: (cols, D, extra)."""
    allowed = np.arange(c.shape[1]) if candidates is None else np.asarray(candidates)
    _, _, piv = la.qr(c[:, allowed], mode="economic", pivoting=True)
    m = c.shape[0]
    dep = np.sort(allowed[piv[:m]])
    ind = np.setdiff1d(np.arange(c.shape[1]), dep)
    cd_inv = la.inv(c[:, dep])
    bld.dependent[face_dofs[dep]] = True
    coeff = -cd_inv @ c[:, ind]  # (m, n_ind)
    bld.entries(np.repeat(face_dofs[dep][:, None], len(ind), 1),
                np.broadcast_to(face_dofs[ind], coeff.shape), coeff, extra=False)
    for cols, rhs, extra in terms:
        g = cd_inv @ rhs  # (m, n_rhs)
        bld.entries(np.repeat(face_dofs[dep][:, None], len(cols), 1),
                    np.broadcast_to(cols, g.shape), g, extra=extra)
