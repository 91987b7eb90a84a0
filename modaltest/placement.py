"""Where a test node sits on the machine at one pose: on the platform or on a leg.

A node lies on a body when it is inside the body or at most `tolerance` from its surface (a
sensor's measuring point sits a few millimetres off the surface it is glued to). The bodies, in
base coordinates: the platform, a plate of thickness h centred on o with normal R e_z (a disk of
radius r2, or the triangle A1A2A3: `Manipulator.platform_shape`), and each leg, a cylinder from
B_i to A_i of its profile's outer diameter (a stepped leg: the housing's up to the junction, the
rod's beyond). A node within tolerance of several bodies is placed on the nearest; a tie (a node
at a platform joint lies inside the plate and the leg's end) goes to the platform, whose motion
the joint's centre shares. A node on no body is refused in one line naming it.

How a placed node moves in a mode (`sample`): the platform is rigid, so u = Delta + Phi x (x - o);
a leg moves as its axis point at the node's fraction t plus the section's rotation times the
node's offset r from the axis, u = u_axis(t) + theta(t) x r, theta = twist(t) e + e x du_axis/ds
(the section turns with the axis's slope: a beam's section rotation, the shear angle left out).
Both models answer these from their own fields (`ModeField`), so a test sees both alike.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from analytical.kinematics import PoseGeometry
from analytical.params import Manipulator
from common.errors import InputError

PLATFORM = "platform"
SLOPE_STEP = 1e-4  # fraction of the leg for the axis's slope (a central difference)


class NodeError(InputError):
    """A test node lies on no body of the machine."""


@dataclass(frozen=True)
class Placement:
    node: int
    body: str  # "platform" or "leg 1", "leg 2", "leg 3"
    distance: float  # m outside the body (0: inside)
    leg: int | None  # 0-based leg index, None on the platform
    fraction: float  # along B_i -> A_i (leg nodes)
    offset: np.ndarray  # (3,) from the axis point (leg nodes) or from o (platform), base frame


def _leg_radius(manipulator: Manipulator, along: np.ndarray) -> np.ndarray:
    leg = manipulator.leg
    if not leg.stepped:
        return np.full_like(along, 0.5 * manipulator.leg_diameter)
    return np.where(along <= leg.housing_length, 0.5 * leg.housing_outer_diameter,
                    0.5 * leg.rod_outer_diameter)


def _outside_triangle(p: np.ndarray, corners: np.ndarray) -> float:
    """In-plane distance from 2D point p to the triangle (0 inside)."""
    signs = []
    best = np.inf
    for k in range(3):
        a, b = corners[k], corners[(k + 1) % 3]
        ab = b - a
        signs.append(np.sign(ab[0] * (p[1] - a[1]) - ab[1] * (p[0] - a[0])))
        s = np.clip(np.dot(p - a, ab) / np.dot(ab, ab), 0.0, 1.0)
        best = min(best, float(np.linalg.norm(p - (a + s * ab))))
    return 0.0 if (all(x >= 0 for x in signs) or all(x <= 0 for x in signs)) else best


def platform_distance(manipulator: Manipulator, geometry: PoseGeometry,
                      point: np.ndarray) -> float:
    """Distance (m) of `point` outside the platform plate (0 inside)."""
    local = geometry.rotation.T @ (point - geometry.platform_centre)
    normal = max(0.0, abs(local[2]) - 0.5 * manipulator.platform_thickness)
    if manipulator.platform_shape == "disk":
        radial = max(0.0, float(np.hypot(local[0], local[1])) - manipulator.platform_radius)
    else:
        corners = np.array([geometry.rotation.T @ (a - geometry.platform_centre)
                            for a in geometry.platform_points])[:, :2]
        radial = _outside_triangle(local[:2], corners)
    return float(np.hypot(normal, radial))


def leg_distance(manipulator: Manipulator, geometry: PoseGeometry, leg: int,
                 point: np.ndarray) -> tuple[float, float, np.ndarray]:
    """(distance outside leg `leg`, fraction t of the nearest axis point clipped to [0, 1],
    offset from that axis point) of `point`."""
    base = geometry.base_points[leg]
    length = float(geometry.leg_lengths[leg])
    e = geometry.leg_directions[leg]
    rel = point - base
    along = float(rel @ e)
    t = min(max(along / length, 0.0), 1.0)
    radial_vec = rel - along * e
    radial = float(np.linalg.norm(radial_vec))
    radius = float(_leg_radius(manipulator, np.array([min(max(along, 0.0), length)]))[0])
    beyond = max(0.0, -along, along - length)
    distance = float(np.hypot(beyond, max(0.0, radial - radius)))
    return distance, t, rel - t * length * e


def place(manipulator: Manipulator, geometry: PoseGeometry, ids: np.ndarray, xyz: np.ndarray,
          tolerance: float, where: str) -> list[Placement]:
    """Each node (ids, xyz in m, base frame) on its body; NodeError naming the first node on
    no body (`where` names the file it came from)."""
    out = []
    for node, point in zip(ids, np.asarray(xyz, float)):
        d_plat = platform_distance(manipulator, geometry, point)
        best = Placement(int(node), PLATFORM, d_plat, None, 0.0,
                         point - geometry.platform_centre)
        for leg in range(geometry.leg_count):
            d, t, offset = leg_distance(manipulator, geometry, leg, point)
            if d < best.distance:
                best = Placement(int(node), f"leg {leg + 1}", d, leg, t, offset)
        if best.distance > tolerance:
            raise NodeError(
                f"{where}: node {int(node)} at ({', '.join(f'{c * 1e3:.1f}' for c in point)}) "
                f"mm lies on no body of the machine at this pose: {best.distance * 1e3:.1f} mm "
                f"from the nearest ({best.body}), the tolerance is {tolerance * 1e3:g} mm")
        out.append(best)
    return out


class ModeField(Protocol):
    """What a model answers about its modes at one pose (both models alike)."""

    @property
    def frequencies_hz(self) -> np.ndarray: ...

    @property
    def platform_motion(self) -> np.ndarray:
        """(6, n): translation of o and rotation of the platform, base frame."""
        ...

    def leg_axis_displacements(self, fractions) -> np.ndarray:
        """(legs, len(fractions), 3, n) translations of the leg axes, base frame."""
        ...

    def leg_axis_twists(self, fractions) -> np.ndarray:
        """(legs, len(fractions), n) rotations of the legs' sections about their axes."""
        ...


