"""Regular workspace and natural-frequency maps over it (paper Section 3.3, Eq. 25, Fig. 6).

The reachable orientations at one height are the tilts theta (any azimuth phi) for which every
constraint of Eq. (25) holds. The regular workspace is the polar-coordinate construction the
paper cites: in each height layer, the largest circle theta <= theta_r(z) inside the reachable
set, so the whole workspace is a truncated cone in (z, theta cos phi, theta sin phi).
"""
from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from .kinematics import PoseError, pose_geometry
from .model import natural_frequencies
from .params import Manipulator, ModelOptions, Pose

MAX_TILT = math.radians(89.0)


def reachable(manipulator: Manipulator, pose: Pose) -> bool:
    try:
        pose_geometry(manipulator, pose)
    except PoseError:
        return False
    return True


def max_tilt(manipulator: Manipulator, height: float, azimuth: float,
             tolerance: float = 1e-6) -> float:
    """Largest tilt (rad) reachable at (height, azimuth) starting from the level platform.

    Found by bisection on theta in [0, 89 deg]; 0 when even the level pose is unreachable.
    """
    if not reachable(manipulator, Pose(height, azimuth, 0.0)):
        return 0.0
    lo, hi = 0.0, MAX_TILT
    if reachable(manipulator, Pose(height, azimuth, hi)):
        return hi
    while hi - lo > tolerance:
        mid = 0.5 * (lo + hi)
        if reachable(manipulator, Pose(height, azimuth, mid)):
            lo = mid
        else:
            hi = mid
    return lo


def regular_radius(manipulator: Manipulator, height: float, azimuths: int = 72) -> float:
    """theta_r(z): the largest tilt reachable at every azimuth of this height layer (rad)."""
    phis = np.linspace(0.0, 2 * math.pi, azimuths, endpoint=False)
    return min(max_tilt(manipulator, height, float(p)) for p in phis)


@dataclass(frozen=True)
class FrequencyMap:
    heights: np.ndarray  # (nz,) m
    radii: np.ndarray  # (nz,) regular tilt radius theta_r(z), rad
    tilts: np.ndarray  # (nz, nr) rad, 0..theta_r(z)
    azimuths: np.ndarray  # (nphi,) rad
    frequencies_hz: np.ndarray  # (nz, nr, nphi, modes); NaN outside the regular workspace


def frequency_map(manipulator: Manipulator, options: ModelOptions, heights, rings: int = 6,
                  azimuths: int = 24) -> FrequencyMap:
    """The lowest `options.modes` frequencies on a polar grid of every height layer."""
    heights = np.asarray(heights, float)
    phis = np.linspace(0.0, 2 * math.pi, azimuths, endpoint=False)
    radii = np.array([regular_radius(manipulator, z) for z in heights])
    tilts = np.outer(radii, np.linspace(0.0, 1.0, rings))
    freqs = np.full((len(heights), rings, azimuths, options.modes), np.nan)
    for iz, z in enumerate(heights):
        if radii[iz] <= 0.0 and not reachable(manipulator, Pose(z)):
            continue
        for ir, theta in enumerate(tilts[iz]):
            for ip, phi in enumerate(phis):
                freqs[iz, ir, ip] = natural_frequencies(manipulator, Pose(z, phi, theta), options)
                if ir == 0:  # the level pose is the same for every azimuth
                    freqs[iz, ir, :] = freqs[iz, ir, ip]
                    break
    return FrequencyMap(heights, radii, tilts, phis, freqs)
