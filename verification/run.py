"""Run one benchmark at its sizes and build its record (a plain JSON-ready dict); run all.

Per reference mode, over the sizes coarse -> fine: the frequencies, the signed deviation of the
finest from the reference, and the project's own discretisation-error estimates at the finest
size (`fem_reference.convergence`): Richardson's relative error and the GCI, the stated error
being the larger (as for every FEM result of the project). Both are computed on the EFFECTIVE
sizes of the meshes ((V / nodes)^(1/3) in 3D, (A / nodes)^(1/2) on a meridian, as the project's
refinement studies do); `mesh_sizes_mm` reports the nominal ones. The observed order is Celik's from
the three sizes, uncapped (None when the sizes give none).

A mode passes when |deviation| <= its tolerance and its deviation is either bounded by the
stated error or explained by the case's `bound_note` and within the reference's uncertainty
(the mode's own, declared beside it, or else the case's). A case passes when every mode and
every check (at every size) passes; a mode or a check declared not counted (a reference that
verifies nothing, a measured limitation of the stated error) is shown with its own verdict and
left out of the case's.
"""
from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable

from fem_reference.convergence import gci, richardson

from .cases import CASE_LIST, Case
from .problems import SOLVERS, Outcome

CASES = tuple(c.name for c in CASE_LIST)


def case_named(name: str) -> Case:
    """The declaration of the case `name` (KeyError naming the known ones)."""
    for case in CASE_LIST:
        if case.name == name:
            return case
    raise KeyError(f"no verification case {name!r}; known: {', '.join(CASES)}")


def replace_sizes(case: Case, sizes) -> Case:
    """The case at other sizes (coarse -> fine, m): for quick runs and tests."""
    return dataclasses.replace(case, sizes_m=tuple(float(h) for h in sizes))


def mode_record(case: Case, index: int, effective: list[float], hz: list[float]) -> dict:
    """The record of reference mode `index` of `case` from its frequencies at the sizes."""
    mode = case.modes[index]
    rich, grid = richardson(effective, hz), gci(effective, hz)
    rich_pct = 100 * rich.relative_error[-1]
    gci_pct = 100 * grid.relative_error[-1]
    stated = max(rich_pct, gci_pct)
    deviation = 100 * (hz[-1] / mode.hz - 1.0)
    tolerance = case.tolerance_percent if mode.tolerance_percent is None \
        else mode.tolerance_percent
    return {"label": mode.label, "reference_hz": mode.hz, "hz": [float(f) for f in hz],
            "deviation_percent": deviation, "observed_order": grid.observed_order,
            "stated_error_percent": stated, "richardson_error_percent": rich_pct,
            "gci_percent": gci_pct, "tolerance_percent": tolerance,
            "within_tolerance": abs(deviation) <= tolerance,
            "bounded": abs(deviation) <= stated, "counted": mode.counted, "note": mode.note}


def uncertainty_of(case: Case, index: int) -> float | None:
    """The reference uncertainty (%) that may explain mode `index`'s deviation."""
    own = case.modes[index].uncertainty_percent
    return case.reference_uncertainty_percent if own is None else own


def mode_passes(case: Case, index: int, record: dict) -> bool:
    """Within tolerance, and bounded or explained (bound_note, within the uncertainty)."""
    if not record["within_tolerance"]:
        return False
    if record["bounded"]:
        return True
    limit = uncertainty_of(case, index)
    return case.bound_note is not None and limit is not None and \
        abs(record["deviation_percent"]) <= limit


def merge_checks(outcomes: list[Outcome]) -> list[dict]:
    """Every check over the sizes: its values coarse -> fine, its limit, passed at all sizes."""
    out = []
    for k, first in enumerate(outcomes[0].checks):
        at = [o.checks[k] for o in outcomes]
        out.append({"what": f"{first.what} (at every size: values coarse -> fine)",
                    "value": [float(c.value) for c in at], "limit": float(first.limit),
                    "op": first.op, "passed": all(c.passed for c in at),
                    "counted": first.counted})
    return out


def compare_checks(case: Case, outcomes: list[Outcome], effective: list[float]) -> list[dict]:
    """Each comparison of two independent discretisations of the same solid: |f / f_other - 1|
    (%) at the finest size against this discretisation's stated error there; not counted when
    the case declares it a measured limitation (`Case.limitation`)."""
    out = []
    for label in outcomes[-1].compare:
        hz = [o.compare[label][0] for o in outcomes]
        other = outcomes[-1].compare[label][1]
        rich, grid = richardson(effective, hz), gci(effective, hz)
        stated = 100 * max(rich.relative_error[-1], grid.relative_error[-1])
        value = 100 * abs(hz[-1] / other - 1.0)
        what = (f"{label}: |f_3D / f_harmonic - 1| (%) at the finest size within the 3D stated "
                f"error (3D Hz coarse -> fine {[round(f, 4) for f in hz]}, harmonic "
                f"{other:.4f})")
        if case.limitation:
            what += f"; {case.limitation}"
        out.append({"what": what, "value": value, "limit": stated, "op": "<=",
                    "passed": value <= stated, "counted": case.limitation is None})
    return out


def run_case(name: str) -> dict:
    """Solve the case `name` at its sizes and return its record (module docstring)."""
    case = case_named(name)
    outcomes, seconds = [], []
    for size in case.sizes_m:
        start = time.perf_counter()
        outcomes.append(SOLVERS[name](case, size))
        seconds.append(time.perf_counter() - start)
    effective = [o.effective_size for o in outcomes]
    modes = [mode_record(case, i, effective, [o.hz[m.label] for o in outcomes])
             for i, m in enumerate(case.modes)]
    for i, record in enumerate(modes):
        record["passed"] = mode_passes(case, i, record)
    checks = merge_checks(outcomes) + compare_checks(case, outcomes, effective)
    passed = all(r["passed"] for r in modes if r["counted"]) and \
        all(c["passed"] for c in checks if c["counted"])
    return {"name": case.name, "title": case.title, "source": case.source,
            "discretisation": case.discretisation, "what": case.what,
            "reference_uncertainty_percent": case.reference_uncertainty_percent,
            "tolerance_percent": case.tolerance_percent,
            "tolerance_reason": case.tolerance_reason,
            "mesh_sizes_mm": [1e3 * float(h) for h in case.sizes_m],
            "dofs": [o.dofs for o in outcomes],
            "seconds": seconds, "modes": modes, "checks": checks,
            "bound_note": case.bound_note, "passed": passed}


def run_all(progress: Callable[[str], None] | None = None) -> dict:
    """Every case in order: {"cases": [record, ...], "passed": all passed, "seconds": total}.
    `progress(name)` is called before each case."""
    start = time.perf_counter()
    records = []
    for name in CASES:
        if progress is not None:
            progress(name)
        records.append(run_case(name))
    return {"cases": records, "passed": all(r["passed"] for r in records),
            "seconds": time.perf_counter() - start}
