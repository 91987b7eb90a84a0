"""A short plain-language verdict per case, written from the numbers in results.json only."""
from __future__ import annotations


def _worst(values) -> float | None:
    values = [abs(v) for v in values if v is not None]
    return max(values) if values else None


def _pct(x: float) -> str:
    return f"{x:.2f} %" if x < 10 else f"{x:.1f} %"


def _grade(x: float) -> str:
    if x <= 1.0:
        return "agree closely"
    if x <= 3.0:
        return "agree"
    if x <= 5.0:
        return "agree only roughly"
    return "disagree"


def _bound(x: float) -> str:
    return f"within {_pct(x)}" if x <= 5.0 else f"differing by up to {_pct(x)}"


def case_verdict(case: dict) -> list[str]:
    """Sentences: agreement of the low and high modes, the FEM's own error, the shapes, the paper."""
    pairs = sorted(case["pairs"], key=lambda p: p["fem_mode"])
    low = [p["error_percent"] for p in pairs if p["fem_mode"] <= 3]
    high = [p["error_percent"] for p in pairs if p["fem_mode"] > 3]
    out = []
    a = case["analytical"]
    model = (f"The analytical model ({a.get('beam', '?')}, s = {a.get('elements', '?')}, "
             f"{a.get('platform_inertia', '?')} inertia)")
    parts = []
    if low:
        w = _worst(low)
        parts.append(f"the first {len(low)} modes {_grade(w)} with our FEM, {_bound(w)}")
    if high:
        w = _worst(high)
        first, last = min(p["fem_mode"] for p in pairs if p["fem_mode"] > 3), max(
            p["fem_mode"] for p in pairs)
        parts.append(f"modes {first}–{last} {_grade(w)}, {_bound(w)}")
    if parts:
        out.append(f"{model}: " + "; ".join(parts) + ".")
    signs = {p["error_percent"] > 0 for p in pairs if abs(p["error_percent"]) > 0.05}
    if signs == {True}:
        out.append("Every analytical frequency lies above the FEM's: the beam model is stiffer.")
    elif signs == {False}:
        out.append("Every analytical frequency lies below the FEM's: the beam model is softer.")

    fem_err = _worst(case.get("fem_estimated_error_percent") or [])
    if fem_err is not None:
        worst_all = _worst(p["error_percent"] for p in pairs) or 0.0
        tail = ("so the discrepancies above are the beam model's, not the mesh's"
                if fem_err < 0.5 * worst_all else
                "comparable to the discrepancies, so part of them may be the mesh's")
        out.append(f"The FEM's own estimated discretisation error (Richardson extrapolation) "
                   f"is at most {_pct(fem_err)}, {tail}.")
    else:
        out.append("No mesh-refinement study for this case: the FEM's own discretisation error "
                   "is not estimated here.")

    macs = [p["mac"] for p in pairs]
    if macs:
        lo = min(macs)
        shape = ("the mode shapes match" if lo >= 0.9 else
                 "most mode shapes match" if lo >= 0.7 else "some mode shapes do not match")
        out.append(f"Paired by shape, {shape} (lowest MAC {lo:.3f}).")
    reps = {p["group"] for p in pairs if p.get("repeated")}
    if reps:
        out.append(f"{len(reps)} repeated pair{'s' if len(reps) > 1 else ''} "
                   f"compared as a 2-D subspace.")

    paper = case.get("paper") or {}
    if paper.get("error_percent"):
        pw = paper["error_percent"]
        out.append(f"For comparison, the paper's own theory-vs-ANSYS errors are within "
                   f"{_pct(_worst(pw[:3]))} (modes 1–3) and {_pct(_worst(pw[3:]))} "
                   f"(modes 4–6).")
    if paper.get("theory_hz"):
        dev = _worst(100 * (a_hz / t - 1) for a_hz, t in
                     zip(case["analytical"]["frequencies_hz"], paper["theory_hz"]))
        if dev <= 1.0:
            out.append(f"Our analytical frequencies reproduce the paper's theoretical row "
                       f"within {_pct(dev)}.")
        else:
            out.append(f"Our analytical frequencies differ from the paper's theoretical row by "
                       f"up to {_pct(dev)} while agreeing with our FEM as stated above; no "
                       f"reading of the paper's angles that we tried reproduces that row "
                       f"(see the angle-convention study).")
    best = best_model(case)
    if best:
        label, low_w, high_w = best
        out.append(f"Best analytical model offered ({label}): modes 1–3 within {_pct(low_w)} "
                   f"and modes 4–6 within {_pct(high_w)} of the FEM.")
    return out


def best_model(case: dict) -> tuple[str, float, float] | None:
    """The model variant with the smallest worst |error| over all modes, if variants exist."""
    best = None
    for label, model in (case.get("models") or {}).items():
        pairs = model.get("pairs") or []
        if not pairs:
            continue
        key = ("error_vs_reference_percent" if "error_vs_reference_percent" in pairs[0]
               else "error_percent")
        low = _worst(p[key] for p in pairs if p["fem_mode"] <= 3) or 0.0
        high = _worst(p[key] for p in pairs if p["fem_mode"] > 3) or 0.0
        if best is None or max(low, high) < max(best[1], best[2]):
            best = (label, low, high)
    return best


def headline(results: dict) -> str:
    """One sentence over the cases that carry paper rows (or all cases)."""
    cases = [c for c in results["cases"] if c.get("paper")] or results["cases"]
    low = _worst(p["error_percent"] for c in cases for p in c["pairs"] if p["fem_mode"] <= 3)
    high = _worst(p["error_percent"] for c in cases for p in c["pairs"] if p["fem_mode"] > 3)
    names = ", ".join(c["name"] for c in cases)
    text = f"Over {names}: modes 1–3 within {_pct(low)} of our FEM" if low is not None else ""
    if high is not None:
        text += f", higher modes within {_pct(high)}"
    return text + "."
