"""Joint and drive stiffness: linear springs both models carry identically, declared once.

A real joint is a bearing and a real actuator is a ball screw, nut and thrust bearings: springs
where the paper's idealisation has rigid constraints. Each is a linear spring on a relative
motion, and each is an idealisation the analytical model and the FEM share (like the payload);
what is elastic, each model builds on its own.

- A joint spring joins the joint's reference point, which moves with its body (the fixed base,
  or the platform at the joint centre), to the leg end's reference point (the point a joint
  face is tied to). On the relative motion (translation t, rotation r) of the leg end against
  the body, base coordinates, its energy is 1/2 t^T K_t t + 1/2 r^T K_r r with
  K_t = k_t I (every constrained translation; a joint constrains all three) and
  K_r = k_r (I - a a^T) for a joint with axis a (R: the two rotations normal to its axis; the
  rotation about it stays free), K_r = 0 for S (it constrains no rotation).
- The drive spring joins the housing's end face to the rod's (at the junction of a stepped leg,
  `common.leg_profile`; at the base joint for a uniform leg): along the leg axis e only, energy
  1/2 k_a (e . (u_rod - u_housing))^2; the other five relative motions stay rigid. In a 3-PRS
  it joins the slider to its rail, e the rail's direction (the pose geometry's `drive_axes`
  say which, per leg); with the slider massless, that is the same point of the chain.

Zero, the default of every key, is a rigid connection (today's behaviour), not a free one.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import InputError
from .joints import JOINTS
from .settings import check_settings, declared, setting

# Plausible springs at the edge: a bearing or drive softer than 1e-3 N/um (1 kN/m) carries no
# machine; above 1e13 N/um a spring is rigid to every digit of a double (a steel leg's axial
# stiffness is of order 1e3 N/um, so 1e13 leaves the "rigid" limit 1e10 times clear).
MIN_SPRING = 1e3  # N/m or N m/rad (1e-3 at the edge)
MAX_SPRING = 1e19


def _spring(doc: str, unit: str):
    return setting(0.0, unit=unit, minimum=0.0, maximum=MAX_SPRING,
                   doc=doc + " (0: rigid, the default)")


@dataclass(frozen=True)
class Stiffness:
    """[stiffness]: the joints' and the drive's springs (default: all rigid)."""

    actuator_axial: float = _spring(
        "the drive's axial stiffness (screw, nut and bearings in series), along the leg at the "
        "housing/rod junction (at the base joint for a uniform leg); a 3-PRS: the slider's "
        "drive, along its rail", "N/um")
    base_joint_translational: float = _spring(
        "each translation of a base joint (its bearing), between the base and the leg end",
        "N/um")
    base_joint_rotational: float = _spring(
        "each rotation a base joint constrains (R: the two normal to its axis; an S joint "
        "constrains none)", "N m/urad")
    platform_joint_translational: float = _spring(
        "each translation of a platform joint, between the platform and the leg end", "N/um")
    platform_joint_rotational: float = _spring(
        "each rotation a platform joint constrains (R: the two normal to its axis; an S joint "
        "constrains none)", "N m/urad")

    def __post_init__(self) -> None:
        check_settings(self)
        for name, spec, _ in declared(self):
            value = getattr(self, name)
            if 0.0 < value < MIN_SPRING:
                raise InputError(f"stiffness.{spec.scene_key(name)} = {spec.edge(value):g}: "
                                 f"expected 0 (rigid) or at least {spec.edge(MIN_SPRING):g} "
                                 f"{spec.unit}")

    def values(self) -> dict[str, float]:
        """Every spring by field name, SI (the declaration's order)."""
        return {name: getattr(self, name) for name, _, _ in declared(self)}

    @property
    def rigid(self) -> bool:
        """True when every connection is rigid (no spring at all)."""
        return not any(self.values().values())

    def joint(self, end: str) -> tuple[float, float]:
        """(k_t, k_r) of the joint at `end` ("base" or "platform"), SI; 0 = rigid."""
        return (getattr(self, f"{end}_joint_translational"),
                getattr(self, f"{end}_joint_rotational"))

    def check_joints(self, base_joint: str, platform_joint: str) -> None:
        """Refuse a rotational spring on a joint that constrains no rotation (S)."""
        for end, kind in (("base", base_joint), ("platform", platform_joint)):
            k_r = getattr(self, f"{end}_joint_rotational")
            if k_r and JOINTS[kind].free == 3:
                raise InputError(
                    f"stiffness.{end}_joint_rotational_nm_per_urad = {k_r / 1e6:g} with "
                    f"{end}_joint = {kind!r}: a spherical joint constrains no rotation")

    def scaled(self, factor: float, names=None) -> "Stiffness":
        """These springs with `names` (default: all) multiplied by `factor` (rigid stays
        rigid)."""
        values = self.values()
        return Stiffness(**{n: v * factor if names is None or n in names else v
                            for n, v in values.items()})


def joint_spring_matrix(joint_type: str, axis, k_t: float, k_r: float) -> np.ndarray:
    """6x6 stiffness of a compliant joint on the leg end's motion relative to its body
    (translation, rotation; base coordinates), the module's K_t and K_r; `axis` (3,) or a
    batch (..., 3) of unit joint axes gives (..., 6, 6). A rigid part (k = 0) has no spring:
    the model ties that motion instead, and this block is zero there."""
    kind = JOINTS[joint_type]
    a = np.zeros(3) if axis is None else np.asarray(axis, float)
    out = np.zeros(a.shape[:-1] + (6, 6))
    out[..., :3, :3] = k_t * np.eye(3)
    if kind.has_axis and k_r:
        a = a / np.linalg.norm(a, axis=-1, keepdims=True)
        out[..., 3:, 3:] = k_r * (np.eye(3) - a[..., :, None] * a[..., None, :])
    return out
