"""Hard cases: continuity of the frequencies along paths, and tracking through crossings."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from analytical.batch_model import assemble_batch
from analytical.batch_solve import batch_modes, probe_shapes, standard_form
from analytical.params import Manipulator, ModelOptions, Pose
from analytical.pose_batch import pose_batch
from analytical.reach import layer_heights, regular_radii
from analytical.tracking import family_values, track_path
from scene import Scene

from .base import Row

# --- continuity and tracking ----------------------------------------------------------------

def _path_modes(m: Manipulator, opts: ModelOptions, start: Pose, end: Pose, steps: int):
    """Frequencies (n, w), probe shapes (n, d, w), and d lambda / dt (n, w) along a straight
    path in (height, azimuth, tilt); the derivative by Hellmann-Feynman, x^T (dK - lambda dM) x
    with dK, dM central differences of the assembled matrices."""
    t = np.linspace(0.0, 1.0, steps)
    ends = np.array([[start.height, start.azimuth, start.tilt],
                     [end.height, end.azimuth, end.tilt]])

    def at(tt):
        p = ends[0] + np.outer(tt, ends[1] - ends[0])
        return assemble_batch(m, pose_batch(m, p[:, 0], p[:, 1], p[:, 2]), opts)

    h = 1e-6
    plus, minus = at(t + h), at(t - h)
    d_k = (plus.stiffness - minus.stiffness) / (2 * h)
    d_m = (plus.mass - minus.mass) / (2 * h)
    model = at(t)
    form = standard_form(model)
    hz, x = batch_modes(form, np.arange(steps), opts.modes)
    lam = (2 * math.pi * hz) ** 2
    rate = (np.einsum("nia,nij,nja->na", x, d_k, x)
            - lam * np.einsum("nia,nij,nja->na", x, d_m, x))
    return t, hz, probe_shapes(model, x), rate


def straight_path(m: Manipulator, steps: int = 120) -> tuple[Pose, Pose, str]:
    """A straight path across the workspace: from a quarter to three quarters of the layer
    band in height, azimuth 0.3 -> 2.6 rad, tilt from 20 % to 80 % of the smaller regular
    radius of its two ends. The workspace need not be convex in (height, azimuth, tilt): where
    a pose of the path (at `steps` points) is unreachable, the tilts are halved until every
    pose is (level poses over the band always are). The note says so where it happened."""
    z = layer_heights(m, 5)
    radius = float(regular_radii(m, [z[1], z[3]]).min())
    t = np.linspace(0.0, 1.0, steps)
    for scale in 0.5 ** np.arange(12):
        start = Pose(float(z[1]), 0.3, 0.2 * radius * scale)
        end = Pose(float(z[3]), 2.6, 0.8 * radius * scale)
        path = pose_batch(m, start.height + t * (end.height - start.height),
                          start.azimuth + t * (end.azimuth - start.azimuth),
                          start.tilt + t * (end.tilt - start.tilt))
        if path.feasible.all():
            return start, end, ("" if scale == 1 else f"tilts scaled by {scale:g} to keep "
                                "every pose of the path reachable")
    return (Pose(float(z[1]), 0.3, 0.0), Pose(float(z[3]), 2.6, 0.0),
            "level poses only: no tilted straight path of this machine is reachable")


def continuity(scene: Scene, steps: int = 120, modes: int = 6) -> Row:
    """Along a straight path in (height, azimuth, tilt), every followed family moves by what
    its derivative explains: each step's change of omega^2 differs from the trapezoid of the
    Hellmann-Feynman derivatives at its ends by less than 2 % of the change (no jump). The
    first six families are followed among nine modes, so one crossing a higher mode stays
    followed."""
    m, opts = scene.manipulator, replace(scene.analytical, modes=modes + 3)
    start, end, note = straight_path(m, steps)
    t, hz, shapes, rate = _path_modes(m, opts, start, end, steps)
    order, quality = track_path(hz, shapes)
    kept = np.minimum.accumulate(quality[:, :modes] >= 0.5, axis=0)[1:]  # not left the modes
    lam = family_values((2 * math.pi * hz) ** 2, order)[:, :modes]
    slope = family_values(rate, order)[:, :modes]
    step = np.diff(lam, axis=0)
    predicted = np.diff(t)[:, None] * 0.5 * (slope[1:] + slope[:-1])
    mismatch = np.abs(step - predicted) / np.maximum(np.abs(step), 1e-9 * lam[1:])
    return Row("continuity along a straight pose path", "each step's change of every family's "
               f"omega^2 against the trapezoid of its derivatives ({steps} steps)", 0.02,
               float(mismatch[kept].max()), "relative", note)


def near_crossing(scene: Scene, steps: int = 60) -> Row:
    """Level poses keep the three-fold symmetry, so families of different symmetry cross
    exactly as the height changes (on the paper's machine a repeated pair falls through a
    threefold leg mode near z = 248.5 mm). Tilted by 1e-4 rad the symmetry is broken and the
    crossing becomes a near-crossing. Followed by shape through it, no family swaps with
    another: every step keeps every family's shape (MAC, or subspace MAC inside a repeated
    group) above 0.9."""
    m, opts = scene.manipulator, replace(scene.analytical, modes=9)
    heights = layer_heights(m, 41)
    _, hz, shapes, _ = _path_modes(m, opts, Pose(heights[0]), Pose(heights[-1]),
                                   len(heights))
    order, _ = track_path(hz, shapes)
    swapped = np.flatnonzero(np.any(order[1:] != order[:-1], axis=1))
    if not len(swapped):
        return Row("near-crossing tracked without swaps", "no two of the first nine families "
                   "cross at level poses: nothing to test", 0.1, 0.0)
    k = int(swapped[0])
    start = Pose(float(heights[k]), 0.4, 1e-4)
    end = Pose(float(heights[k + 1]), 0.4, 1e-4)
    if not pose_batch(m, np.linspace(start.height, end.height, steps), 0.4,
                      1e-4).feasible.all():
        return Row("near-crossing tracked without swaps", "the machine cannot tilt by 1e-4 rad "
                   "at the crossing: nothing to test", 0.1, 0.0)
    _, hz, shapes, _ = _path_modes(m, opts, start, end, steps)
    _, quality = track_path(hz, shapes)
    return Row("near-crossing tracked without swaps", "1 - the lowest MAC of a followed "
               f"family between neighbouring poses, {steps} steps through the near-crossing at "
               f"{1e3 * heights[k]:.1f}-{1e3 * heights[k + 1]:.1f} mm, tilt 1e-4 rad", 0.1,
               float(1.0 - quality.min()))
