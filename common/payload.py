"""A payload on the platform: a rigid body fixed to it (a tool, a spindle, a workpiece), declared
once and carried identically by both models: it is an idealisation they share (like the pose);
what is elastic, each model builds on its own. Its place is not checked against the legs (a
spindle may hang below the platform, among them).

The scene gives its mass m, its centre c in the platform frame (from o, mm at the edge) and its
principal moments of inertia about its own centre, along the platform axes. About o, in the
platform frame, on (translation of o, rotation), its mass is that of any rigid body
(`rigid_body.rigid_body_mass`'s convention):

    M = [[m I, -[S x]], [[S x], J_o]],   S = m c,   J_o = J_c + m (|c|^2 I - c c^T)

(the parallel-axis theorem), and in base coordinates diag(R, R) M diag(R, R)^T.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import InputError
from .rigid_body import skew
from .settings import MAX_LENGTH, check_settings, setting

MAX_MASS = 1e5  # kg: a hundred tonnes, beyond any payload a parallel machine of legs carries
MAX_INERTIA = 1e6  # kg m2: that mass at a radius of a few metres


@dataclass(frozen=True)
class Payload:
    """[payload]: a rigid body fixed to the platform (default: none)."""

    mass: float = setting(0.0, unit="kg", minimum=0.0, maximum=MAX_MASS,
                          doc="mass of the payload (0: no payload)")
    centre: tuple[float, float, float] = setting(
        (0.0, 0.0, 0.0), kind=tuple, unit="mm", length=3, minimum=-MAX_LENGTH,
        maximum=MAX_LENGTH, doc="its centre of mass in the platform frame, from the platform "
        "centre o (z along the platform normal)")
    inertia: tuple[float, float, float] = setting(
        (0.0, 0.0, 0.0), kind=tuple, unit="kg m2", length=3, minimum=0.0, maximum=MAX_INERTIA,
        doc="principal moments of inertia about its own centre, along the platform axes x, y, "
        "z (each at most the sum of the other two, as for any body)")

    def __post_init__(self) -> None:
        check_settings(self)
        a, b, c = self.inertia
        for k, (value, others) in enumerate(((a, b + c), (b, a + c), (c, a + b))):
            if value > others * (1 + 1e-9) + 1e-12:
                raise InputError(
                    f"payload.inertia_kg_m2 = {list(self.inertia)}: moment {k + 1} exceeds "
                    "the sum of the other two, which no body has (triangle inequality)")
        if self.mass == 0.0 and any(self.inertia):
            raise InputError(f"payload.inertia_kg_m2 = {list(self.inertia)} with mass_kg = 0: "
                             "a payload with inertia needs its mass")

    @property
    def first_moment(self) -> np.ndarray:
        """S = m c (kg m), platform frame."""
        return self.mass * np.asarray(self.centre, float)

    def body_mass(self) -> np.ndarray:
        """6x6 mass about o in the platform frame (the module docstring)."""
        c = np.asarray(self.centre, float)
        out = np.zeros((6, 6))
        out[:3, :3] = self.mass * np.eye(3)
        out[:3, 3:] = -skew(self.first_moment)
        out[3:, :3] = skew(self.first_moment)
        out[3:, 3:] = np.diag(self.inertia) + self.mass * (c @ c * np.eye(3) - np.outer(c, c))
        return out


def payload_mass_matrix(payload: Payload, rotation: np.ndarray) -> np.ndarray:
    """6x6 mass of the payload about o in base coordinates, the platform turned by `rotation`."""
    r6 = np.zeros((6, 6))
    r6[:3, :3] = r6[3:, 3:] = np.asarray(rotation, float)
    return r6 @ payload.body_mass() @ r6.T
