"""Input uncertainty through the fast model: the scene's [uncertainty] (scene.uncertainty)
sampled on Saltelli's design (solvers.sensitivity), every sample a machine
(`scene.address`), all of them solved as one batch at a pose (analytical.sample_batch), and
the statistics of every output: the frequencies of the lowest modes (mode k: the k-th lowest
frequency of each sample) and, where the scene has [tool] or [damping], the least dynamic
stiffness at the tool along x, y and z (common.frf, as `rps frf` and the workspace's map).

Everything the samples need is checked before the first solve: each sample's machine is built
(its dataclass checks), its pose geometry computed and its reach checked; a sample refused
there is named in one line (InputError), and nothing has been solved.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from analytical.params import Manipulator, ModelOptions, Pose
from common.errors import InputError
from common.frf import DIRECTIONS, LINES
from results.uncertainty_records import (
    FrequencyStatistics,
    StiffnessStatistics,
    UncertaintyRecord,
)

from .sensitivity import Statistics, design, statistics

CHUNK = 256  # samples assembled and solved together (K and M of 256 x 135 coordinates: 75 MB)
PATH_SAMPLES = 512  # plain draws per pose of a workspace path (the 95 % band only)


@dataclass(frozen=True)
class Sampled:
    """The model's outputs at every row of a design: frequencies (n, modes), Hz, and the
    least dynamic stiffness (n, 3), N/m, or None."""

    frequencies_hz: np.ndarray
    least_n_per_m: np.ndarray | None
    seconds: float


def machines(scene, unit) -> list[Manipulator]:
    """The machine of every row of unit values (n, d) of the scene's inputs."""
    from scene.address import applied

    moved = scene.uncertainty.values(unit)
    out = []
    for k in range(len(unit)):
        try:
            m = applied(scene.manipulator, {a: float(v[k]) for a, v in moved})
        except ValueError as exc:
            shown = ", ".join(f"{a.name} = {v[k]:.6g}" for a, v in moved)
            raise InputError(f"uncertainty sample {k + 1} ({shown}): the machine is refused: "
                             f"{exc}") from None
        out.append(m)
    return out


@dataclass(frozen=True)
class Prepared:
    """Every sample's machine and pose, checked: what the solves need."""

    machines: list
    poses: object  # analytical.pose_batch.PoseBatch

    def __len__(self) -> int:
        return len(self.machines)

    def take(self, part: slice) -> "Prepared":
        return Prepared(self.machines[part],
                        self.poses.take(np.arange(len(self.machines))[part]))  # type: ignore


def prepare(scene, pose: Pose, unit) -> Prepared:
    """Each row's machine and its pose, every check done (module docstring)."""
    from analytical.sample_batch import SampleOutOfReach, same_geometry, sample_poses

    built = machines(scene, unit)
    try:
        poses = sample_poses(built, pose, same_geometry(scene.uncertainty.tables))
    except SampleOutOfReach as exc:
        raise InputError(f"uncertainty: {exc} (height {pose.height * 1e3:g} mm, azimuth "
                         f"{math.degrees(pose.azimuth):g} deg, tilt {math.degrees(pose.tilt):g} "
                         "deg): narrow the inputs that move the machine's dimensions") from None
    return Prepared(built, poses)


def solve_prepared(scene, options: ModelOptions, prepared: Prepared, modes: int,
                   tool: bool) -> Sampled:
    """The outputs of prepared samples, solved CHUNK at a time."""
    start = time.perf_counter()
    n = len(prepared)
    freq = np.empty((n, modes))
    least = np.empty((n, 3)) if tool else None
    for first in range(0, n, CHUNK):
        part = slice(first, min(n, first + CHUNK))
        chunk = prepared.take(part)
        f, s = _solve(scene, options, chunk.machines, chunk.poses, modes, tool)
        freq[part] = f
        if least is not None:
            least[part] = s
    return Sampled(freq, least, time.perf_counter() - start)


