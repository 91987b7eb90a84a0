"""A campaign's correlation and identification, end to end, and what they write: the JSON
record, its CSV tables and its page (`rps correlate`, `rps identify`)."""
from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from analytical.params import ModelOptions
from common.atomic import write_text_atomic
from common.errors import ComputeError
from common.paths import display_path
from results.campaign_records import SCHEMA, Correlation, Identification, ModelRecord
from results.outputs import CORRELATION, IDENTIFICATION
from scene.address import edited_text
from scene.load import SceneError

from . import identify as ident
from .campaign import Campaign
from .correlate import correlate_pose, correlation
from .models import AnalyticalField, analytical_field, fem_field
from .validation import validation as validate


def model_record(kind: str, options: ModelOptions, source: str) -> ModelRecord:
    if kind == "fem":
        return ModelRecord(kind="fem", description="the scene's 3D solid FEM at its default "
                           "mesh size")
    return ModelRecord(kind="analytical", description=(
        f"substructure model: {options.beam} beams ({options.shear} shear), s = "
        f"{options.elements}, joint ends {options.joint_ends}, legs {options.legs}; {source}"))


def solved_modes(campaign: Campaign) -> list[int]:
    """The model modes solved at each pose: the test's count and the extra ones."""
    return [len(tp.modes.frequencies_hz) + campaign.correlation.extra_model_modes
            for tp in campaign.poses]


def analytical_fields(campaign: Campaign, options: ModelOptions) -> list[AnalyticalField]:
    return [analytical_field(campaign.scene.manipulator, tp.pose, tp.geometry, options, n)
            for tp, n in zip(campaign.poses, solved_modes(campaign))]


def run_correlation(campaign: Campaign, options: ModelOptions, source: str,
                    model: str = "analytical", cache=None) -> Correlation:
    """Every pose's correlation with the analytical model (or the FEM)."""
    start = time.perf_counter()
    fields = (analytical_fields(campaign, options) if model == "analytical" else
              [fem_field(campaign.scene, tp.geometry, n, cache)
               for tp, n in zip(campaign.poses, solved_modes(campaign))])
    poses = [correlate_pose(campaign, tp, f) for tp, f in zip(campaign.poses, fields)]
    return correlation(campaign, poses, model_record(model, options, source),
                       time.perf_counter() - start)


