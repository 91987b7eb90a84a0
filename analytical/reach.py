"""The reachable workspace of a machine: the one definition every study takes its poses from.

A pose (height z, tilt azimuth phi, tilt theta) is reachable when the inverse kinematics closes
(Eqs. 1-3), every limit of Eq. (25) holds (actuator range or slider stroke, S- and R-joint
angles) and no bodies
interpenetrate (`kinematics.clearances`: legs apart, legs reaching the platform from below, the
plate above the base). `pose_batch.feasible` evaluates exactly that rule for many poses and
`kinematics.pose_geometry` raises on it for one; everything here is built on them, nothing keeps
a formula of its own.

From the rule:
- `level_band`: the heights at which the level pose is reachable (one interval; which limit
  bounds it at each end), or WorkspaceError naming the binding limit when there is none;
- `layer_band` / `layer_heights`: where studies put their height layers (inside the level band);
- `max_tilts` / `regular_radii`: the reachable tilt at every (height, azimuth) from the level
  pose, and theta_r(z), the largest tilt reachable at every azimuth of a layer (the paper's
  regular workspace, Fig. 6);
- `sample_poses`: random reachable poses (bounded work; fewer than asked only if the machine
  hardly tilts, never an endless loop).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from common.errors import InputError

from .architectures import actuation, height_reach, of
from .kinematics import PoseError, clearances, pose_geometry
from .params import Manipulator, Pose
from .pose_batch import pose_batch

MAX_TILT = math.radians(89.0)
LAYER_INSET = 0.05  # layers stay this fraction of the height reach (L_max) inside the band ...
LAYER_INSET_SHARE = 0.25  # ... or this share of the band's width, if the band is narrower
GRID = 2001  # heights scanned for the level band, (0, height reach] (a 3-RPS: L_max)
BAND_TOLERANCE = 1e-12  # m: the level band's ends, by bisection
SAMPLE_TILT = 0.6  # rad: random poses draw |tilt| up to this
SAMPLE_ROUNDS = 200  # rounds of 4 x count draws at most


class WorkspaceError(InputError):
    """The machine's reachable workspace is empty, or too thin for what was asked of it."""


@dataclass(frozen=True)
class LevelBand:
    """Heights (m) at which the level pose is reachable, and what bounds them."""

    low: float
    high: float
    binding_low: str  # the limit violated just below `low` (a scene key or a clearance)
    binding_high: str  # the same just above `high`

    @property
    def width(self) -> float:
        return self.high - self.low

    def bounding_text(self) -> str:
        return f"{self.binding_low} below, {self.binding_high} above"


def reachable(manipulator: Manipulator, pose: Pose) -> bool:
    try:
        pose_geometry(manipulator, pose)
    except PoseError:
        return False
    return True


def _level_ok(m: Manipulator, heights) -> np.ndarray:
    return pose_batch(m, heights, 0.0, 0.0).feasible


def violations(m: Manipulator, heights, azimuths, tilts) -> dict[str, np.ndarray]:
    """How far every pose is beyond each limit, relative (positive: violated), by the scene
    key of the limit or the name of the clearance."""
    b = pose_batch(m, heights, azimuths, tilts)
    scale = height_reach(m)
    act = actuation(m)
    out = {
        act.low_key: (act.low - b.actuation.min(axis=1)) / scale,
        act.high_key: (b.actuation.max(axis=1) - act.high) / scale,
        "s_joint_max_deg": np.abs(b.s_joint_angles).max(axis=1) / m.s_joint_max - 1,
        "r_joint_max_deg": np.abs(b.r_joint_angles).max(axis=1) / m.r_joint_max - 1,
    }
    for key, beyond in of(m).limits(m, b.platform_points).items():  # its own limits
        out[key] = beyond / scale
    apart = clearances(m, b.base_points, b.platform_points, b.rotation, b.platform_centre)
    out.update({f"{name} clearance": -value / scale for name, value in apart.items()})
    return out


def binding_limit(m: Manipulator, heights, azimuths, tilts) -> list[str]:
    """The limit each pose is furthest beyond (or closest to, when reachable)."""
    found = violations(m, heights, azimuths, tilts)
    names = list(found)
    return [names[k] for k in np.argmax(np.stack(list(found.values())), axis=0)]