def sample_model(scene, options: ModelOptions, pose: Pose, unit, modes: int,
                 tool: bool) -> Sampled:
    """The model's outputs at every row of `unit` (module docstring): machines and poses first
    (every check), then the solves in chunks."""
    return solve_prepared(scene, options, prepare(scene, pose, unit), modes, tool)


def estimate_seconds(scene, options: ModelOptions, pose: Pose, unit, modes: int,
                     tool: bool, pilot: int = 16) -> float:
    """The time every row of `unit` would take (machines, checks and solves), from a pilot of
    its first rows: measured before the rest is built, so a design too large for its budget
    is refused before it holds any memory."""
    start = time.perf_counter()
    head = unit[:pilot]
    solve_prepared(scene, options, prepare(scene, pose, head), modes, tool)
    return (time.perf_counter() - start) / len(head) * len(unit)


def tool_modes(scene, options: ModelOptions, prepared: Prepared, count: int):
    """The tool modes (analytical.tool_response.ToolModes, a leading axis per sample; base
    frame) of prepared samples: `count` modes at the scene's tool point, one batch."""
    from analytical.tool_response import batch_tool_modes

    poses: Any = prepared.poses  # analytical.pose_batch.PoseBatch
    model, form, reduced = _assembled(scene, options, prepared.machines, poses)
    return batch_tool_modes(model, form, poses.rotation, scene.tool.point,
                            min(count, reduced.coordinates[1]))


def _assembled(scene, options, built, poses):
    """(model, its standard form, the nominal machine's leg reduction) of sampled machines."""
    from analytical.batch_model import leg_reduction
    from analytical.batch_solve import standard_form
    from analytical.sample_batch import assemble_samples

    reduced = leg_reduction(scene.manipulator, options)  # the nominal machine's, every sample
    model = assemble_samples(built, poses, options, reduced.modes)
    return model, standard_form(model), reduced


def _solve(scene, options, built, poses, modes: int, tool: bool):
    from analytical.batch_model import leg_reduction
    from analytical.batch_solve import frequencies
    from analytical.sample_batch import assemble_samples
    from analytical.tool_response import SUPERPOSED_EXTRA, batch_tool_modes
    from common.frf import (
        band_lines,
        least_dynamic_stiffness,
        residual_flexibility,
        summed_band_top,
    )

    if not tool:
        reduced = leg_reduction(scene.manipulator, options)
        return frequencies(assemble_samples(built, poses, options, reduced.modes), modes), None
    model, form, reduced = _assembled(scene, options, built, poses)
    count = min(modes + SUPERPOSED_EXTRA, reduced.coordinates[1])
    found = batch_tool_modes(model, form, poses.rotation, scene.tool.point, count)
    residual = residual_flexibility(found.static, found.omega, found.phi)
    band = band_lines(summed_band_top(found.omega, modes, found.next_omega, scene.damping),
                      LINES)
    least = least_dynamic_stiffness(band, found.omega, scene.damping.ratios(found.omega),
                                    found.phi, np.diagonal(residual, axis1=1, axis2=2))
    return found.omega[:, :modes] / (2.0 * math.pi), least.stiffness_n_per_m


def nominal(scene, options: ModelOptions, pose: Pose, modes: int, tool: bool) -> Sampled:
    """The outputs at the scene's own values (every input at its scene value)."""
    from analytical.sample_batch import sample_poses

    poses = sample_poses([scene.manipulator], pose, True)
    start = time.perf_counter()
    f, s = _solve(scene, options, [scene.manipulator], poses, modes, tool)
    return Sampled(f, s, time.perf_counter() - start)


