"""Calibration of the one unknown the paper prints wrongly: the platform height.

The paper gives z = 4.9 m for both test poses, beyond the actuator limit L_max = 1 m. The height
is recovered from Case 1's theoretical row alone, as the value minimising the worst relative
deviation over the six modes (a minimax fit, one scalar for both cases).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import minimize_scalar

from .architectures import height_range
from .model import natural_frequencies
from .params import Manipulator, ModelOptions, Pose


@dataclass(frozen=True)
class HeightCalibration:
    height: float  # m
    worst_deviation: float  # max_i |f_i / target_i - 1| at that height
    deviations: np.ndarray  # per mode, signed


def worst_deviation(manipulator: Manipulator, pose: Pose, target_hz, options: ModelOptions
                    ) -> np.ndarray:
    target = np.asarray(target_hz, float)
    f = natural_frequencies(manipulator, pose, replace(options, modes=len(target)))
    return f / target - 1.0


def calibrate_height(manipulator: Manipulator, pose: Pose, target_hz,
                     options: ModelOptions, bounds: tuple[float, float] | None = None
                     ) -> HeightCalibration:
    """Height (m) at which the model best reproduces `target_hz` in the minimax sense."""
    lo, hi = bounds or height_range(manipulator)

    def cost(height: float) -> float:
        return float(np.abs(worst_deviation(manipulator, replace(pose, height=height),
                                            target_hz, options)).max())

    # coarse scan first: the minimax cost is not unimodal over the whole actuator range
    grid = np.linspace(lo, hi, 81)
    costs = []
    for h in grid:
        try:
            costs.append(cost(h))
        except ValueError:
            costs.append(np.inf)
    k = int(np.argmin(costs))
    res = minimize_scalar(cost, bounds=(grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]),
                          method="bounded", options={"xatol": 1e-7})
    dev = worst_deviation(manipulator, replace(pose, height=res.x), target_hz, options)
    return HeightCalibration(float(res.x), float(np.abs(dev).max()), dev)