def level_band(manipulator: Manipulator) -> LevelBand:
    """The interval of heights whose level pose is reachable (the longest one, should the
    limits leave several), its ends to BAND_TOLERANCE. Raises WorkspaceError naming the limit
    that binds at the height closest to reachable when no level pose is."""
    m = manipulator
    top = height_reach(m)  # no platform joint reaches higher
    z = np.linspace(top / GRID, top, GRID)
    ok = _level_ok(m, z)
    if not ok.any():
        worst = np.max(np.stack(list(violations(m, z, 0.0, 0.0).values())), axis=0)
        best = float(z[int(np.argmin(worst))])
        try:
            pose_geometry(m, Pose(best))
            why = "no reachable height found"
        except PoseError as exc:
            why = str(exc)
        raise WorkspaceError(f"no level pose of this machine is reachable at any height (the "
                             f"closest, z = {best * 1e3:.1f} mm: {why})")
    edges = np.flatnonzero(np.diff(np.concatenate([[0], ok.astype(int), [0]])))
    starts, stops = edges[::2], edges[1::2]  # runs [start, stop) of reachable heights
    k = int(np.argmax(stops - starts))
    first, last = int(starts[k]), int(stops[k]) - 1
    low = _bisect(m, z[first - 1], z[first]) if first > 0 else 0.0
    high = _bisect(m, z[last + 1], z[last]) if last < GRID - 1 else float(z[-1])
    below = binding_limit(m, max(low - 1e-6 * top, 1e-12), 0.0, 0.0)[0] \
        if first > 0 else "height > 0"
    above = binding_limit(m, high + 1e-6 * top, 0.0, 0.0)[0]
    return LevelBand(low, high, below, above)


def _bisect(m: Manipulator, outside: float, inside: float) -> float:
    """The reachable end of the level band between a height outside it and one inside."""
    while abs(inside - outside) > BAND_TOLERANCE:
        mid = 0.5 * (inside + outside)
        if _level_ok(m, [mid])[0]:
            inside = mid
        else:
            outside = mid
    return float(inside)


def layer_band(manipulator: Manipulator) -> tuple[float, float]:
    """Heights (m) of the lowest and highest study layer: the level band, LAYER_INSET L_max
    inside each end (a quarter of the band's width if it is narrower), so every layer's level
    pose is reachable with room to tilt."""
    band = level_band(manipulator)
    inset = min(LAYER_INSET * height_reach(manipulator), LAYER_INSET_SHARE * band.width)
    return band.low + inset, band.high - inset


def layer_heights(manipulator: Manipulator, count: int) -> np.ndarray:
    """`count` heights (m) evenly over `layer_band` (one, at its middle, for count = 1)."""
    low, high = layer_band(manipulator)
    if count == 1:
        return np.array([0.5 * (low + high)])
    return np.linspace(low, high, count)


def max_tilts(manipulator: Manipulator, heights, azimuths,
              tolerance: float = 1e-6) -> np.ndarray:
    """Largest tilt (rad) reachable from the level platform at every (height, azimuth):
    (len(heights), len(azimuths)), or (len(azimuths),) for one height.

    Bisection on theta in [0, 89 deg], all heights and azimuths at once; 0 where even the
    level pose is unreachable. Few pairs (a search's one pose) look several halvings ahead
    in one batch (`_bisect_tilts`): the same midpoints, decisions and result, bit for bit.
    """
    z = np.atleast_1d(np.asarray(heights, float))[:, None]
    phis = np.atleast_1d(np.asarray(azimuths, float))[None, :]
    z, phis = np.broadcast_arrays(z, phis)
    lo = np.zeros(z.shape)
    level = pose_batch(manipulator, z[:, 0], 0.0, 0.0).feasible
    hi = np.full(z.shape, MAX_TILT)
    done = ~level[:, None] | pose_batch(manipulator, z, phis, hi).feasible.reshape(z.shape)
    lo[done & level[:, None]] = MAX_TILT
    if not done.all():
        _bisect_tilts(manipulator, z, phis, lo, hi, done, tolerance)
    return lo if np.ndim(heights) else lo[0]


LOOKAHEAD_POSES = 64  # poses one bisection step may solve to decide several halvings at once