def _entry(stats: Statistics, names: list[str], unit: str) -> dict[str, Any]:
    """The statistics of one output under its unit's field names (FrequencyStatistics or
    StiffnessStatistics, less the nominal value)."""
    def keyed(values) -> dict[str, float | None]:
        return dict(zip(names, values))

    return {f"mean_{unit}": stats.mean, f"std_{unit}": stats.std, f"q025_{unit}": stats.q025,
            f"q975_{unit}": stats.q975, f"mean_error_{unit}": stats.mean_error,
            f"std_error_{unit}": stats.std_error, f"q025_error_{unit}": stats.q025_error,
            f"q975_error_{unit}": stats.q975_error,
            "cv_percent": 100.0 * stats.std / stats.mean if stats.mean else None,
            "sobol_first": keyed(stats.sobol_first),
            "sobol_first_error": keyed(stats.sobol_first_error),
            "sobol_total": keyed(stats.sobol_total),
            "sobol_total_error": keyed(stats.sobol_total_error)}


def refusal(scene, options: ModelOptions) -> str | None:
    """Why the scene's inputs cannot be propagated through the model `options`, or None: with
    solid joint ends or solid legs every sample that moves the material or a dimension would
    need its own solid FEM (an end zone, a leg part)."""
    if options.joint_ends != "solid" and options.legs != "solid":
        return None
    moved = sorted(scene.uncertainty.tables - {"stiffness", "payload"})
    if not moved:
        return None
    return (f"uncertain [{moved[0]}] keys with the model {options.describe()!r}: every sample "
            "would need its own solid end zone or leg part (a solid FEM each); propagate "
            "through a beam model ([analytical] joint_ends = \"beam\", legs = \"beam\")")


def run_model(scene, options: ModelOptions) -> ModelOptions:
    """The model a run propagates through: its chosen one, or, where that one cannot
    (`refusal`: solid joint ends or legs with uncertain material or dimensions), the same
    settings with beam joint ends and beam legs. The spread of a frequency over the inputs is
    a relative quantity the two share closely; the model's own error against the FEM stays the
    chosen model's. The record names the model it propagated through."""
    from dataclasses import replace

    if refusal(scene, options) is None:
        return options
    return replace(options, joint_ends="beam", legs="beam")


class OverBudget(InputError):
    """The propagation would take longer than it may."""


def propagate(scene, options: ModelOptions, pose: Pose, modes: int,
              budget_seconds: float | None = None, samples: int | None = None
              ) -> UncertaintyRecord:
    """The uncertainty of one pose: every statistic of every output (module docstring), as the
    record `rps uncertainty` writes (uncertainty.json) and the run's case study keeps. Every
    sample is checked first; with `budget_seconds`, a pilot solve estimates the whole and
    OverBudget refuses what would take longer, before the rest is solved."""
    u = scene.uncertainty
    n, d, seed = samples or u.settings.samples, len(u.inputs), u.settings.seed
    tool = bool(scene.dynamics_given)
    unit = design(d, n, seed)
    if budget_seconds is not None:
        estimate = estimate_seconds(scene, options, pose, unit, modes, tool)
        if estimate > budget_seconds:
            raise OverBudget(f"{len(unit):,} model runs ({n} samples x {d + 2}) would take "
                             f"about {estimate:.0f} s (a pilot's {1e3 * estimate / len(unit):.2g}"
                             f" ms a run), above the {budget_seconds:g} s allowed: fewer "
                             "samples")
    sampled = solve_prepared(scene, options, prepare(scene, pose, unit), modes, tool)
    at_scene = nominal(scene, options, pose, modes, tool)
    start = time.perf_counter()
    names = u.names
    out_modes: list[FrequencyStatistics] = []
    for k in range(modes):
        entry = _entry(statistics(sampled.frequencies_hz[:, k], n, d, seed), names, "hz")
        out_modes.append(cast(FrequencyStatistics, {
            "mode": k + 1, "nominal_hz": float(at_scene.frequencies_hz[0, k]), **entry}))
    least: dict[str, StiffnessStatistics] | None = None
    if sampled.least_n_per_m is not None and at_scene.least_n_per_m is not None:
        least = {name: cast(StiffnessStatistics, {
            "nominal_n_per_m": float(at_scene.least_n_per_m[0, j]),
            **_entry(statistics(sampled.least_n_per_m[:, j], n, d, seed), names, "n_per_m")})
                 for j, name in enumerate(DIRECTIONS)}
    return {"inputs": [{"key": i.name, "distribution": i.spec.distribution,
                        "described": i.describe(), "unit": i.address.unit,
                        "nominal": i.nominal, "support": list(i.support),
                        "followers": [a.name for a, _ in i.followers],
                        "source": i.spec.source} for i in u.inputs],
            "design": f"Saltelli's scheme on a scrambled Sobol' sequence (SALib), N = {n} base "
                      f"points, {d} inputs, {len(unit)} model runs, seed {seed}",
            "samples": n, "runs": len(unit), "model": options.describe(),
            "modes": out_modes, "least_dynamic_stiffness": least,
            "model_seconds": sampled.seconds,
            "statistics_seconds": time.perf_counter() - start}


