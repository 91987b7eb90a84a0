"""Natural-frequency maps over the regular workspace (paper Section 3.3, Fig. 6).

Which poses are reachable is `analytical.reach` (Eq. 25 and no interpenetration). The regular
workspace is the polar-coordinate construction the paper cites: in each height layer, the
largest circle theta <= theta_r(z) inside the reachable set (`reach.regular_radii`), so the
whole workspace is a truncated cone in (z, theta cos phi, theta sin phi).

A map samples every layer on rings (tilt fractions of theta_r) and azimuths. Its modes are
followed by shape (analytical.tracking): from the level pose of each layer out along azimuth
0 ring by ring, around every ring, and from layer to layer through the level poses, so a family
keeps its name where it crosses another; the crossings are recorded. Layers are independent
tasks, run on every core (one process per core); within a layer the poses are assembled and
solved as a batch (analytical.batch_model), eigenvalues only except where tracking needs shapes.
"""
from __future__ import annotations

import math
import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Literal, cast

import numpy as np

from common.errors import InputError

from .batch_model import CHUNK, assemble_batch, assembly_plan, batch_coordinates, batch_layout
from .batch_solve import batch_modes, frequencies, probe_shapes, standard_form
from .end_zones import zone_for
from .params import Manipulator, ModelOptions
from .pose_batch import pose_batch
from .reach import regular_radii
from .tracking import (
    REPEATED,
    family_values,
    follow,
    match_modes,
    match_steps,
    steps_needing_shapes,
)

GUARD_MODES = 1  # modes followed above the reported ones, so a family leaving is seen
LOST_MAC = 0.5  # a match below this MAC loses the family (it left the tracked window)


@dataclass(frozen=True)
class Crossing:
    """Two families swap order between neighbouring poses of a map (linearly interpolated)."""

    families: tuple[int, int]  # 0-based family indices, lower first
    height: float  # m
    tilt: float  # rad
    azimuth: float  # rad
    frequency_hz: float
    along: Literal["azimuth", "tilt", "height"]  # the direction of the map's step


@dataclass(frozen=True)
class Tracking:
    """How the modes of a map were followed."""

    root_height: float  # m: families are numbered by their order at this layer's level pose
    window: int  # modes followed (the reported ones and GUARD_MODES more)
    steps: int  # neighbour-to-neighbour steps followed
    steps_with_shapes: int  # steps matched by MAC (the rest could not hide a crossing)
    poses_with_shapes: int
    min_mac: float  # worst MAC of a reported family over the steps matched by MAC
    open_rings: int  # rings whose tracking does not return to its start after a full turn
    lost: tuple[int, ...]  # reported families that left the window somewhere (NaN there)


@dataclass(frozen=True)
class FrequencyMap:
    heights: np.ndarray  # (nz,) m
    radii: np.ndarray  # (nz,) regular tilt radius theta_r(z), rad
    tilts: np.ndarray  # (nz, nr) rad, 0..theta_r(z)
    azimuths: np.ndarray  # (nphi,) rad
    frequencies_hz: np.ndarray  # (nz, nr, nphi, modes) ascending; NaN outside the workspace
    tracked_hz: np.ndarray | None = None  # (nz, nr, nphi, modes) per family (tracked by MAC)
    crossings: tuple[Crossing, ...] = ()
    tracking: Tracking | None = None


@dataclass(frozen=True)
class _Layer:
    radius: float
    sorted_hz: np.ndarray  # (nr, nphi, w + 1), NaN where unreachable
    order: np.ndarray  # (nr, nphi, w): family (numbered at the level pose) -> sorted index
    lost: np.ndarray  # (nr, nphi, w) bool
    mac: np.ndarray  # (nr, nphi, w) MAC of the step into each pose per family (1: no shapes)
    crossings: list  # Crossing, families numbered at this layer's level pose
    level_shapes: np.ndarray | None  # (d, w) probe shapes of the level pose
    steps: int
    steps_with_shapes: int
    poses_with_shapes: int
    open_rings: int


def _empty_layer(rings: int, azimuths: int, window: int) -> _Layer:
    return _Layer(0.0, np.full((rings, azimuths, window + 1), np.nan),
                  np.tile(np.arange(window), (rings, azimuths, 1)),
                  np.ones((rings, azimuths, window), bool), np.full((rings, azimuths, window),
                                                                   np.nan),
                  [], None, 0, 0, 0, 0)


