"""The condensed end zone as the analytical model takes it: plain arrays, numpy only.

A zone's dofs are [t_J, theta_J, t_I, theta_I] with x from the joint J towards the interface
I (the local frame of `joint_ends.zone`). The zone at the platform end A_i of a leg is the
mirror image x -> -x of the zone at B_i, with its nodes in leg order [I, J]: translations flip
their x, rotations (pseudovectors) their y and z.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_MIRROR = np.diag([-1.0, 1.0, 1.0, 1.0, -1.0, -1.0])
_TO_TOP = np.block([[np.zeros((6, 6)), _MIRROR], [_MIRROR, np.zeros((6, 6))]])


@dataclass(frozen=True)
class EndZone:
    """A condensed solid end zone in its local frame: joint node first, x towards the middle."""

    length: float  # l_z, m
    stiffness: np.ndarray  # (12, 12)
    mass: np.ndarray  # (12, 12)

    def at_platform_end(self) -> tuple[np.ndarray, np.ndarray]:
        """(K, M) of the zone at A_i in the limb frame, nodes [interface, joint]."""
        return _TO_TOP.T @ self.stiffness @ _TO_TOP, _TO_TOP.T @ self.mass @ _TO_TOP
