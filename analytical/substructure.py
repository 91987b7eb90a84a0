"""Substructure synthesis of the 3-RPS manipulator in independent coordinates (Eqs. 4-22).

Each leg is a beam of s frame elements from B_i (node 0) to A_i (node s), turned into base
coordinates by its limb frame (Eqs. 5-6). The rigid platform has six coordinates at its centre
o (Eq. 7). The joints are multipoint constraints eliminated exactly, so no Lagrange multiplier
appears (the paper's contribution):

- S joint at A_i (Eq. 10): the leg-top translation follows the platform,
  Delta_Ai = Delta_p + Phi_p x (A_i - o); the leg-top rotation stays free.
- R joint at B_i (Eqs. 14-17): Delta_Bi = 0 and the rotation is restricted to the joint axis,
  Phi_Bi = axis_i * phi_i.

The independent coordinates (Eq. 19), per leg i then for the platform, are

    q = [phi_1, u_in,1, Phi_A1, phi_2, u_in,2, Phi_A2, phi_3, u_in,3, Phi_A3, Delta_p, Phi_p]

with 6s - 2 per leg and 6 for the platform: 18 s in all (18 (s + 2) with solid joint ends, whose
two end zones per leg add two segments: analytical.end_zones). With the joint order of the
paper's Section 2 text (S at B_i, R at A_i with its axis fixed in the platform) the same count
holds: per leg [Phi_Bi (3), u_in,i, phi_i (1)], the S joint's leg end fixed in translation with
a free rotation, the R joint's leg end translating with the platform (Eq. 10) and turning with
it plus phi_i about the joint axis. A joint's coordinates and rows are read from its declaration
(`common.joints.JOINTS`: how many rotations it leaves free, about which directions, whether the
rest follow its body), in `leg_coordinates` and `_joint_rows`, for this model and the batched
one (`batch_model`) alike; the kinematics hands every leg its chain of joints. Every constrained
leg coordinate is a linear function of q, U_leg,i = T_i q, which plays the role of the product
of the paper's H_i (Eq. 12) and Q (Eq. 21); K = sum T_i^T K_i T_i and M = sum T_i^T M_i T_i +
T_p^T M_p T_p (Eqs. 13 and 22).

The paper picks the R-joint coordinate as phi_By with phi_Bx = R_i(1,2)/R_i(2,2) phi_By
(Eqs. 17-18, 21); that ratio is singular whenever a joint axis is parallel to the base x-axis.
Here the coordinate is the rotation about the unit joint axis itself, regular for every layout
and pose. The paper's form is kept (`r_joint_coordinate = "paper-eq18"`) to show the difference.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from common.errors import InputError
from common.joints import JOINTS
from common.rigid_body import skew
from common.stiffness import joint_spring_matrix

from .end_zones import zone_for
from .kinematics import PoseGeometry
from .leg_chain import leg_chain, leg_segments, leg_stations
from .params import Manipulator, ModelOptions
from .platform import platform_mass_matrix
from .solid_legs import part_blocks


class SingularJointMap(InputError):
    """The chosen independent R-joint coordinate cannot describe the joint's rotation."""


@dataclass(frozen=True)
class SubstructureModel:
    """Reduced stiffness and mass on the 18 s independent coordinates, and how to expand them."""

    stiffness: np.ndarray  # (18s, 18s)
    mass: np.ndarray  # (18s, 18s)
    leg_maps: tuple[np.ndarray, ...]  # T_i: (6(s+1), 18s), global leg nodal DOFs from q
    leg_nodes: np.ndarray  # (3, n+1, 3) node positions along each leg, base coordinates
    platform_slice: slice  # position of (Delta_p, Phi_p) in q
    elements: int  # n, segments per leg (leg_chain: elements, end zones, the drive's)
    springs: dict | None = None  # "joints", "drive": each spring kind's share of K (18s, 18s)


