"""The hard cases' row and the helpers every claim uses."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

import results
from analytical.params import Manipulator
from common.leg_profile import LegProfile
from common.payload import Payload
from common.stiffness import Stiffness

SEED = 20231201


@dataclass(frozen=True)
class Row:
    case: str
    claim: str
    tolerance: float
    measured: float
    unit: str = ""
    note: str = ""

    @property
    def passed(self) -> bool:
        return bool(self.measured <= self.tolerance)

    def record(self) -> results.HardCase:
        return results.HardCase(case=self.case, claim=self.claim, tolerance=self.tolerance,
                                measured=self.measured, unit=self.unit, note=self.note,
                                passed=self.passed)


def checked_residuals(modal) -> np.ndarray:
    """The relative residuals of a solve's eigenpairs (`analytical.modal`; every dense solve
    states them)."""
    if modal.residuals is None:
        raise ValueError("the eigen solve stated no residuals")
    return modal.residuals


def bare(m: Manipulator) -> Manipulator:
    """The machine without its payload and springs: the claims of symmetry (repeated pairs,
    turned layouts) and of material scaling are the structure's; a payload off the axis breaks
    the three-fold symmetry, its mass does not scale with the material's density, nor does a
    spring's stiffness with the material's modulus."""
    return replace(m, payload=Payload(), stiffness=Stiffness())


def uniform(m: Manipulator, diameter: float) -> Manipulator:
    """The machine with uniform solid legs of `diameter` (the claims about a leg's slenderness
    are the paper's leg's)."""
    return replace(m, leg=LegProfile(), leg_diameter=diameter)


def turned(m: Manipulator, angle: float) -> Manipulator:
    """The same machine with its leg layout turned by `angle` (rad) about z."""
    a, b, c = (x + angle for x in m.leg_angles)
    return replace(m, leg_angles=(a, b, c))


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q

def untestable(case: str, tolerance: float, exc: Exception) -> Row:
    """The row of a claim whose changed machine reaches no pose to test it at."""
    return Row(case, "nothing to test: the changed machine reaches no pose", tolerance, 0.0,
               note=str(exc))