def draws(scene, samples: int = PATH_SAMPLES) -> np.ndarray:
    """Plain scrambled Sobol' draws (samples, d) of the scene's inputs' unit values."""
    from scipy.stats import qmc

    u = scene.uncertainty
    return qmc.Sobol(len(u.inputs), scramble=True, seed=u.settings.seed).random(samples)


def spread_percent(scene, options: ModelOptions, pose: Pose, modes: int,
                   samples: int = PATH_SAMPLES) -> np.ndarray:
    """(modes,) the standard deviation over mean of each of the lowest frequencies (the k-th
    lowest of each sample) at `pose`, %, from plain draws (u_input of solvers.vv20)."""
    f = sample_model(scene, options, pose, draws(scene, samples), modes, False).frequencies_hz
    return 100.0 * f.std(axis=0, ddof=1) / f.mean(axis=0)


def band(scene, options: ModelOptions, poses, modes: int, samples: int = PATH_SAMPLES,
         budget_seconds: float | None = None) -> list[dict]:
    """At each pose of `poses` (Pose list), the 2.5 / 50 / 97.5 % quantiles of f1 and, where
    the scene asks for the dynamic compliance, of the least dynamic stiffness at the tool (the
    least over x, y and z of each sample), from plain scrambled Sobol' draws of the inputs;
    {"refused": why} at a pose some sample cannot reach. Every pose's samples are checked
    first; with `budget_seconds`, a pilot estimates the whole and OverBudget refuses what would
    take longer."""
    unit = draws(scene, samples)
    tool = bool(scene.dynamics_given)
    prepared: list[Prepared | str] = []
    for pose in poses:
        try:
            prepared.append(prepare(scene, pose, unit))
        except InputError as exc:  # this pose's refusal, the others' bands still drawn
            prepared.append(str(exc))
    ready_ones = [p for p in prepared if isinstance(p, Prepared)]
    if budget_seconds is not None and ready_ones:
        estimate = estimate_seconds(scene, options, poses[prepared.index(ready_ones[0])], unit,
                                    modes, tool) * len(ready_ones)
        if estimate > budget_seconds:
            raise OverBudget(f"{len(ready_ones)} poses x {samples} samples would take about "
                             f"{estimate:.0f} s, above the {budget_seconds:g} s allowed")
    out: list[dict] = []
    for ready in prepared:
        if isinstance(ready, str):
            out.append({"refused": ready})
            continue
        sampled = solve_prepared(scene, options, ready, modes, tool)
        row: dict = {"f1_hz": np.quantile(sampled.frequencies_hz[:, 0],
                                          (0.025, 0.5, 0.975)).tolist()}
        if sampled.least_n_per_m is not None:
            row["least_n_per_m"] = np.quantile(sampled.least_n_per_m.min(axis=1),
                                               (0.025, 0.5, 0.975)).tolist()
        out.append(row)
    return out
