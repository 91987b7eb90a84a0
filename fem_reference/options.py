"""What a solid model of a pose is (`FemOptions`), how it is run (`FemRuntime`), and its error.

Below both leg discretisations (`tetrahedra.py`, `harmonic.py`): every module of the package
may import from here; nothing here imports a discretisation.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, replace

from common.errors import InputError
from common.joints import COUPLINGS
from common.settings import MAX_SOLVED_MODES, check_settings, nested_setting, setting
from meshing.geometry import MeshSettings

from .eigen import BACKENDS

PLATFORMS = ("rigid", "elastic")
LEG_MODELS = ("harmonic", "tetrahedra")


def legs_for(platform: str | None, legs: str | None) -> str | None:
    """The leg discretisation asked for: `legs` when given; else tetrahedra for an elastic
    plate (meshed in 3D, so are the legs joined to it); else None (FemOptions' default)."""
    if legs is None and platform == "elastic":
        return "tetrahedra"
    return legs


class FemError(InputError):
    """Bad input or a failed FEM step; the message is one line naming the offending value."""


@dataclass(frozen=True)
class FemOptions:
    """What the solid model is: the mesh, the platform, the joint-face coupling, the modes.

    Everything that changes the answer is here (the result cache keys on the whole object);
    how the answer is obtained (cache directory, DOF guard, linear solver) is `FemRuntime`.
    """

    mesh: MeshSettings = nested_setting(MeshSettings)
    platform: str = setting("rigid", kind=str, choices=PLATFORMS,
                            doc="rigid: 6 coordinates at o with the plate's inertia (as the "
                            "paper); elastic: the plate meshed as a solid")
    legs: str = setting("harmonic", kind=str, choices=LEG_MODELS,
                        doc="how the solid legs are discretised: harmonic (the exact Fourier "
                        "split of each cylinder's 3D elasticity on a 2D meridian mesh of P2 "
                        "triangles, harmonic.py; rigid platform only) or tetrahedra (a 3D "
                        "mesh of 10-node tetrahedra, graded toward the rims; what an elastic "
                        "platform takes when legs is not given)")
    coupling: str = setting("rigid", kind=str, choices=COUPLINGS,
                            doc="how a joint face follows its joint centre: rigid (RBE2-like) or "
                            "distributing (RBE3-like, the face may warp)")
    modes: int = setting(6, kind=int, minimum=1, maximum=MAX_SOLVED_MODES, scene=False,
                         doc="number of modes solved for")
    platform_mesh: float = setting(
        0.2, minimum=0.0, exclusive_minimum=True, maximum=2.0, scene=False,
        doc="element size of the rigid platform's own mesh, over which its mass and inertia "
        "are integrated, as a fraction of the platform radius (0.2: 1e-6 of the disk's "
        "closed form, fem_reference/rigid_platform.py)")

    def __post_init__(self):
        if not isinstance(self.mesh, MeshSettings):
            raise FemError(f"mesh = {self.mesh!r}: expected MeshSettings")
        try:
            check_settings(self)
        except ValueError as exc:
            raise FemError(str(exc)) from None
        if self.legs == "harmonic" and self.platform != "rigid":
            raise FemError(f"legs = 'harmonic' with platform = {self.platform!r}: harmonic legs "
                           "need the rigid platform (use legs = 'tetrahedra')")

    @property
    def mesh_size(self) -> float:
        return self.mesh.size

    def with_size(self, size: float) -> "FemOptions":
        """The same options at another global element size (m)."""
        try:
            return replace(self, mesh=replace(self.mesh, size=float(size)))
        except ValueError as exc:
            raise FemError(str(exc)) from None


@dataclass(frozen=True)
class FemRuntime:
    """How a solve is run; nothing here changes the frequencies."""

    cache_dir: str | os.PathLike | None = None  # mesh cache; None: meshing.cache.DEFAULT_DIR
    use_cache: bool = True
    max_dofs: int = setting(600_000, kind=int, minimum=100, maximum=100_000_000,
                            doc="refuse meshes with more raw degrees of freedom than this "
                            "(estimated before meshing); whatever it says, a solve whose "
                            "estimated memory exceeds half of what the machine has available "
                            "is refused too (fem_reference/resources.py)")
    backend: str = setting("splu", kind=str, choices=BACKENDS, scene=False,
                           doc="sparse factorisation of the shift-invert eigen solve")
    memory_share: float = setting(1.0, minimum=0.0, exclusive_minimum=True, maximum=1.0,
                                  scene=False, doc="the share of the memory limit this solve "
                                  "may take: 1 / n when n solves run at once (a sweep's "
                                  "workers), so together they stay within it")

    def __post_init__(self):
        try:
            check_settings(self)
        except ValueError as exc:
            raise FemError(str(exc)) from None


def with_size(options: FemOptions, size: float) -> FemOptions:
    """`options.with_size(size)` (the same options at another global element size, m)."""
    return options.with_size(size)

