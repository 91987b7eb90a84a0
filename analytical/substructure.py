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

with 6s - 2 per leg and 6 for the platform: 18 s in all. Every constrained leg coordinate is a
linear function of q, U_leg,i = T_i q, which plays the role of the product of the paper's H_i
(Eq. 12) and Q (Eq. 21); K = sum T_i^T K_i T_i and M = sum T_i^T M_i T_i + T_p^T M_p T_p
(Eqs. 13 and 22).

The paper picks the R-joint coordinate as phi_By with phi_Bx = R_i(1,2)/R_i(2,2) phi_By
(Eqs. 17-18, 21); that ratio is singular whenever a joint axis is parallel to the base x-axis.
Here the coordinate is the rotation about the unit joint axis itself, regular for every layout
and pose. The paper's form is kept (`r_joint_coordinate = "paper-eq18"`) to show the difference.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from common.rigid_body import skew

from .beam import Section, assemble_beam
from .kinematics import PoseGeometry
from .params import Manipulator, ModelOptions
from .platform import platform_mass_matrix


class SingularJointMap(ValueError):
    """The chosen independent R-joint coordinate cannot describe the joint's rotation."""


@dataclass(frozen=True)
class SubstructureModel:
    """Reduced stiffness and mass on the 18 s independent coordinates, and how to expand them."""

    stiffness: np.ndarray  # (18s, 18s)
    mass: np.ndarray  # (18s, 18s)
    leg_maps: tuple[np.ndarray, ...]  # T_i: (6(s+1), 18s), global leg nodal DOFs from q
    leg_nodes: np.ndarray  # (3, s+1, 3) node positions along each leg, base coordinates
    platform_slice: slice  # position of (Delta_p, Phi_p) in q
    elements: int


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
    raise ValueError(f"r_joint_coordinate = {form!r}: expected axis or paper-eq18")


def _leg_map(s: int, leg: int, axis_dir: np.ndarray, arm: np.ndarray) -> np.ndarray:
    """T_i: leg nodal coordinates (base frame) in terms of q (Eqs. 10, 12, 17, 21)."""
    n_q = 18 * s
    per_leg = 6 * s - 2
    first = leg * per_leg
    t = np.zeros((6 * (s + 1), n_q))
    t[3:6, first] = axis_dir  # R joint: Phi_B = axis * phi; Delta_B = 0
    inner = 6 * (s - 1)
    t[6:6 + inner, first + 1:first + 1 + inner] = np.eye(inner)  # interior nodes
    top = 6 * s
    p = 3 * per_leg
    t[top:top + 3, p:p + 3] = np.eye(3)  # S joint, Eq. (10): Delta_A = Delta_p + Phi_p x arm
    t[top:top + 3, p + 3:p + 6] = -skew(arm)
    t[top + 3:top + 6, first + 1 + inner:first + 4 + inner] = np.eye(3)  # Phi_A free
    return t


def _to_limb_frame(leg_map: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """T_i^T times a map into base coordinates, T_i = diag(R_i, ..., R_i) (Eq. 6).

    Gives the limb-frame nodal coordinates u_i = T_i^T U_i in terms of q, so that
    K_i = T_i K_e T_i^T (Eq. 5) never has to be formed.
    """
    n = leg_map.shape[0] // 3
    return np.einsum("ba,kbq->kaq", rotation, leg_map.reshape(n, 3, -1)).reshape(leg_map.shape)


def assemble(manipulator: Manipulator, geometry: PoseGeometry,
             options: ModelOptions) -> SubstructureModel:
    """Reduced stiffness K and mass M of the whole manipulator in one pose (Eqs. 4-22)."""
    s = options.elements
    mat = manipulator.material
    section = Section.solid_circle(manipulator.leg_diameter, mat.poisson_ratio,
                                   options.shear_coefficient)
    n_q = 18 * s
    k_total = np.zeros((n_q, n_q))
    m_total = np.zeros((n_q, n_q))
    maps = []
    nodes = np.empty((3, s + 1, 3))
    stations = np.linspace(0.0, 1.0, s + 1)
    for i in range(3):
        k_local, m_local = assemble_beam(mat.youngs_modulus, mat.shear_modulus, mat.density,
                                         section, float(geometry.leg_lengths[i]), s,
                                         options.beam)
        arm = geometry.platform_points[i] - geometry.platform_centre
        t = _leg_map(s, i, r_joint_direction(geometry.joint_axes[i],
                                             options.r_joint_coordinate), arm)
        local = _to_limb_frame(t, geometry.leg_frames[i])  # u_i = T_i^T T q, Eqs. (5)-(6)
        k_total += local.T @ k_local @ local
        m_total += local.T @ m_local @ local
        maps.append(t)
        nodes[i] = geometry.base_points[i] + np.outer(stations, geometry.platform_points[i]
                                                      - geometry.base_points[i])
    p = slice(n_q - 6, n_q)
    m_total[p, p] += platform_mass_matrix(manipulator, geometry.rotation,
                                          options.platform_inertia)
    return SubstructureModel(k_total, m_total, tuple(maps), nodes, p, s)