def r_joint_direction(axis: np.ndarray, form: str) -> np.ndarray:
    """Global rotation of the base node per unit independent R-joint coordinate.

    "axis": Phi_B = axis * phi (regular). "paper-eq18": the paper's choice with phi_By as
    independent coordinate, Phi_B = [R(1,2)/R(2,2), 1, 0] phi_By (Eqs. 17, 21), which is the
    same direction scaled by 1/axis_y and so diverges as axis_y -> 0.
    """
    if form == "axis":
        return axis
    if form == "paper-eq18":
        if axis[1] == 0.0:
            raise SingularJointMap(
                f"R-joint axis {np.round(axis, 12).tolist()} has R_i(2,2) = 0: the paper's "
                "Eq. (18) coordinate is singular here (use r_joint_coordinate = 'axis')")
        return np.array([axis[0] / axis[1], 1.0, axis[2] / axis[1]])
    raise InputError(f"r_joint_coordinate = {form!r}: expected axis or paper-eq18")


LEGS = 3  # the substructure model is for a three-legged machine


@dataclass(frozen=True)
class JointLayout:
    """The coordinates a joint gives its leg end: its free rotations (R: one, about the axis;
    S: three) and, when compliant (`common.stiffness`), the relative motions its springs
    resist: a translational spring adds the three translations tau of the leg end against the
    body's point; a rotational spring on an R joint frees its two tied rotations too, so the
    leg end's rotation relative to the body is three coordinates rho (the spring resists
    rho's part normal to the axis, k_r (I - a a^T))."""

    type: str
    translational: bool = False
    rotational: bool = False

    @property
    def rotations(self) -> int:
        return 3 if self.rotational else JOINTS[self.type].free

    @property
    def count(self) -> int:
        return self.rotations + (3 if self.translational else 0)


@dataclass(frozen=True)
class LegLayout:
    """How a leg's nodal coordinates come from q: its joints' layouts, its node count and the
    drive's node (`leg_chain`: it repeats the node before it plus delta along the leg)."""

    base: JointLayout
    top: JointLayout
    segments: int
    split: int | None = None

    @property
    def interior(self) -> int:
        """Nodes with six coordinates of their own (not a joint's, not the drive's)."""
        return self.segments - 1 - (self.split is not None)

    @property
    def count(self) -> int:
        """Coordinates of one leg: base joint, interior nodes, delta, platform joint."""
        return self.base.count + 6 * self.interior + (self.split is not None) + self.top.count


def leg_layout(manipulator: Manipulator, options: ModelOptions, base_joint: str | None = None,
               platform_joint: str | None = None, modes: int = 0) -> LegLayout:
    """The layout of every leg of this machine with these options (the joints default to the
    manipulator's); `modes`: solid parts reduced to that many modal coordinates
    (`part_reduction`, the batched model's)."""
    chain = leg_chain(manipulator, options, modes)
    k = manipulator.stiffness
    joints = []
    for end, kind in (("base", base_joint or manipulator.base_joint),
                      ("platform", platform_joint or manipulator.platform_joint)):
        k_t, k_r = k.joint(end)
        joints.append(JointLayout(kind, k_t > 0.0, k_r > 0.0 and JOINTS[kind].has_axis))
    return LegLayout(joints[0], joints[1], chain.segments, chain.split)


def rigid_layout(s: int, base_joint: str, platform_joint: str) -> LegLayout:
    """The paper's leg of s segments between rigid joints, no drive spring."""
    return LegLayout(JointLayout(base_joint), JointLayout(platform_joint), s)


def leg_coordinates(s: int, base_joint: str, platform_joint: str) -> int:
    """Independent coordinates of one paper's leg of s segments: its base joint's free
    rotations, the six of every interior node, its platform joint's free rotations (6 s - 2
    for R and S)."""
    return rigid_layout(s, base_joint, platform_joint).count


def coordinate_count(layout: LegLayout) -> int:
    """Length of q: every leg's coordinates, then the platform's six (18 s for the paper's
    leg)."""
    return LEGS * layout.count + 6


def model_coordinates(manipulator: Manipulator, options: ModelOptions) -> int:
    """The analytical model's coordinates (its most modes) for this machine and options."""
    return coordinate_count(leg_layout(manipulator, options))


_EYE3, _EYE6 = np.eye(3), np.eye(6)  # (read only; written into the maps, never changed)
_EYE3.flags.writeable = _EYE6.flags.writeable = False