def _layer(manipulator: Manipulator, options: ModelOptions, height: float, radius: float,
           fractions: np.ndarray, phis: np.ndarray, window: int) -> _Layer:
    """Frequencies of one height layer (regular tilt radius `radius`), and its modes followed
    from its level pose."""
    rings, azimuths = len(fractions), len(phis)
    if not pose_batch(manipulator, height, 0.0, 0.0).feasible[0]:
        return _empty_layer(rings, azimuths, window)
    tilts = radius * fractions
    ring_of = np.concatenate([[0], np.repeat(np.arange(1, rings), azimuths)])
    az_of = np.concatenate([[0], np.tile(np.arange(azimuths), rings - 1)])
    poses = pose_batch(manipulator, height, phis[az_of], tilts[ring_of])
    where = np.full((rings, azimuths), -1)  # solved pose of every (ring, azimuth); -1: none
    feasible = np.flatnonzero(poses.feasible)
    where[ring_of[feasible], az_of[feasible]] = np.arange(len(feasible))
    where[0, :] = where[0, 0]  # the level pose is the same for every azimuth
    solvable = poses.take(feasible)
    plan = assembly_plan(batch_layout(manipulator, options, poses.base_joint,
                                      poses.platform_joint))
    solved = []  # per chunk of poses: (its slice, its model, its frequencies)
    for chunk in _chunks(len(feasible)):
        model = assemble_batch(manipulator, solvable.take(chunk), options, plan)
        solved.append((chunk, model, frequencies(model, window + 1, keep=True)))
    hz = np.concatenate([found for _, _, found in solved])
    sorted_hz = np.where(where[..., None] >= 0, hz[where], np.nan)

    steps, closures = _steps(where, sorted_hz)
    shaped = np.unique([where[0, 0]] + [where[q] for a, b, need, _ in steps + closures
                                        if need for q in (a, b)])
    probes: dict[int, np.ndarray] = {}
    for chunk, model, _ in solved:
        inside = shaped[(shaped >= chunk.start) & (shaped < chunk.stop)] - chunk.start
        if len(inside):  # the standard form of these poses alone
            _, vectors = batch_modes(standard_form(model, inside), np.arange(len(inside)),
                                     window)
            probes.update(zip((inside + chunk.start).tolist(),
                              probe_shapes(model, vectors, inside)))
    matched = [step for step in steps + closures if step[2]]
    match = {}
    if matched:
        src = [where[a] for a, *_ in matched]
        dst = [where[b] for _, b, *_ in matched]
        targets, qualities = match_steps(np.stack([probes[k] for k in src]), hz[src, :window],
                                         np.stack([probes[k] for k in dst]), hz[dst, :window])
        match = {(a, b): (t, q) for (a, b, *_), t, q in zip(matched, targets, qualities)}
    order, lost, mac, crossings = _follow(steps, match, sorted_hz, window,
                                          lambda at: (height, tilts[at[0]], phis[at[1]]))
    open_rings = sum(int(np.any(follow(order[a], match[a, b][0]) != order[b]))
                     for a, b, need, _ in closures if need)
    lost[where < 0] = True  # unreachable poses carry no family
    return _Layer(radius, sorted_hz, order, lost, mac, crossings, probes[where[0, 0]],
                  len(steps) + len(closures), len(matched), len(shaped), open_rings)


def _steps(where: np.ndarray, sorted_hz: np.ndarray) -> tuple[list, list]:
    """The steps a layer is followed along, (source, target, needs shapes, direction): out
    along the first reachable azimuth of every ring (the spine), then around every ring; and
    the closing step of every ring, which only checks that the labels come back."""
    rings, azimuths = where.shape
    anchors, members = [(0, 0)], {}
    for r in range(1, rings):
        on_ring = [a for a in range(azimuths) if where[r, a] >= 0]
        if not on_ring:
            break
        members[r] = on_ring
        anchors.append((r, on_ring[0]))
    spine = steps_needing_shapes(sorted_hz[tuple(np.array(anchors).T)])
    steps = [(a, b, bool(need), "tilt") for a, b, need in zip(anchors, anchors[1:], spine)]
    closures = []
    for r, on_ring in members.items():
        path = [(r, a) for a in on_ring]
        need = steps_needing_shapes(sorted_hz[r, on_ring], closed=True)
        skips = [b - a != 1 for a, b in zip(on_ring, on_ring[1:])]  # an unreachable gap
        steps += [(a, b, bool(n or skip), "azimuth")
                  for a, b, n, skip in zip(path, path[1:], need[:-1], skips)]
        if len(on_ring) > 1:
            closures.append((path[-1], path[0], bool(need[-1] or len(on_ring) < azimuths),
                             "closure"))
    return steps, closures


