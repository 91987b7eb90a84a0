"""Case study: the scene's input uncertainty ([uncertainty]) through the run's analytical model
at the case's pose (solvers/uncertainty.py: Saltelli's design, Sobol' indices, every
statistic with its sampling error), and the V&V 20 table of the model against the FEM
(results.cases[].uncertainty).

The V&V 20 table (solvers/vv20.py): per FEM mode paired by shape, E the model's error
against the FEM (%), u_num the FEM's stated error as a standard uncertainty, u_input the
model's frequency standard deviation over the inputs, no u_D, and the verdict.
"""
from __future__ import annotations

import time
from typing import Any, Mapping, cast

from typing_extensions import TypedDict

import results
from common.frf import DIRECTIONS
from results import Section, Table
from results.uncertainty_records import UncertaintyRecord
from solvers import vv20

from .registry import CaseContext, Context, Study, own

BUDGET_SECONDS = 300.0  # a case's propagation in a run; beyond, refused in the record


def validation_rows(pairs: list, modes: list) -> list[results.ValidationRow]:
    """V&V 20 rows from the comparison's pairs (results.Pair) and the model's mode statistics
    (the uncertainty record's `modes`, by analytical mode); no u_D against the FEM."""
    rows = []
    for p in pairs:
        j = p["analytical_mode"] - 1
        if j >= len(modes):
            continue
        u_num = vv20.from_bound(p["fem_estimated_error_percent"])
        u_input = modes[j]["cv_percent"]
        u_val = vv20.u_val(u_num, u_input, None)
        rows.append(results.ValidationRow(
            fem_mode=p["fem_mode"], analytical_mode=p["analytical_mode"],
            e_percent=p["error_percent"], u_num_percent=u_num, u_input_percent=u_input,
            u_d_percent=None, u_val_percent=u_val,
            verdict=vv20.verdict(p["error_percent"], u_num, u_val)))
    return rows


def case_uncertainty(scene, case, cache) -> UncertaintyRecord | Refused:
    """The propagation's record (solvers.uncertainty.propagate) at the case, through the
    result cache; {"refused": why} where it cannot run (the model, the budget, a sample out of
    reach): written in the record, never fatal, and a refusal is not cached (the budget's
    pilot depends on the machine's load)."""
    from importlib.metadata import version

    from common.errors import InputError
    from common.settings import as_dict
    from solvers.uncertainty import propagate, run_model

    options = run_model(scene, scene.analytical)
    payload = {"manipulator": as_dict(scene.manipulator), "pose": as_dict(case.pose),
               "analytical": as_dict(options), "uncertainty": scene.raw["uncertainty"],
               "damping": as_dict(scene.damping), "tool": as_dict(scene.tool),
               "dynamics": bool(scene.dynamics_given), "modes": scene.fidelity.modes,
               "budget": BUDGET_SECONDS, "salib": version("SALib")}

    def compute():
        return propagate(scene, options, case.pose, scene.fidelity.modes,
                         budget_seconds=BUDGET_SECONDS), {}

    try:
        value, _, _ = cache.get_or_compute(
            "uncertainty", payload, compute,
            modules=("solvers.uncertainty", "solvers.sensitivity", "analytical.sample_batch",
                     "analytical.batch_model", "scene.uncertainty", "scene.address"))
    except InputError as exc:  # OverBudget, a sample out of reach or refused as a machine
        return Refused(refused=str(exc))
    return cast(UncertaintyRecord, value)  # the cache returns what `propagate` stored


MODE_KEYS = tuple(results.UncertaintyMode.__annotations__)  # its record's fields


class Refused(TypedDict):
    """Why a pose's propagation did not run (written in the record, never fatal)."""
    refused: str


def _sobol(output: str, entry: Mapping[str, Any]) -> list[results.SobolRow]:
    return [results.SobolRow(output=output, key=key, first=entry["sobol_first"][key],
                             first_error=entry["sobol_first_error"][key],
                             total=entry["sobol_total"][key],
                             total_error=entry["sobol_total_error"][key])
            for key in entry["sobol_first"]]


def run(ctx: Context, cc: CaseContext) -> results.UncertaintyCase | None:
    from solvers.compare import analytical_case, error_table

    scene = ctx.scene
    if scene.uncertainty is None:
        return None
    cc.step("input uncertainty through the analytical model")
    start = time.perf_counter()
    record = case_uncertainty(scene, cc.case, ctx.cache)
    inputs = [results.UncertainInputRecord(
        key=i.name, distribution=i.spec.distribution, described=i.describe(),
        unit=i.address.unit, nominal=i.nominal, support=list(i.support),
        followers=[a.name for a, _ in i.followers], source=i.spec.source.strip())
        for i in scene.uncertainty.inputs]
    if "modes" not in record:  # refused
        return results.UncertaintyCase(
            inputs=inputs, design="", model=scene.analytical.describe(), runs=0,
            refused=cast(Refused, record)["refused"], modes=[], least=[], sobol=[],
            validation=[], seconds=time.perf_counter() - start)
    record = cast(UncertaintyRecord, record)
    rows: list[Mapping[str, Any]] = list(record["modes"])
    modes = [cast(results.UncertaintyMode, {k: m[k] for k in MODE_KEYS}) for m in rows]
    sobol = [row for m in record["modes"] for row in _sobol(f"f{m['mode']}", m)]
    least = []
    stiffness = record["least_dynamic_stiffness"] or {}
    for d in DIRECTIONS if stiffness else ():
        s = stiffness[d]
        least.append(results.UncertaintyStiffness(
            direction=d, nominal_n_per_m=s["nominal_n_per_m"], mean_n_per_m=s["mean_n_per_m"],
            mean_error_n_per_m=s["mean_error_n_per_m"], std_n_per_m=s["std_n_per_m"],
            cv_percent=cast(float, s["cv_percent"]),  # a stiffness's mean is positive
            q025_n_per_m=s["q025_n_per_m"],
            q975_n_per_m=s["q975_n_per_m"]))
        sobol += _sobol(f"least {d}", s)
    a = analytical_case(scene, cc.case, scene.analytical)
    pairs = error_table(a, cc.fem, scene.fidelity.modes, cc.fem_error, cc.reference)
    return results.UncertaintyCase(
        inputs=inputs, design=record["design"], model=record["model"], runs=record["runs"],
        refused=None, modes=modes, least=least, sobol=sobol,
        validation=validation_rows(pairs, modes),
        seconds=record["model_seconds"] + record["statistics_seconds"])


STUDY = Study(own(
    "uncertainty", "case",
    section=Section("uncertainty", "Input uncertainty: spread, Sobol' indices, V&V 20",
                    None, asks="[uncertainty]"),
    tables=(Table("validation", ("fem_mode", "analytical_mode", "e_percent", "u_num_percent",
                                 "u_input_percent", "u_val_percent", "verdict"),
                  each="validation"),
            Table("frequencies", ("mode", "nominal_hz", "mean_hz", "std_hz", "cv_percent",
                                  "q025_hz", "q975_hz", "mean_error_hz", "q025_error_hz",
                                  "q975_error_hz"), each="modes"),
            Table("sobol", ("output", "key", "first", "first_error", "total", "total_error"),
                  each="sobol"),
            Table("least_stiffness", ("direction", "nominal_n_per_m", "mean_n_per_m", "std_n_per_m",
                                      "cv_percent", "q025_n_per_m", "q975_n_per_m"),
                  each="least"),
            Table("inputs", ("key", "described", "source"), each="inputs"))),
    "case", run)
