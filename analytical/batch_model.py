"""The substructure model of many poses at once (Eqs. 4-24), for workspace maps.

The same reduced K and M as `substructure.assemble`, pose by pose (with solid legs, on fewer
coordinates: below), built with numpy over a batch of poses, for the eigen solves of
`batch_solve`:

- the element matrices depend only on the leg length: one batched `frame_element` call gives
  every element of every leg of every pose (a leg's s elements are equal); solid end zones
  (analytical.end_zones) are the same two matrices in every pose;
- every joint map T_i (Eqs. 10, 12, 17, 21) is affine in the arm A_i - o and in the R-joint
  direction, so it is read from `substructure._leg_map` once, at zero and unit arms and
  directions, and combined per pose (`LegMapBasis`);
- K = sum over legs and elements of T_e^T K_e T_e (Eqs. 5-6, 13, 22) with T_e the element's
  12 rows of the leg map in its limb frame, restricted to the columns of q they touch;
- the rigid platform's mass (Eqs. 7-9) is diag(m I, R J R^T), with m and J read from
  `platform_mass_matrix` at R = I, plus, for a payload off the platform centre, the coupling
  -[R S x] / [R S x] of its first moment S (common/payload.py).

- with solid legs, each part's interior reduced to the fewest of its own modes that keep the
  frequencies within REDUCTION_TARGET of every station kept, chosen per machine
  (`leg_reduction`, `part_reduction`).

The eigen solves and the shapes compared between poses are `batch_solve`'s.
tests/test_workspace_fast.py checks matrices and frequencies against the per-pose model.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from common.errors import InputError
from common.rigid_body import skew
from common.settings import MAX_SOLVED_MODES

from .batch_solve import BatchModel, frequencies
from .end_zones import zone_for
from .kinematics import Joint
from .leg_chain import leg_segments
from .modal import ModalError
from .params import Manipulator, ModelOptions
from .platform import platform_mass_matrix
from .pose_batch import PoseBatch, pose_batch
from .solid_legs import part_blocks
from .substructure import (
    LegLayout,
    SingularJointMap,
    _leg_map,
    coordinate_count,
    leg_layout,
    r_joint_direction,
    spring_stiffness,
)

CHUNK = 64  # poses assembled and solved together (their matrices stay in cache)


@dataclass(frozen=True)
class LegMapBasis:
    """T_i(arm, d, e) = constant + sum_k arm_k * per_arm[k] + sum_k d_k * per_direction[k]
    + sum_k e_k * per_axis[k], restricted to `columns` of q (the leg's own coordinates and the
    platform's); e is the drive's direction (its stretch moves along it: the leg's axis in a
    3-RPS, the rail in a 3-PRS)."""

    columns: np.ndarray  # (c,) indices into q
    constant: np.ndarray  # (6(s+1), c)
    per_arm: np.ndarray  # (3, 6(s+1), c)
    per_direction: np.ndarray  # (3, 6(s+1), c)
    per_axis: np.ndarray  # (3, 6(s+1), c)

    def evaluate(self, arms: np.ndarray, directions: np.ndarray,
                 axes: np.ndarray | None = None) -> np.ndarray:
        """(N, 6(s+1), c) for arms, R-joint directions and leg axes of shape (N, 3)."""
        varying = (arms @ self.per_arm.reshape(3, -1)
                   + directions @ self.per_direction.reshape(3, -1))
        if axes is not None:
            varying = varying + axes @ self.per_axis.reshape(3, -1)
        return self.constant + varying.reshape((len(arms),) + self.constant.shape)

    def touched(self, rows: slice) -> np.ndarray:
        """Local columns that the given rows can reach for some arm, direction and axis."""
        every = (np.abs(self.constant) + np.abs(self.per_arm).sum(0)
                 + np.abs(self.per_direction).sum(0) + np.abs(self.per_axis).sum(0))
        return np.flatnonzero(np.any(every[rows] != 0.0, axis=0))


def _runs(q_columns: np.ndarray) -> list[tuple[slice, slice]]:
    """Contiguous runs of increasing q indices: (slice of q, slice of their positions)."""
    breaks = np.flatnonzero(np.diff(q_columns) != 1) + 1
    starts = np.concatenate([[0], breaks])
    stops = np.concatenate([breaks, [len(q_columns)]])
    return [(slice(int(q_columns[a]), int(q_columns[b - 1]) + 1), slice(int(a), int(b)))
            for a, b in zip(starts, stops)]


def leg_map_basis(layout: LegLayout, leg: int, base_joint: str, platform_joint: str
                  ) -> LegMapBasis:
    """The joint map of leg `leg` probed at zero and unit arms, R-joint directions and leg
    axes."""
    def leg_map(arm, direction, axis):
        joints = (Joint.at(base_joint, np.zeros(3), direction, "base"),
                  Joint.at(platform_joint, np.zeros(3), direction, "platform"))
        return _leg_map(layout, leg, joints, np.asarray(arm, float), "axis",
                        np.asarray(axis, float))

    zero = np.zeros(3)
    constant = leg_map(zero, zero, zero)
    per_arm = np.stack([leg_map(e, zero, zero) - constant for e in np.eye(3)])
    per_direction = np.stack([leg_map(zero, e, zero) - constant for e in np.eye(3)])
    per_axis = np.stack([leg_map(zero, zero, e) - constant for e in np.eye(3)])
    every = np.concatenate([constant[None], per_arm, per_direction, per_axis])
    columns = np.flatnonzero(np.any(every != 0.0, axis=(0, 1)))
    probe = (np.array([0.3, -0.7, 0.2]), np.array([0.6, 0.1, -0.4]),
             np.array([-0.5, 0.4, 0.3]))
    affine = LegMapBasis(columns, constant[:, columns], per_arm[:, :, columns],
                         per_direction[:, :, columns], per_axis[:, :, columns])
    if not np.allclose(affine.evaluate(*(p[None] for p in probe))[0],
                       leg_map(*probe)[:, columns], rtol=0, atol=1e-14) or np.any(
                           leg_map(*probe)[:, np.setdiff1d(np.arange(constant.shape[1]),
                                                           columns)]):
        raise AssertionError("the joint map is not affine in the arm, joint direction and "
                             "leg axis")
    return affine


# The batched model's solid legs (`part_reduction`): each part's interior reduced to the fewest
# of these modal coordinates that keep f1..f_CHECK_MODES (or the run's modes, if more) within
# REDUCTION_TARGET of every station kept, at the machine's CHECK poses: a tenth of issue 51's
# 1e-4, for the poses between them. None meeting it: every station kept.
MODE_COUNTS = (12, 18, 24, 30, 36)
REDUCTION_TARGET = 1e-5
CHECK_MODES = 10


@dataclass(frozen=True)
class LegReduction:
    """How the batched model reduces one machine's solid legs, and what it costs."""

    modes: int  # modal coordinates a part (0: every station kept)
    error: float  # largest |f_reduced / f_kept - 1| over the checked modes and poses
    poses: int  # poses checked (the level band's ends and middle, level and at full tilt)
    coordinates: tuple[int, int]  # n a pose: every station kept, reduced


def batch_layout(manipulator: Manipulator, options: ModelOptions, base_joint: str,
                 platform_joint: str) -> LegLayout:
    """The legs' layout of the batched model: the per-pose model's, with solid legs reduced
    (`leg_reduction`)."""
    return leg_layout(manipulator, options, base_joint, platform_joint,
                      leg_reduction(manipulator, options).modes)


def batch_coordinates(manipulator: Manipulator, options: ModelOptions) -> int:
    """The batched model's coordinates (its most modes) for this machine and options."""
    return coordinate_count(batch_layout(manipulator, options, manipulator.base_joint,
                                         manipulator.platform_joint))


@functools.lru_cache(maxsize=32)
def leg_reduction(manipulator: Manipulator, options: ModelOptions) -> LegReduction:
    """The solid legs' reduction for this machine (module constants above; remembered per
    process): the fewest modal coordinates whose frequencies at the check poses are within
    REDUCTION_TARGET of the model with every station kept."""
    from .reach import WorkspaceError, level_band, regular_radii

    def size(modes):
        return coordinate_count(leg_layout(manipulator, options, manipulator.base_joint,
                                           manipulator.platform_joint, modes))

    kept = size(0)
    if options.legs != "solid":
        return LegReduction(0, 0.0, 0, (kept, kept))
    # fewer modal coordinates than the interior has, and more coordinates a pose than any
    # count of modes a run may ask (a map, a minimum, the dynamic stiffness's sum)
    counts = [c for c in MODE_COUNTS
              if c < 6 * (options.elements - 1) and size(c) > MAX_SOLVED_MODES]
    if not counts:
        return LegReduction(0, 0.0, 0, (kept, kept))
    try:
        band = level_band(manipulator)
    except WorkspaceError:  # no level pose: nothing to check against, nothing reduced
        return LegReduction(0, 0.0, 0, (kept, kept))
    heights = np.repeat(np.linspace(band.low, band.high, 3), 3)
    tilts = 0.98 * np.repeat(regular_radii(manipulator, np.linspace(band.low, band.high, 3)),
                             3) * np.tile([0.0, 1.0, 1.0], 3)
    azimuths = np.tile([0.0, 0.0, math.pi], 3)
    poses = pose_batch(manipulator, heights, azimuths, tilts)
    poses = poses.take(np.flatnonzero(poses.feasible))
    count = min(max(CHECK_MODES, options.modes), size(counts[0]) - 1)
    if not len(poses):
        return LegReduction(0, 0.0, 0, (kept, kept))
    try:
        reference = frequencies(assemble_batch(manipulator, poses, options, modes=0), count)
        for modes in counts:
            hz = frequencies(assemble_batch(manipulator, poses, options, modes=modes), count)
            error = float(np.max(np.abs(hz / reference - 1.0)))
            if error <= REDUCTION_TARGET:
                return LegReduction(modes, error, len(poses), (kept, size(modes)))
    except (ModalError, InputError):  # a check pose the model cannot solve: keep every
        pass  # station (the run's own poses say what is wrong with them, if anything)
    return LegReduction(0, 0.0, len(poses), (kept, kept))


@dataclass(frozen=True)
class AssemblyPlan:
    """What does not change from pose to pose: per leg its map basis and, per segment, the
    local columns its rows touch and where those sit in q (contiguous runs)."""

    layout: LegLayout
    legs: tuple  # per leg: (LegMapBasis, ((columns, runs) per segment))


def assembly_plan(layout: LegLayout) -> AssemblyPlan:
    legs = []
    for i in range(3):
        basis = leg_map_basis(layout, i, layout.base.type, layout.top.type)
        per_element = []
        for e in range(layout.segments):
            columns = basis.touched(slice(6 * e, 6 * e + 12))
            per_element.append((columns, _runs(basis.columns[columns])))
        legs.append((basis, tuple(per_element)))
    return AssemblyPlan(layout, tuple(legs))


def _directions(axes: np.ndarray, form: str) -> np.ndarray:
    """(N, 3) rotation of the R-joint leg end per unit independent coordinate."""
    if form == "axis":
        return axes
    return np.array([r_joint_direction(a, form) for a in axes])


@dataclass(frozen=True)
class MachineParts:
    """What the machine itself (not its pose) puts into K and M, per pose of a batch: the leg
    segments' limb-frame matrices, whole solid parts, the springs, the platform's mass at
    R = I and the payload's first moment. One machine at N poses (`machine_parts`), or N
    machines at a pose each (`stack_parts`: input samples) assemble alike."""

    segments: np.ndarray  # (s, 2, 3, N, 12, 12), Eq. (4)
    solid: tuple  # ((first node, (2, 3, N, d, d)), ...) with legs = "solid"
    springs: tuple  # per leg: ((columns, (N, c, c)), ...)
    level: np.ndarray  # (N, 6, 6) platform mass at R = I (payload included)
    first_moment: np.ndarray  # (N, 3) the payload's, platform frame
    leg_radius: float
    platform_radius: float


def machine_parts(manipulator: Manipulator, poses: PoseBatch, options: ModelOptions,
                  layout: LegLayout, modes: int | None = None) -> MachineParts:
    """The parts of one machine at every pose of `poses` (`modes`: the solid legs' modal
    coordinates a part; None: the machine's, `leg_reduction`)."""
    n = len(poses)
    if modes is None:
        modes = leg_reduction(manipulator, options).modes
    segments = leg_segments(manipulator, options, zone_for(manipulator, options),
                            poses.leg_lengths.T, modes)
    solid = tuple(part_blocks(manipulator, options, poses.leg_lengths.T, modes))
    joints = (Joint.at(poses.base_joint, np.zeros(3), np.zeros(3), "base"),
              Joint.at(poses.platform_joint, np.zeros(3), np.zeros(3), "platform"))
    springs = tuple(
        tuple((columns, np.broadcast_to(spring, (n, *np.shape(spring)[-2:])))
              for columns, spring in spring_stiffness(layout, manipulator, i, joints,
                                                      poses.joint_axes[:, i]))
        for i in range(3))
    level = platform_mass_matrix(manipulator, np.eye(3), options.platform_inertia)
    return MachineParts(segments, solid, springs, np.broadcast_to(level, (n, 6, 6)),
                        np.broadcast_to(manipulator.payload.first_moment, (n, 3)),
                        manipulator.leg_diameter / 2, manipulator.platform_radius)


def stack_parts(parts: list[MachineParts]) -> MachineParts:
    """Parts of N batches (one machine each) as one batch, poses in order."""
    first = parts[0]
    return MachineParts(
        np.concatenate([p.segments for p in parts], axis=3),
        tuple((f, np.concatenate([p.solid[k][1] for p in parts], axis=2))
              for k, (f, _) in enumerate(first.solid)),
        tuple(tuple((columns, np.concatenate([p.springs[i][k][1] for p in parts]))
                    for k, (columns, _) in enumerate(first.springs[i])) for i in range(3)),
        np.concatenate([p.level for p in parts]),
        np.concatenate([p.first_moment for p in parts]),
        first.leg_radius, first.platform_radius)


def assemble_batch(manipulator: Manipulator, poses: PoseBatch, options: ModelOptions,
                   plan: AssemblyPlan | None = None, parts: MachineParts | None = None,
                   modes: int | None = None) -> BatchModel:
    """K and M of every pose in `poses` (Eqs. 4-22), as substructure.assemble does one, with
    solid legs reduced to `modes` modal coordinates a part (None: the machine's,
    `leg_reduction`; 0: every station kept, the per-pose model's coordinates).

    `plan` (from `assembly_plan`) may be passed to reuse it over many batches; `parts` (from
    `machine_parts` or `stack_parts`) gives the machine's own matrices per pose (default:
    `manipulator`'s at every pose).
    """
    if modes is None:
        modes = leg_reduction(manipulator, options).modes
    layout = leg_layout(manipulator, options, poses.base_joint, poses.platform_joint, modes)
    s = layout.segments  # elements, end zones with solid joint ends, the drive's
    if plan is None or plan.layout != layout:
        plan = assembly_plan(layout)
    if parts is None:
        parts = machine_parts(manipulator, poses, options, layout, modes)
    n, n_q = len(poses), coordinate_count(layout)
    matrices = np.zeros((2, n, n_q, n_q))  # K and M
    arms = poses.platform_points - poses.platform_centre[:, None, :]
    maps = []
    for i, (basis, per_element) in enumerate(plan.legs):
        try:
            directions = _directions(poses.joint_axes[:, i], options.r_joint_coordinate)
        except SingularJointMap as exc:
            raise ModalError(str(exc)) from None
        axes = poses.drive_axes[:, i]  # the drive's direction (the leg's axis; a rail)
        t = basis.evaluate(arms[:, i], directions, axes)  # leg DOFs from q, Eqs. (10)-(21)
        limb_to_base = np.swapaxes(poses.leg_frames[:, i], 1, 2)[:, None]
        local = (limb_to_base @ t.reshape(n, 2 * (s + 1), 3, -1)).reshape(t.shape)  # Eq. (6)
        for e, (columns, runs) in enumerate(per_element):
            rows = local[:, 6 * e:6 * e + 12][:, :, columns]
            reduced = np.swapaxes(rows, 1, 2) @ parts.segments[e, :, i] @ rows  # (2, N, c, c)
            for to_rows, a in runs:
                for to_cols, b in runs:
                    matrices[:, :, to_rows, to_cols] += reduced[:, :, a, b]
        for first, block in parts.solid:  # legs = "solid": whole parts, (2, 3, N, d, d)
            span = slice(6 * first, 6 * first + block.shape[-1])
            columns = basis.touched(span)
            rows = local[:, span][:, :, columns]
            reduced = np.swapaxes(rows, 1, 2) @ block[:, i] @ rows
            for to_rows, a in _runs(basis.columns[columns]):
                for to_cols, b in _runs(basis.columns[columns]):
                    matrices[:, :, to_rows, to_cols] += reduced[:, :, a, b]
        maps.append((basis.columns, t))
        for columns, spring in parts.springs[i]:
            matrices[0][:, columns[:, None], columns[None, :]] += spring
    stiffness, mass = matrices
    translation, rotation = slice(n_q - 6, n_q - 3), slice(n_q - 3, n_q)
    level = parts.level
    mass[:, translation, translation] += level[:, :3, :3]  # m I
    mass[:, rotation, rotation] += poses.rotation @ level[:, 3:, 3:] @ np.swapaxes(
        poses.rotation, 1, 2)  # R J R^T
    if np.any(parts.first_moment):  # an offset payload: -[R S x], [R S x]
        coupling = skew(np.einsum("nij,nj->ni", poses.rotation, parts.first_moment))
        mass[:, translation, rotation] -= coupling
        mass[:, rotation, translation] += coupling
    return BatchModel(stiffness, mass, tuple(maps), slice(n_q - 6, n_q),
                      parts.leg_radius, parts.platform_radius)


