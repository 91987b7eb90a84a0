"""The substructure model of many machines at one pose each (input samples), batched for the
eigen solves: each machine's K and M assembled as `batch_model.assemble_batch` assembles one
pose (its assembly plan, which depends only on the leg layout, built once and reused), then
stacked so that `batch_model.standard_form`, `batch_frequencies` and
`tool_response.batch_tool_modes` solve them together as they solve a map's poses.

A sample that moves only material, springs or payload leaves the kinematics as it is: one
pose geometry serves every sample (`same_geometry`); a sample that moves the machine's
dimensions gets its own (`pose_batch` per machine), and one whose pose is out of reach is
refused before any solve (`SampleOutOfReach`).
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from common.errors import InputError

from .batch_model import assemble_batch, assembly_plan, machine_parts, stack_parts
from .batch_solve import BatchModel
from .params import Manipulator, ModelOptions, Pose
from .pose_batch import PoseBatch, pose_batch
from .substructure import leg_layout

KINEMATIC_FREE = ("material", "stiffness", "payload")  # tables that never move the kinematics


class SampleOutOfReach(InputError):
    """A sampled machine cannot reach the pose."""


def same_geometry(tables) -> bool:
    """Whether samples that move keys of these tables all share the scene's pose geometry."""
    return all(t in KINEMATIC_FREE for t in tables)


def sample_poses(machines: Sequence[Manipulator], pose: Pose, shared: bool) -> PoseBatch:
    """The pose of every machine (one geometry repeated when `shared`), checked reachable."""
    if shared:
        one = pose_batch(machines[0], [pose.height], [pose.azimuth], [pose.tilt])
        index = np.zeros(len(machines), int)
        poses = one.take(index)
    else:
        singles = [pose_batch(m, [pose.height], [pose.azimuth], [pose.tilt]) for m in machines]
        stacked: dict[str, Any] = {
            name: (np.concatenate([getattr(p, name) for p in singles])
                   if isinstance(getattr(singles[0], name), np.ndarray)
                   else getattr(singles[0], name)) for name in PoseBatch.__dataclass_fields__}
        poses = PoseBatch(**stacked)
    out = np.flatnonzero(~poses.feasible)
    if len(out):
        raise SampleOutOfReach(f"sample {int(out[0]) + 1} ({len(out)} of {len(machines)} "
                               "samples) cannot reach the pose")
    return poses


def assemble_samples(machines: Sequence[Manipulator], poses: PoseBatch,
                     options: ModelOptions, modes: int = 0) -> BatchModel:
    """K and M of machine k at pose k, (N, n_q, n_q), assembled as one batch: each machine's
    own parts (`batch_model.machine_parts`) at its pose, stacked, then one assembly. `modes`:
    solid legs reduced to that many modal coordinates a part in every sample (the nominal
    machine's, `batch_model.leg_reduction`; 0: every station kept)."""
    if not machines:
        raise InputError("no samples to assemble")
    layouts = [leg_layout(m, options, poses.base_joint, poses.platform_joint, modes)
               for m in machines]
    if any(layout != layouts[0] for layout in layouts[1:]):
        raise InputError("the samples' models have different coordinates (an input changes "
                         "the leg's layout); sample one layout at a time")
    parts = stack_parts([machine_parts(m, poses.take([k]), options, layouts[0], modes)
                         for k, m in enumerate(machines)])
    return assemble_batch(machines[0], poses, options, assembly_plan(layouts[0]), parts,
                          modes)