def _follow(steps: list, match: dict, sorted_hz: np.ndarray, window: int, position):
    """Family labels along the steps (sorted order where no shapes were needed, the MAC match
    where they were), whether each family is lost, the MAC into each pose, the crossings."""
    rings, azimuths = sorted_hz.shape[:2]
    order = np.zeros((rings, azimuths, window), int)
    order[0] = np.arange(window)
    lost = np.zeros((rings, azimuths, window), bool)
    mac = np.ones((rings, azimuths, window))
    crossings = []
    for a, b, need, along in steps:
        if not need:
            order[b], lost[b] = order[a], lost[a]
            continue
        target, quality = match[a, b]
        order[b] = follow(order[a], target)
        mac[b] = quality[order[a]]
        lost[b] = lost[a] | (mac[b] < LOST_MAC)
        crossings += _crossings(sorted_hz[a], order[a], sorted_hz[b], order[b], position(a),
                                position(b), along, ~lost[b])
    return order, lost, mac, crossings


def _chunks(count: int, size: int = CHUNK) -> list[slice]:
    return [slice(a, min(a + size, count)) for a in range(0, count, size)]


def _crossings(hz_a, order_a, hz_b, order_b, where_a, where_b, along,
               followed: np.ndarray) -> list[Crossing]:
    """The pairs of followed families whose order differs between two neighbouring poses."""
    fa, fb = family_values(hz_a, order_a), family_values(hz_b, order_b)
    out = []
    for i in np.flatnonzero(followed):
        for j in np.flatnonzero(followed[i + 1:]) + i + 1:
            d0, d1 = fa[i] - fa[j], fb[i] - fb[j]
            tol = REPEATED * max(abs(fa[i]), abs(fb[i]))
            if abs(d0) > tol and abs(d1) > tol and np.sign(d0) != np.sign(d1):
                t = d0 / (d0 - d1)
                z0, th0, ph0 = where_a
                z1, th1, ph1 = where_b
                turn = math.remainder(ph1 - ph0, 2 * math.pi)
                out.append(Crossing((int(i), int(j)), z0 + t * (z1 - z0), th0 + t * (th1 - th0),
                                    (ph0 + t * turn) % (2 * math.pi),
                                    float(fa[i] + t * (fb[i] - fa[i])), along))
    return out


def _layer_task(args) -> _Layer:
    return _layer(*args)


def _run_layers(tasks: list, workers: int) -> list[_Layer]:
    """Every layer, in one process or in a pool of `workers` forked processes (a daemonic
    process may not have children: it runs them itself)."""
    if workers <= 1 or len(tasks) <= 1 or multiprocessing.current_process().daemon:
        return [_layer_task(t) for t in tasks]
    try:
        context = multiprocessing.get_context("fork")
    except ValueError:  # no fork on this platform
        context = None
    with ProcessPoolExecutor(min(workers, len(tasks)), mp_context=context) as pool:
        return list(pool.map(_layer_task, tasks))


def default_workers() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def _link_layers(layers: list[_Layer], heights: np.ndarray, window: int):
    """Number the families of every layer after one root layer, following the level poses
    from layer to layer. Returns per layer the layer's own family number of every global
    family (-1: lost), the crossings between layers, the root index and the steps taken."""
    reachable_layers = [i for i, layer in enumerate(layers) if layer.level_shapes is not None]
    relabel = [np.full(window, -1) for _ in layers]
    if not reachable_layers:
        return relabel, [], None, 0
    root = min(reachable_layers, key=lambda i: abs(i - (len(layers) - 1) / 2))
    relabel[root] = np.arange(window)
    crossings = []
    k = reachable_layers.index(root)
    for walk in (reachable_layers[k:], reachable_layers[k::-1]):
        for a, b in zip(walk, walk[1:]):
            la, lb = layers[a], layers[b]
            hz_a, hz_b = la.sorted_hz[0, 0, :window], lb.sorted_hz[0, 0, :window]
            # the walk visits reachable layers only: their level shapes are arrays
            target, mac = match_modes(cast(np.ndarray, la.level_shapes), hz_a,
                                      cast(np.ndarray, lb.level_shapes), hz_b)
            known = relabel[a] >= 0  # local numbers are sorted indices at the level pose
            relabel[b] = np.where(known & (mac[np.maximum(relabel[a], 0)] >= LOST_MAC),
                                  target[np.maximum(relabel[a], 0)], -1)
            crossings += _crossings(hz_a, np.maximum(relabel[a], 0), hz_b,
                                    np.maximum(relabel[b], 0), (heights[a], 0.0, 0.0),
                                    (heights[b], 0.0, 0.0), "height", relabel[b] >= 0)
    return relabel, crossings, root, len(reachable_layers) - 1


