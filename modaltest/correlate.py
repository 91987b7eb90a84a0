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
(`solvers.pairing.group_scores`), not its MAC with one arbitrary member; and a test's own
near-repeated pair (two modes within 2 %, whose measured shapes mix as the model's would)
scores a model shape by its share in the pair's subspace. Within a group, frequency orders.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import linear_sum_assignment

from common.modes import clusters, mac_matrix
from results.campaign_records import (
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
        "mode per test mode; against a repeated model group the test shape's share in its "
        "subspace stands for the MAC")
DIRECTIONS = ("x", "y", "z")


def scores(test_shapes: np.ndarray, model_shapes: np.ndarray, model_hz: np.ndarray,
           test_hz: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, set[int]]:
    """(MAC, score, repeated model modes): MAC (test, model), the score with groups of
    (near-)repeated modes taken as subspaces (the model's; with `test_hz` the test's too: a
    model shape's share in a test pair's subspace), and which model modes are in such a
    group."""
    mac = mac_matrix(test_shapes, model_shapes)
    groups = clusters(np.asarray(model_hz, float), REPEAT_TOLERANCE)
    score = group_scores(test_shapes, model_shapes, mac, groups)
    if test_hz is not None:  # and a test's own near-repeated pair, seen from the model
        test_groups = clusters(np.asarray(test_hz, float), REPEAT_TOLERANCE)
        score = np.maximum(score, group_scores(model_shapes, test_shapes, mac.T,
                                               test_groups).T)
    repeated = {j for g in groups if len(g) > 1 for j in g}
    return mac, score, repeated


def _in_order(pairs: dict[int, int], test_hz: np.ndarray,
              model_hz: np.ndarray) -> dict[int, int]:
    """The pairs with, inside every group of near-repeated test modes and of near-repeated
    model modes, the partners in ascending order of frequency (a group's members are one
    subspace: which member pairs with which is the frequency's to say)."""
    out = dict(pairs)
    for hz, groups in ((test_hz, clusters(test_hz, REPEAT_TOLERANCE)),
                       (model_hz, clusters(model_hz, REPEAT_TOLERANCE))):
        for group in groups:
            if len(group) < 2:
                continue
            if hz is test_hz:
                members = [i for i in group if i in out]
                partners = sorted(out[i] for i in members)
            else:
                members = sorted(i for i, j in out.items() if j in group)
                partners = sorted(out[i] for i in members)
            for i, j in zip(sorted(members, key=lambda k: test_hz[k]),
                            sorted(partners, key=lambda k: model_hz[k])):
                out[i] = j
    return out


def pair(score: np.ndarray, test_hz: np.ndarray, model_hz: np.ndarray,
         settings: CorrelationSettings) -> tuple[dict[int, int], dict[int, str]]:
    """({test mode: model mode}, {unpaired test mode: reason}), 0-based."""
    test_hz = np.asarray(test_hz, float)
    model_hz = np.asarray(model_hz, float)
    ratio = np.log(model_hz[None, :] / test_hz[:, None])
    limit = settings.max_frequency_deviation_percent / 100.0
    near = np.abs(model_hz[None, :] / test_hz[:, None] - 1.0) <= limit
    ok = (score >= settings.min_mac) & near
    cost = np.where(ok, -(score - np.abs(ratio)), 1e6)
    rows, cols = linear_sum_assignment(cost)
    pairs = _in_order({int(i): int(j) for i, j in zip(rows, cols) if ok[i, j]}, test_hz,
                      model_hz)
    reasons: dict[int, str] = {}
    for i in range(len(test_hz)):
        if i in pairs:
            continue
        best = int(np.argmax(score[i]))
        if not near[i].any():
            j = int(np.argmin(np.abs(ratio[i])))
            reasons[i] = (f"no model mode within {settings.max_frequency_deviation_percent:g} % "
                          f"(nearest: model mode {j + 1} at {model_hz[j]:.2f} Hz)")
        elif not ok[i].any():
            reasons[i] = (f"no admissible shape: best MAC {score[i, best]:.2f} (model mode "
                          f"{best + 1}, {model_hz[best]:.2f} Hz), below {settings.min_mac:g} or "
                          "too far in frequency")
        else:
            taken = [k for k, j in pairs.items() if ok[i, j]]
            reasons[i] = ("its candidates pair better with test mode"
                          f"{'s' if len(taken) > 1 else ''} "
                          f"{', '.join(str(k + 1) for k in sorted(taken))}")
    return pairs, reasons


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
    mac, score, repeated = scores(tp.modes.shapes, sampled(tp, field), model_hz, test_hz)
    pairs, reasons = pair(score, test_hz, model_hz, campaign.correlation)
    rows = [PairRecord(test_mode=i + 1, model_mode=j + 1, test_hz=float(test_hz[i]),
                       model_hz=float(model_hz[j]),
                       error_percent=float(100.0 * (model_hz[j] / test_hz[i] - 1.0)),
                       mac=float(score[i, j]), repeated=j in repeated)
            for i, j in sorted(pairs.items())]
    damping = tp.modes.damping_ratios
    return PoseCorrelation(
        name=tp.name, height_mm=float(tp.pose.height * 1e3),
        azimuth_deg=float(math.degrees(tp.pose.azimuth)),
        tilt_deg=float(math.degrees(tp.pose.tilt)), source=tp.source, data=tp.data,
        test_hz=[float(f) for f in test_hz],
        test_damping_ratio=None if damping is None else [float(z) for z in damping],
        model_hz=[float(f) for f in model_hz],
        mac=[[float(v) for v in row] for row in mac], pairs=rows,
        unpaired_test_modes=[UnpairedTest(test_mode=i + 1, test_hz=float(test_hz[i]),
                                          reason=why) for i, why in sorted(reasons.items())],
        unpaired_model_modes=[UnpairedModel(model_mode=j + 1, model_hz=float(model_hz[j]))
                              for j in range(len(model_hz)) if j not in pairs.values()],
        nodes=_nodes(tp), machine=_machine(campaign, tp))


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
    return Correlation(schema=1, campaign=campaign.path, scene=campaign.scene_path, model=model,
                       pairing=pairing_record(campaign.correlation), poses=poses,
                       summary=summary(poses), seconds=seconds)
