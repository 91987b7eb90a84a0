"""A model against a modal test at one pose: the model's modes sampled at the test's measured
dofs, the MAC matrix, the pairing by shape and frequency, the frequency error of every pair,
and the modes left unpaired, each named with the reason.

The pairing (never by order alone): a test mode i and a model mode j may pair when their MAC is
at least `min_mac` and |f_j / f_i - 1| is at most `max_frequency_deviation_percent`; among the
admissible pairs the assignment maximises the sum of MAC - |ln(f_j / f_i)| (shape first, the
frequency breaking near-ties: 10 % apart costs as much as 0.095 of MAC), one model mode per
test mode (Hungarian algorithm, scipy's linear_sum_assignment). Against a group of model modes
of (near-)repeated frequency (relative gap below 2 %, a symmetric machine's pairs) any basis is
as valid as another, so a test shape's score there is its share in the group's subspace
(`solvers.pairing.group_scores`), not its MAC with one arbitrary member. A test's own
near-repeated pair (two modes within 2 %) is paired by shape first, like any mode; a member
left without a partner (its measured shape a mix of the pair's, as the model's are not) is then
paired by a model shape's share in the pair's subspace, among the model modes left. Within a
group, frequency orders; such a pair is marked `repeated` and its `mac` is the subspace share.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from common.modes import clusters, mac_matrix
from common.paths import display_path
from results.campaign_records import (
    SCHEMA,
    Correlation,
    CorrelationSummary,
    MachineRecord,
    ModelRecord,
    NodeRecord,
    PairingRecord,
    PairRecord,
    PoseCorrelation,
    UnpairedModel,
    UnpairedTest,
)
from solvers.pairing import group_scores

from .campaign import Campaign, CorrelationSettings, TestPose
from .placement import ModeField, sample

REPEAT_TOLERANCE = 0.02  # relative frequency gap of a repeated group (as solvers.pairing)
RULE = ("admissible: MAC >= min_mac and |f_model / f_test - 1| <= the largest deviation; "
        "assigned to maximise the sum of MAC - |ln(f_model / f_test)| (Hungarian), one model "
        "mode per test mode; against a repeated model group (within 2 %) the test shape's share "
        "in its subspace stands for the MAC, and a test mode of a near-repeated test group left "
        "unpaired is paired by its group's subspace; within a group, frequency orders")
DIRECTIONS = ("x", "y", "z")


@dataclass(frozen=True)
class Scores:
    """How alike each test shape is to each model shape (test, model)."""

    mac: np.ndarray  # the plain MAC
    score: np.ndarray  # the MAC; against a repeated model group, the share in its subspace
    test_subspace: np.ndarray  # against a test group: a model shape's share in its subspace
    test_groups: list[list[int]]
    model_groups: list[list[int]]

    @property
    def repeated(self) -> set[int]:
        """The model modes in a repeated group."""
        return {j for g in self.model_groups if len(g) > 1 for j in g}


def scores(test_shapes: np.ndarray, model_shapes: np.ndarray, model_hz: np.ndarray,
           test_hz: np.ndarray) -> Scores:
    """The MAC and the subspace shares of groups of (near-)repeated modes on either side."""
    mac = mac_matrix(test_shapes, model_shapes)
    model_groups = clusters(np.asarray(model_hz, float), REPEAT_TOLERANCE)
    test_groups = clusters(np.asarray(test_hz, float), REPEAT_TOLERANCE)
    score = group_scores(test_shapes, model_shapes, mac, model_groups)
    test_subspace = group_scores(model_shapes, test_shapes, mac.T, test_groups).T
    return Scores(mac, score, test_subspace, test_groups, model_groups)


def _assign(score: np.ndarray, ok: np.ndarray, ratio: np.ndarray, rows: list[int],
            cols: list[int], mac: np.ndarray) -> dict[int, int]:
    """The admissible assignment of `rows` to `cols` maximising score - |ln ratio| (a tie
    inside a repeated group, where every member scores its subspace share, broken by the
    plain MAC)."""
    if not rows or not cols:
        return {}
    sub = np.ix_(rows, cols)
    cost = np.where(ok[sub], -(score[sub] - np.abs(ratio[sub]) + 1e-6 * mac[sub]), 1e6)
    r, c = linear_sum_assignment(cost)
    return {rows[i]: cols[j] for i, j in zip(r, c) if ok[rows[i], cols[j]]}


def _in_order(pairs: dict[int, int], members: list[int], test_hz: np.ndarray,
              model_hz: np.ndarray) -> None:
    """The partners of `members` (one group: one subspace) in ascending order of frequency."""
    members = sorted((i for i in members if i in pairs), key=lambda k: test_hz[k])
    partners = sorted((pairs[i] for i in members), key=lambda k: model_hz[k])
    pairs.update(zip(members, partners))


def pair(s: Scores, test_hz: np.ndarray, model_hz: np.ndarray,
         settings: CorrelationSettings) -> tuple[dict[int, int], set[int], dict[int, str]]:
    """({test mode: model mode}, test modes paired as a group's member, {unpaired test mode:
    reason}), 0-based. First by shape (the MAC; a repeated model group as a subspace); then a
    test mode of a near-repeated test group that found no partner (its measured shape a mix of
    the group's) by its group's subspace, among the model modes left."""
    test_hz = np.asarray(test_hz, float)
    model_hz = np.asarray(model_hz, float)
    ratio = np.log(model_hz[None, :] / test_hz[:, None])
    limit = settings.max_frequency_deviation_percent / 100.0
    near = np.abs(model_hz[None, :] / test_hz[:, None] - 1.0) <= limit
    ok = (s.score >= settings.min_mac) & near
    every = list(range(len(test_hz)))
    pairs = _assign(s.score, ok, ratio, every, list(range(len(model_hz))), s.mac)
    grouped = {i for i, j in pairs.items() if j in s.repeated}
    for group in s.model_groups:
        _in_order(pairs, [i for i, j in pairs.items() if j in group], test_hz, model_hz)
    ok_group = (s.test_subspace >= settings.min_mac) & near
    for group in s.test_groups:
        left = [i for i in group if i not in pairs]
        if len(group) < 2 or not left:
            continue
        used = set(pairs.values())
        found = _assign(s.test_subspace, ok_group, ratio, left,
                        [j for j in range(len(model_hz)) if j not in used], s.mac)
        pairs.update(found)
        grouped |= set(found)
        _in_order(pairs, list(found), test_hz, model_hz)
    reasons: dict[int, str] = {}
    for i in every:
        if i in pairs:
            continue
        best = int(np.argmax(s.score[i]))
        if not near[i].any():
            j = int(np.argmin(np.abs(ratio[i])))
            reasons[i] = (f"no model mode within {settings.max_frequency_deviation_percent:g} % "
                          f"(nearest: model mode {j + 1} at {model_hz[j]:.2f} Hz)")
        elif not ok[i].any():
            reasons[i] = (f"no admissible shape: best MAC {s.score[i, best]:.2f} (model mode "
                          f"{best + 1}, {model_hz[best]:.2f} Hz), below {settings.min_mac:g} or "
                          "too far in frequency")
        else:
            taken = [k for k, j in pairs.items() if ok[i, j]]
            reasons[i] = ("its candidates pair better with test mode"
                          f"{'s' if len(taken) > 1 else ''} "
                          f"{', '.join(str(k + 1) for k in sorted(taken))}")
    return pairs, grouped, reasons


def _machine(campaign: Campaign, tp: TestPose) -> MachineRecord:
    g, m = tp.geometry, campaign.scene.manipulator
    mm = lambda v: [round(float(x) * 1e3, 6) for x in v]  # noqa: E731
    return MachineRecord(
        base_joints_mm=[mm(p) for p in g.base_points],
        platform_joints_mm=[mm(p) for p in g.platform_points],
        platform_centre_mm=mm(g.platform_centre),
        platform_normal=[float(x) for x in g.rotation[:, 2]],
        platform_radius_mm=float(m.platform_radius * 1e3),
        leg_diameter_mm=float(m.leg_diameter * 1e3))


def _nodes(tp: TestPose) -> list[NodeRecord]:
    dofs = tp.modes.dofs
    out = []
    for node_id, xyz, p in zip(tp.nodes.ids, tp.nodes.xyz, tp.placements):
        mine = dofs.direction[dofs.node == node_id]
        names = sorted({("-" if d[np.argmax(np.abs(d))] < 0 else "")
                        + DIRECTIONS[int(np.argmax(np.abs(d)))] for d in mine})
        out.append(NodeRecord(id=int(node_id), xyz_mm=[float(c * 1e3) for c in xyz],
                              body=p.body, distance_mm=float(p.distance * 1e3),
                              directions=names))
    return out


def sampled(tp: TestPose, field: ModeField) -> np.ndarray:
    """(measured dofs, model modes): the model's modes where the test measured."""
    return sample(field, tp.geometry, tp.placements, tp.modes.dofs.node,
                  tp.modes.dofs.direction)


def correlate_pose(campaign: Campaign, tp: TestPose, field: ModeField) -> PoseCorrelation:
    """The correlation of one pose's test with one model's modes there."""
    model_hz = np.asarray(field.frequencies_hz, float)
    test_hz = np.asarray(tp.modes.frequencies_hz, float)
    found = scores(tp.modes.shapes, sampled(tp, field), model_hz, test_hz)
    pairs, grouped, reasons = pair(found, test_hz, model_hz, campaign.correlation)
    rows = [PairRecord(test_mode=i + 1, model_mode=j + 1, test_hz=float(test_hz[i]),
                       model_hz=float(model_hz[j]),
                       error_percent=float(100.0 * (model_hz[j] / test_hz[i] - 1.0)),
                       mac=float(match(found, grouped, i, j)), repeated=i in grouped)
            for i, j in sorted(pairs.items())]
    damping = tp.modes.damping_ratios
    return PoseCorrelation(
        name=tp.name, height_mm=float(tp.pose.height * 1e3),
        azimuth_deg=float(math.degrees(tp.pose.azimuth)),
        tilt_deg=float(math.degrees(tp.pose.tilt)), source=tp.source, data=display_path(tp.data),
        test_hz=[float(f) for f in test_hz],
        test_damping_ratio=None if damping is None else [float(z) for z in damping],
        model_hz=[float(f) for f in model_hz],
        mac=[[float(v) for v in row] for row in found.mac], pairs=rows,
        unpaired_test_modes=[UnpairedTest(test_mode=i + 1, test_hz=float(test_hz[i]),
                                          reason=why) for i, why in sorted(reasons.items())],
        unpaired_model_modes=[UnpairedModel(model_mode=j + 1, model_hz=float(model_hz[j]))
                              for j in range(len(model_hz)) if j not in pairs.values()],
        nodes=_nodes(tp), machine=_machine(campaign, tp))


def match(s: Scores, grouped: set[int], i: int, j: int) -> float:
    """How alike a pair's shapes are: the MAC, or for a pair within a repeated group the
    share in the group's subspace (its MAC with one member of an arbitrary basis says
    nothing)."""
    if i not in grouped:
        return float(s.mac[i, j])
    return float(max(s.score[i, j], s.test_subspace[i, j]))


def summary(poses: list[PoseCorrelation]) -> CorrelationSummary:
    errors = [abs(p["error_percent"]) for pose in poses for p in pose["pairs"]]
    macs = [p["mac"] for pose in poses for p in pose["pairs"]]
    return CorrelationSummary(
        pairs=len(errors),
        unpaired_test_modes=sum(len(p["unpaired_test_modes"]) for p in poses),
        mean_abs_error_percent=float(np.mean(errors)) if errors else None,
        max_abs_error_percent=float(np.max(errors)) if errors else None,
        min_mac=float(np.min(macs)) if macs else None)


def pairing_record(settings: CorrelationSettings) -> PairingRecord:
    return PairingRecord(min_mac=settings.min_mac,
                         max_frequency_ratio=1.0 + settings.max_frequency_deviation_percent / 100,
                         rule=RULE)


def correlation(campaign: Campaign, poses: list[PoseCorrelation], model: ModelRecord,
                seconds: float) -> Correlation:
    return Correlation(record="correlation", schema=SCHEMA, campaign=display_path(campaign.path),
                       scene=display_path(campaign.scene_path), model=model,
                       pairing=pairing_record(campaign.correlation), poses=poses,
                       summary=summary(poses), seconds=seconds)