def _renumbered(crossing: Crossing, relabel: np.ndarray) -> Crossing | None:
    """A layer's crossing with its families numbered globally (None if one is not tracked)."""
    inverse = {int(local): j for j, local in enumerate(relabel) if local >= 0}
    if not all(f in inverse for f in crossing.families):
        return None
    a, b = sorted(inverse[f] for f in crossing.families)
    return Crossing((a, b), crossing.height, crossing.tilt, crossing.azimuth,
                    crossing.frequency_hz, crossing.along)


def followed_modes(manipulator, options) -> int:
    """The most modes a map can follow with these options: one fewer than the model has
    coordinates (the window of every pose)."""
    return batch_coordinates(manipulator, options) - 1


def frequency_map(manipulator: Manipulator, options: ModelOptions, heights, rings: int = 6,
                  azimuths: int = 24, workers: int | None = None) -> FrequencyMap:
    """The lowest `options.modes` frequencies on a polar grid of every height layer, sorted
    and per family (followed by shape), with the places where families cross.

    Families are numbered by their order at the level pose of the middle reachable layer.
    `workers` processes share the layers (default: every core this process may use).
    """
    heights = np.asarray(heights, float)
    phis = np.linspace(0.0, 2 * math.pi, azimuths, endpoint=False)
    fractions = np.linspace(0.0, 1.0, rings)
    modes = options.modes
    window = min(modes + GUARD_MODES, followed_modes(manipulator, options))
    if not len(heights):
        raise InputError("heights = []: a map needs at least one height")
    radii = regular_radii(manipulator, heights)
    zone_for(manipulator, options)  # build or load solid end zones once, before the workers
    tasks = [(manipulator, options, float(z), float(r), fractions, phis, window)
             for z, r in zip(heights, radii)]
    layers = _run_layers(tasks, default_workers() if workers is None else workers)
    relabel, crossings, root, layer_steps = _link_layers(layers, heights, window)
    sorted_hz = np.stack([layer.sorted_hz for layer in layers])
    tracked_by_layer, lost_by_layer, macs_by_layer = [], [], []
    for layer, numbers in zip(layers, relabel):
        local = np.broadcast_to(np.maximum(numbers, 0), layer.order.shape)
        order = np.take_along_axis(layer.order, local, -1)
        gone = np.take_along_axis(layer.lost, local, -1) | (numbers < 0)
        tracked_by_layer.append(np.where(gone, np.nan, family_values(layer.sorted_hz, order)))
        lost_by_layer.append(gone)
        macs_by_layer.append(np.take_along_axis(layer.mac, local, -1))
        crossings += [c for c in (_renumbered(c, numbers) for c in layer.crossings) if c]
    tracked = np.stack(tracked_by_layer)
    lost, macs = np.stack(lost_by_layer), np.stack(macs_by_layer)
    reached = np.isfinite(sorted_hz[..., :modes])
    reported = macs[..., :modes][reached & ~lost[..., :modes]]
    summary = Tracking(
        root_height=float(heights[root]) if root is not None else math.nan,
        window=window,
        steps=sum(layer.steps for layer in layers) + layer_steps,
        steps_with_shapes=sum(layer.steps_with_shapes for layer in layers) + layer_steps,
        poses_with_shapes=sum(layer.poses_with_shapes for layer in layers),
        min_mac=float(reported.min()) if reported.size else math.nan,
        open_rings=sum(layer.open_rings for layer in layers),
        lost=tuple(j for j in range(modes) if np.any(lost[..., j] & reached[..., j])),
    )
    return FrequencyMap(heights, radii, np.outer(radii, fractions), phis,
                        sorted_hz[..., :modes], tracked[..., :modes],
                        tuple(sorted((c for c in crossings if c.families[0] < modes),
                                     key=lambda c: (c.height, c.tilt, c.azimuth))), summary)
