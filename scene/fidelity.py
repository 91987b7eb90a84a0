"""[fidelity]: what accuracy a scene asks for, declared once (the choice that meets it is the
fidelity study's, `studies.fidelity`)."""
from __future__ import annotations

from dataclasses import dataclass

from common.settings import MAX_MODES, check_settings, setting

MIN_TOLERANCE_PERCENT = 0.01  # a fifth of it is the FEM's attainable accuracy (see the doc)


@dataclass(frozen=True)
class FidelitySettings:
    """[fidelity]: what accuracy the scene needs, on which modes."""

    modes: int = setting(6, kind=int, minimum=1, maximum=MAX_MODES,
                         doc="number of modes compared, lowest first")
    tolerance_percent: float = setting(
        1.0, minimum=MIN_TOLERANCE_PERCENT, maximum=50.0,
        doc="largest |error| accepted on each compared mode, analytical model against the "
        "converged FEM, in percent (at least 0.01: the FEM reference may use a fifth of it, "
        "and 0.002 % is already below the stated error of the finest meshes that fit in "
        "memory; a smaller tolerance could never be shown to be met)")

    def __post_init__(self):
        check_settings(self)
