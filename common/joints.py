"""The kinds of joint a leg ends in, declared once, and the couplings of a joint face.

A joint joins a leg end to a body (the fixed base or the moving platform). Its centre moves with
the body; of the leg end's rotation, the joint leaves `free` independent rotations to the leg
and ties the rest to the body's rotation:

- "S" (spherical): all three rotations free; the body's rotation does not reach the leg;
- "R" (revolute): one rotation free, about the joint axis; the two normal to it follow the body.

Kinematics, the analytical substructure synthesis and both FEM discretisations read a joint's
behaviour from here (`JOINTS[type]`), so a new kind of joint (a universal joint: two rotations
free) is one declaration, not a branch in every model. The strings are the scene file's
(`base_joint = "R"`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class JointType:
    """What a joint leaves free. `free` independent rotations; with an axis (R) they are
    rotations about it, without one (S) all three."""

    name: str  # the scene's letter
    description: str
    free: int  # independent rotations the joint leaves to the leg end (its coordinates)
    has_axis: bool  # True: the free rotation is about the joint's axis

    def free_rotations(self, axis) -> np.ndarray:
        """(3, free): the directions of the rotations the joint leaves free."""
        if not self.has_axis:
            return np.eye(3)
        return np.asarray(axis, float).reshape(3, 1)

    def tied_rotations(self, axis) -> np.ndarray:
        """(3 - free, 3): rows spanning the rotations that follow the body (orthonormal)."""
        if not self.has_axis:
            return np.zeros((0, 3))
        a = np.asarray(axis, float)
        _, _, vt = np.linalg.svd(a[None, :])
        return vt[1:]

    @property
    def follows_body(self) -> bool:
        """True when part of the leg end's rotation is the body's (some rotation is tied)."""
        return self.free < 3


JOINTS: dict[str, JointType] = {
    "R": JointType("R", "revolute: one rotation about its axis", free=1, has_axis=True),
    "S": JointType("S", "spherical: three rotations", free=3, has_axis=False),
}
JOINT_TYPES = tuple(JOINTS)

# How a joint's face is tied to the joint: "rigid", the face moves as a rigid body with the
# joint's reference point; "distributing", only the face's average rigid motion is (the face
# deforms freely). One declaration for the analytical end zones, both FEM discretisations and
# the studies that compare them.
COUPLINGS = ("rigid", "distributing")
