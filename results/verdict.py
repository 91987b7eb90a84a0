"""A short plain-language verdict per case, written from the numbers in results.json only."""
from __future__ import annotations

from typing import Iterable

from results import LOW_MODES, Case, Results, mode_ranges, worst_by_mode_range, worst_in_mode_ranges


def _worst(values: Iterable[float | None]) -> float | None:
    present = [abs(v) for v in values if v is not None]
    return max(present) if present else None


def _pct(x: float) -> str:
    return f"{x:.2f} %" if x < 10 else f"{x:.1f} %"


def grade(x: float) -> str:
    if x <= 1.0:
        return "agree closely"
    if x <= 3.0:
        return "agree"
    if x <= 5.0:
        return "agree only roughly"
    return "disagree"


def _bound(x: float) -> str:
    return f"within {_pct(x)}" if x <= 5.0 else f"differing by up to {_pct(x)}"


def case_verdict(case: Case, conventions: bool = False) -> list[str]:
    """Sentences: agreement of the low and high modes, the FEM's own error, the shapes, the
    paper (`conventions`: the results hold an angle-convention study of this case)."""
    pairs = sorted(case["pairs"], key=lambda p: p["fem_mode"])
    low, high = worst_by_mode_range(pairs, error=lambda p: p["error_percent"])
    out = []
    a = case["analytical"]
    model = (f"The analytical model ({a['beam']}, s = {a['elements']}, "
             f"{a['platform_inertia']} inertia)")
    parts = []
    if low is not None:
        count = sum(p["fem_mode"] <= LOW_MODES for p in pairs)
        parts.append(f"the first {count} modes {grade(low)} with our FEM, {_bound(low)}")
    if high is not None:
        last = max(p["fem_mode"] for p in pairs)
        parts.append(f"modes {LOW_MODES + 1}–{last} {grade(high)}, {_bound(high)}")
    if parts:
        out.append(f"{model}: " + "; ".join(parts) + ".")
    signs = {p["error_percent"] > 0 for p in pairs if abs(p["error_percent"]) > 0.05}
    if signs == {True}:
        out.append("Every analytical frequency lies above the FEM's: the beam model is stiffer.")
    elif signs == {False}:
        out.append("Every analytical frequency lies below the FEM's: the beam model is softer.")

    fem_err = _worst(case["fem_estimated_error_percent"] or [])
    if fem_err is not None:
        worst_all = _worst(p["error_percent"] for p in pairs) or 0.0
        tail = ("so the discrepancies above are the beam model's, not the mesh's"
                if fem_err < 0.5 * worst_all else
                "comparable to the discrepancies, so part of them may be the mesh's")
        out.append(f"The FEM's own estimated discretisation error (the larger of Richardson's "
                   f"extrapolation and the grid convergence index) "
                   f"is at most {_pct(fem_err)}, {tail}.")
    else:
        out.append("No mesh-refinement study for this case: the FEM's own discretisation error "
                   "is not estimated here.")

    macs = [p["mac"] for p in pairs]
    if macs:
        lo = min(macs)
        shape = ("the mode shapes match" if lo >= 0.9 else
                 "most mode shapes match" if lo >= 0.7 else "some mode shapes do not match")
        any_repeated = any(p["repeated"] for p in pairs)
        out.append(f"Paired by shape, {shape} (lowest MAC {lo:.3f}"
                   + (", a repeated pair's taken over its 2-D subspace" if any_repeated else "")
                   + ").")
    reps = {p["group"] for p in pairs if p["repeated"]}
    if reps:
        out.append(f"{len(reps)} repeated pair{'s' if len(reps) > 1 else ''} "
                   f"compared as a 2-D subspace.")

    paper = case["paper"]
    pw = paper["error_percent"] if paper else None
    if pw:
        ranges = [f"{_pct(worst)} ({label})" for worst, label in
                  zip(worst_in_mode_ranges(enumerate(pw, start=1)), mode_ranges(pairs))
                  if worst is not None]
        out.append("For comparison, the paper's own theory-vs-ANSYS errors are within "
                   + " and ".join(ranges) + ".")
    theory = paper["theory_hz"] if paper else None
    if theory:
        dev = _worst(100 * (a_hz / t - 1) for a_hz, t in
                     zip(case["analytical"]["frequencies_hz"], theory))
        if dev is None:  # no analytical frequency: `None <= 1.0` would raise the same
            raise TypeError("no analytical frequency to compare with the paper's theory row")
        if dev <= 1.0:
            out.append(f"Our analytical frequencies reproduce the paper's theoretical row "
                       f"within {_pct(dev)}.")
        else:
            out.append(f"Our analytical frequencies differ from the paper's theoretical row by "
                       f"up to {_pct(dev)} while agreeing with our FEM as stated above"
                       + ("; no reading of the paper's angles that we tried reproduces that "
                          "row (see the angle-convention study)." if conventions else "."))
    best = best_model(case)
    if best:
        label, low_w, high_w = best
        low_range, high_range = mode_ranges(pairs)
        out.append(f"Best analytical model offered ({label}): {low_range} within {_pct(low_w)}"
                   + (f" and {high_range} within {_pct(high_w)}" if high_w is not None else "")
                   + " of the FEM.")
    return out


def best_model(case: Case) -> tuple[str, float, float | None] | None:
    """The model variant with the smallest worst |error| over all modes, if variants exist:
    (label, worst of the low modes, worst of the modes above)."""
    best: tuple[str, float, float | None] | None = None
    for label, model in (case["models"] or {}).items():
        low, high = worst_by_mode_range(model["pairs"])
        if low is None:
            continue
        if best is None or max(low, high or 0.0) < max(best[1], best[2] or 0.0):
            best = (label, low, high)
    return best


def headline(results: Results) -> str:
    """One sentence over the cases that carry paper rows (or all cases)."""
    cases = [c for c in results["cases"] if c["paper"]] or results["cases"]
    pairs = [p for c in cases for p in c["pairs"]]
    low, high = worst_by_mode_range(pairs, error=lambda p: p["error_percent"])
    names = ", ".join(c["name"] for c in cases)
    text = (f"Over {names}: modes 1–{LOW_MODES} within {_pct(low)} of our FEM"
            if low is not None else f"Over {names}")
    if high is not None:
        text += f", higher modes within {_pct(high)}"
    return text + "."