def run_identification(campaign: Campaign, options: ModelOptions, source: str,
                       frequency_uncertainty_percent: Mapping[str, Sequence[float]] | None = None
                       ) -> tuple[Identification, str]:
    """The fit of the campaign's [identify] keys; the record and the identified scene's
    text (the scene file with the identified values, every comment kept).
    `frequency_uncertainty_percent`: per pose name, the standard uncertainty of each of its test
    modes' frequencies (in the file's order, %) that the modes' own identification states (e.g.
    from FRFs: errors fixed per mode, which a fresh test of the same FRFs repeats); combined
    into the noise (`identify.noise`). None: the poses' own, where their modes come from FRFs
    (each mode's scatter over the stabilisation chart's stable orders, `TestPose`)."""
    if frequency_uncertainty_percent is None:
        frequency_uncertainty_percent = {
            tp.name: [100.0 * float(u) for u in tp.frequency_uncertainty]
            for tp in campaign.poses if tp.frequency_uncertainty is not None} or None
    start = time.perf_counter()
    problem = ident.Problem(campaign, options, solved_modes(campaign))
    x0 = np.log([p.start for p in campaign.parameters])
    at_scene = [correlate_pose(campaign, tp, f)
                for tp, f in zip(campaign.poses, problem.fields(None))]
    problem.fitted = _paired(at_scene)
    if not problem.fitted:  # a rigid spring's scene may pair nothing: try the start
        problem.fitted = _paired([correlate_pose(campaign, tp, f) for tp, f in
                                  zip(campaign.poses, problem.fields(x0))])
    if not problem.fitted:
        raise ComputeError("identification: no test mode pairs with a model mode at the "
                           "scene's values (see `rps correlate`); nothing to fit")
    before = _residuals_at_scene(problem)
    fit = ident.fit(problem, x0, before)
    after = [correlate_pose(campaign, tp, f)
             for tp, f in zip(campaign.poses, problem.fields(fit.x))]
    more = sorted(set(_paired(after)) - set(problem.fitted))
    if more:  # modes that pair only near the answer: fitted too, once, from there
        problem.fitted = sorted(set(problem.fitted) | set(more))
        fit = ident.fit(problem, fit.x, _residuals_at_scene(problem))
        after = [correlate_pose(campaign, tp, f)
                 for tp, f in zip(campaign.poses, problem.fields(fit.x))]
    extraction = _extraction(campaign, problem.fitted, frequency_uncertainty_percent)
    fit, found = ident.settled(problem, fit, extraction)
    records, noise, singular, corr = (found.parameters, found.noise, found.singular_values,
                                      found.correlation)
    after_fields = problem.fields(fit.x)
    _, likeness = problem.partners(after_fields)
    macs = dict(zip(problem.fitted, likeness))
    values = {p.address: math.exp(x) for p, x in zip(campaign.parameters, fit.x)}
    text = Path(campaign.scene_path).read_text(encoding="utf-8")
    notes = {p.address: (f"identified from {Path(campaign.path).name}: 95 % "
                         f"[{r['ci95'][0]:.4g}, {r['ci95'][1]:.4g}]" if r["identifiable"] else
                         f"NOT IDENTIFIABLE from {Path(campaign.path).name}, fitted jointly "
                         f"with the other keys: {r['reason']}")
             for p, r in zip(campaign.parameters, records)}
    identified = edited_text(text, values, notes)
    try:  # the identified machine as a whole (plausibility: parse_scene's checks)
        scene = campaign.scene_with(values)
        check = "accepted" + "".join(f"; warning: {w}" for w in scene.warnings)
    except SceneError as exc:
        check = f"refused: {exc}"
    model = model_record("analytical", options, source)
    fitted = ident.fit_table(problem, fit, after_fields, macs)
    validation, validation_note = validate(campaign, options, at_scene, fitted, noise)
    seconds = time.perf_counter() - start
    record = Identification(
        record="identification", schema=SCHEMA, campaign=display_path(campaign.path),
        scene=display_path(campaign.scene_path),
        identified_scene="identified.toml", identified_scene_check=check, model=model,
        parameters=records,
        residual_rms_percent_before=ident.rms_percent(fit.residuals_before),
        residual_rms_percent_after=ident.rms_percent(fit.residuals_after), noise=noise,
        singular_values=singular, parameter_correlation=corr,
        fit=fitted, evaluations=fit.evaluations,
        seconds=seconds, optimiser=(
            f"scipy least_squares (trf, bounded, log space): {fit.message}"
            + ("" if fit.converged else " (NOT converged: the keys are not to be trusted)")
            + f"; {problem.partner_changes} changes of a fitted mode's partner"
            + (f"; {len(more)} test modes paired only near the answer, fitted from there"
               if more else "") + (f"; {found.note}" if found.note else "")),
        correlation_after=correlation(campaign, after, model, seconds),
        validation=validation, validation_note=validation_note)
    return record, identified


def _extraction(campaign: Campaign, fitted: list[tuple[int, int]],
                uncertainty: Mapping[str, Sequence[float]] | None) -> np.ndarray | None:
    """The fitted modes' stated frequency uncertainties (fractions; 0 for a mode without one),
    None without any."""
    if not uncertainty:
        return None
    out = []
    for pose, i in fitted:
        tp = campaign.poses[pose]
        values = uncertainty.get(tp.name)
        if values is not None and len(values) != len(tp.modes.frequencies_hz):
            raise ComputeError(f"identification: pose {tp.name}: {len(values)} frequency "
                               f"uncertainties for {len(tp.modes.frequencies_hz)} test modes")
        u = 0.0 if values is None else float(values[i])
        if not (math.isfinite(u) and u >= 0.0):
            raise ComputeError(f"identification: pose {tp.name} mode {i + 1}: frequency "
                               f"uncertainty {u!r} %; a standard uncertainty is finite, >= 0")
        out.append(u / 100.0)
    return np.array(out)


def _paired(poses: list) -> list[tuple[int, int]]:
    """(pose, test mode) of every pair, 0-based."""
    return [(k, p["test_mode"] - 1) for k, pose in enumerate(poses) for p in pose["pairs"]]


def _residuals_at_scene(problem: ident.Problem) -> np.ndarray:
    """The fitted modes' residuals at the scene's own values (a rigid spring included),
    each with the partner the pairing gives there; the fit's own partners are left as
    they were."""
    kept = dict(problem.previous), problem.partner_changes
    out = problem.residuals(None)
    problem.previous, problem.partner_changes = kept
    return out


def write_correlation(data: Correlation, directory: Path) -> Path:
    """correlation.json and its declared tables (tables/correlation-*.csv), checked against
    results.outputs.CORRELATION (the page is the report room's, `reports.campaign_pages`)."""
    return CORRELATION.write(directory, data)


def write_identification(data: Identification, identified: str, directory: Path) -> Path:
    """identification.json and its declared tables (tables/identification-*.csv), checked
    against results.outputs.IDENTIFICATION, and identified.toml."""
    write_text_atomic(directory / "identified.toml", identified)
    return IDENTIFICATION.write(directory, data)