def _joint_rows(joint, layout: JointLayout, first: int, n_q: int, platform: int,
                arm: np.ndarray, r_form: str) -> np.ndarray:
    """(6, n_q): the six nodal coordinates (translation, rotation) of the leg end at `joint`
    in terms of q, the joint's own coordinates (`layout`) starting at column `first`: its
    rotations, then tau when translationally compliant.

    - translation: body "base": Delta = tau (0 when rigid, Eqs. 14-16); body "platform":
      Delta = Delta_p + Phi_p x arm (+ tau) (Eq. 10), arm = joint centre - o.
    - rotation: Phi = Phi_body + sum_k f_k psi_k over the joint's free rotations f_k; the body's
      rotation only where the joint ties some rotation to it (`follows_body`, Phi_body = 0 on
      the fixed base). S: three free rotations, the body's rotation does not reach the leg end
      (Eq. 10); R: one, about the joint axis (Eqs. 16-17), scaled as `r_form` says; R with a
      rotational spring: three, rho, the body's rotation still reaching the leg end.
    """
    kind = JOINTS[joint.type]
    rows = np.zeros((6, n_q))
    if joint.body == "platform":
        rows[:3, platform:platform + 3] = _EYE3
        rows[:3, platform + 3:platform + 6] = -skew(arm)
    if layout.rotational:
        rows[3:, first:first + 3] = _EYE3
    else:
        axis = r_joint_direction(joint.axis, r_form) if kind.has_axis else None
        rows[3:, first:first + kind.free] = kind.free_rotations(axis)
    if kind.follows_body and joint.body == "platform":
        rows[3:, platform + 3:platform + 6] = _EYE3
    if layout.translational:
        tau = first + layout.rotations
        rows[:3, tau:tau + 3] += _EYE3
    return rows


def _leg_map(layout: LegLayout, leg: int, joints, arm: np.ndarray, r_form: str,
             axis: np.ndarray | None = None) -> np.ndarray:
    """T_i: leg nodal coordinates (base frame) in terms of q (Eqs. 10, 12, 17, 21).

    Per leg, q holds the base joint's coordinates, the interior nodes' six, the drive's
    stretch delta and the platform joint's coordinates (`LegLayout`); every leg has the same
    joints. `axis` is the unit direction of the leg's drive (base frame: the leg's axis
    B_i -> A_i in a 3-RPS, the rail in a 3-PRS), along which the drive's node moves by delta.
    """
    base, top = joints
    first = leg * layout.count
    platform = LEGS * layout.count
    n_q = platform + 6
    s = layout.segments
    t = np.zeros((6 * (s + 1), n_q))
    t[0:6] = _joint_rows(base, layout.base, first, n_q, platform, arm, r_form)
    column = first + layout.base.count
    for node in range(1, s):
        rows = slice(6 * node, 6 * node + 6)
        if node == layout.split:
            continue
        t[rows, column:column + 6] = _EYE6
        column += 6
    top_first = column + (layout.split is not None)
    t[6 * s:] = _joint_rows(top, layout.top, top_first, n_q, platform, arm, r_form)
    if layout.split is not None:  # u_split = u_before + delta e
        j = layout.split
        t[6 * j:6 * j + 6] = t[6 * j - 6:6 * j]
        t[6 * j:6 * j + 3, column] += np.zeros(3) if axis is None else axis
    return t


def spring_stiffness(layout: LegLayout, manipulator: Manipulator, leg: int, joints,
                     axes=None) -> list[tuple[np.ndarray, np.ndarray]]:
    """The springs of leg `leg` on q, as (columns, block) pairs: each joint's
    `common.stiffness.joint_spring_matrix` on its tau and rho, the drive's k_a on delta.
    `axes` (N, 3), R-joint axes of N poses, batches the blocks, (N, c, c); default: the
    joints' own axes, one pose."""
    out = []
    first = leg * layout.count
    column = first
    for end, joint, jl in (("base", joints[0], layout.base), ("platform", joints[1], layout.top)):
        if end == "platform":
            column = first + layout.base.count + 6 * layout.interior
            if layout.split is not None:
                out.append((np.array([column]),
                            np.array([[manipulator.stiffness.actuator_axial]])))
                column += 1
        if not (jl.rotational or jl.translational):  # a rigid joint: no spring, nothing built
            continue
        k_t, k_r = manipulator.stiffness.joint(end)
        block = joint_spring_matrix(joint.type, joint.axis if axes is None else axes, k_t, k_r)
        if jl.rotational:
            out.append((np.arange(column, column + 3), block[..., 3:, 3:]))
        if jl.translational:
            tau = column + jl.rotations
            out.append((np.arange(tau, tau + 3), block[..., :3, :3]))
    return out


