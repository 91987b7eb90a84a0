"""The hard cases' row and the helpers every claim uses."""
from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np

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

    def to_dict(self) -> dict:
        return {**asdict(self), "passed": self.passed}


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
    return replace(m, leg_angles=tuple(a + angle for a in m.leg_angles))


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q

def untestable(case: str, tolerance: float, exc: Exception) -> Row:
    """The row of a claim whose changed machine reaches no pose to test it at."""
    return Row(case, "nothing to test: the changed machine reaches no pose", tolerance, 0.0,
               note=str(exc))