def _bisect_tilts(m: Manipulator, z, phis, lo, hi, done, tolerance: float) -> None:
    """Halve [lo, hi] of every pair not `done` (in place) until the widest is within
    `tolerance`, as plain bisection does (mid = (lo + hi) / 2, lo = mid where feasible, else
    hi = mid, the width checked after every halving), but `depth` halvings per batch: every
    midpoint the next `depth` halvings could visit (2^depth - 1 per pair, computed as bisection
    would from the same end points) solved at once, then the path walked."""
    active = np.flatnonzero(~done.ravel())
    lo_a, hi_a = lo.ravel()[active], hi.ravel()[active]
    z_a, phi_a = z.ravel()[active], phis.ravel()[active]
    depth = max(1, int(math.log2(LOOKAHEAD_POSES // len(active) + 1)))
    width = MAX_TILT
    while width > tolerance:
        ends_lo, ends_hi = lo_a[:, None], hi_a[:, None]
        mids = []
        for _ in range(depth):  # node k's children: 2k = [lo, mid], 2k + 1 = [mid, hi]
            mid = 0.5 * (ends_lo + ends_hi)
            mids.append(mid)
            ends_lo = np.stack([ends_lo, mid], -1).reshape(len(active), -1)
            ends_hi = np.stack([mid, ends_hi], -1).reshape(len(active), -1)
        tree = np.concatenate(mids, axis=1)  # (pairs, 2^depth - 1), level by level
        ok = pose_batch(m, np.repeat(z_a, tree.shape[1]), np.repeat(phi_a, tree.shape[1]),
                        tree.ravel()).feasible.reshape(tree.shape)
        node = np.zeros(len(active), int)
        rows = np.arange(len(active))
        for level in range(depth):
            k = (1 << level) - 1 + node
            step = ok[rows, k]
            lo_a = np.where(step, tree[rows, k], lo_a)
            hi_a = np.where(step, hi_a, tree[rows, k])
            node = 2 * node + step
            width = float(np.max(hi_a - lo_a))
            if width <= tolerance:
                break
    lo.ravel()[active] = lo_a
    hi.ravel()[active] = hi_a


def max_tilt(manipulator: Manipulator, height: float, azimuth: float,
             tolerance: float = 1e-6) -> float:
    """Largest tilt (rad) reachable at (height, azimuth) starting from the level platform."""
    return float(max_tilts(manipulator, height, [azimuth], tolerance)[0])


def regular_radii(manipulator: Manipulator, heights, azimuths: int = 72) -> np.ndarray:
    """theta_r(z) of every height: the largest tilt reachable at every azimuth (rad)."""
    phis = np.linspace(0.0, 2 * math.pi, azimuths, endpoint=False)
    return np.min(max_tilts(manipulator, np.atleast_1d(heights), phis), axis=1)


def regular_radius(manipulator: Manipulator, height: float, azimuths: int = 72) -> float:
    """theta_r(z): the largest tilt reachable at every azimuth of this height layer (rad)."""
    return float(regular_radii(manipulator, [height], azimuths)[0])


def sample_poses(manipulator: Manipulator, count: int, rng: np.random.Generator) -> list[Pose]:
    """`count` random reachable poses: heights uniform over `layer_band`, azimuths uniform,
    tilts uniform in [-SAMPLE_TILT, SAMPLE_TILT], the unreachable ones rejected. Bounded: after
    SAMPLE_ROUNDS rounds the poses found so far are returned (at least one: the level pose of
    every layer height is reachable, and a machine that hardly tilts fills the rounds with it);
    WorkspaceError if there is no level band."""
    low, high = layer_band(manipulator)
    out: list[Pose] = []
    for _ in range(SAMPLE_ROUNDS):
        n = 4 * count
        z, phi, theta = (rng.uniform(low, high, n), rng.uniform(0, 2 * math.pi, n),
                         rng.uniform(-SAMPLE_TILT, SAMPLE_TILT, n))
        ok = pose_batch(manipulator, z, phi, theta).feasible
        out += [Pose(float(a), float(b), float(c)) for a, b, c in
                zip(z[ok], phi[ok], theta[ok])]
        if len(out) >= count:
            return out[:count]
    if not out:  # the machine does not tilt at all: level poses over the band
        out = [Pose(float(z)) for z in rng.uniform(low, high, count)]
    return out