def _to_limb_frame(leg_map: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """T_i^T times a map into base coordinates, T_i = diag(R_i, ..., R_i) (Eq. 6).

    Gives the limb-frame nodal coordinates u_i = T_i^T U_i in terms of q, so that
    K_i = T_i K_e T_i^T (Eq. 5) never has to be formed.
    """
    n = leg_map.shape[0] // 3
    return np.einsum("ba,kbq->kaq", rotation, leg_map.reshape(n, 3, -1)).reshape(leg_map.shape)


def assemble(manipulator: Manipulator, geometry: PoseGeometry,
             options: ModelOptions) -> SubstructureModel:
    """Reduced stiffness K and mass M of the whole manipulator in one pose (Eqs. 4-22).

    Every leg is its chain of segments (`leg_chain`: frame elements of each part, solid end
    zones at the coupled faces with solid joint ends, the drive's node; with solid legs each
    part whole, `solid_legs`); the joints act on the
    chain's end nodes exactly as on a beam's end nodes; the joint and drive springs add their
    energy on their coordinates (`spring_stiffness`).
    """
    if geometry.leg_count != LEGS:
        raise InputError(f"{geometry.leg_count} legs: the substructure model is for three")
    layout = leg_layout(manipulator, options, geometry.base_joint, geometry.platform_joint)
    n = layout.segments
    zones = zone_for(manipulator, options)
    n_q = coordinate_count(layout)
    k_total = np.zeros((n_q, n_q))
    m_total = np.zeros((n_q, n_q))
    maps = []
    springs: dict[str, np.ndarray] = {}
    nodes = np.empty((geometry.leg_count, n + 1, 3))
    lengths = np.asarray(geometry.leg_lengths, float)
    stations = leg_stations(manipulator, options, zones, lengths)
    parts = leg_segments(manipulator, options, zones, lengths)  # (n, 2, 3, 12, 12), Eq. (4)
    solid = part_blocks(manipulator, options, lengths)  # legs = "solid": whole parts
    for i in range(geometry.leg_count):
        k_local = np.zeros((6 * (n + 1), 6 * (n + 1)))
        m_local = np.zeros_like(k_local)
        for e in range(n):
            sl = slice(6 * e, 6 * e + 12)
            k_local[sl, sl] += parts[e, 0, i]
            m_local[sl, sl] += parts[e, 1, i]
        for first, whole in solid:
            sl = slice(6 * first, 6 * first + whole.shape[-1])
            k_local[sl, sl] += whole[0, i]
            m_local[sl, sl] += whole[1, i]
        arm = geometry.platform_points[i] - geometry.platform_centre
        joints = geometry.leg_joints(i)
        t = _leg_map(layout, i, joints, arm, options.r_joint_coordinate,
                     geometry.drive_axes[i])
        local = _to_limb_frame(t, geometry.leg_frames[i])  # u_i = T_i^T T q, Eqs. (5)-(6)
        cols = np.flatnonzero(np.any(local != 0.0, axis=0))  # this leg's and the platform's
        local = local[:, cols]
        block = np.ix_(cols, cols)
        k_total[block] += local.T @ k_local @ local
        m_total[block] += local.T @ m_local @ local
        for columns, spring in spring_stiffness(layout, manipulator, i, joints):
            kind = "drive" if len(columns) == 1 else "joints"
            springs.setdefault(kind, np.zeros((n_q, n_q)))[np.ix_(columns, columns)] += spring
        maps.append(t)
        nodes[i] = geometry.base_points[i] + np.outer(stations[i], geometry.platform_points[i]
                                                      - geometry.base_points[i])
    for spring_block in springs.values():
        k_total += spring_block
    p = slice(n_q - 6, n_q)
    m_total[p, p] += platform_mass_matrix(manipulator, geometry.rotation,
                                          options.platform_inertia)
    return SubstructureModel(k_total, m_total, tuple(maps), nodes, p, n, springs)