def node_motion(field: ModeField, geometry: PoseGeometry,
                placements: list[Placement]) -> np.ndarray:
    """(nodes, 3, n) translations of the placed nodes in every mode of `field`."""
    plat = np.asarray(field.platform_motion)
    n = plat.shape[1]
    out = np.empty((len(placements), 3, n))
    legs = [p for p in placements if p.leg is not None]
    if legs:
        t = np.array([p.fraction for p in legs])
        lo = np.clip(t - SLOPE_STEP, 0.0, 1.0)
        hi = np.clip(t + SLOPE_STEP, 0.0, 1.0)
        axis = field.leg_axis_displacements(np.concatenate([t, lo, hi]))
        twist = field.leg_axis_twists(t)
    k = 0
    for row, p in enumerate(placements):
        if p.leg is None:
            out[row] = plat[:3] + np.cross(plat[3:].T, p.offset).T
            continue
        m = len(legs)
        e = geometry.leg_directions[p.leg]
        u = axis[p.leg, k]
        ds = (hi[k] - lo[k]) * geometry.leg_lengths[p.leg]
        slope = (axis[p.leg, 2 * m + k] - axis[p.leg, m + k]) / ds  # (3, n)
        theta = np.outer(e, twist[p.leg, k]) + np.cross(e, slope.T).T
        out[row] = u + np.cross(theta.T, p.offset).T
        k += 1
    return out


def sample(field: ModeField, geometry: PoseGeometry, placements: list[Placement],
           dof_nodes: np.ndarray, dof_directions: np.ndarray) -> np.ndarray:
    """(dofs, n): each measured dof (node id, unit direction) in every mode of `field`."""
    motion = node_motion(field, geometry, placements)
    row_of = {p.node: i for i, p in enumerate(placements)}
    rows = np.array([row_of[int(node)] for node in dof_nodes])
    return np.einsum("kj,kjn->kn", np.asarray(dof_directions, float), motion[rows])
