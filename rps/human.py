"""Terminal output for people: numbers rounded by what they measure, and the compact summary
printed at the end of `rps validate`. (`--json` prints the exact values instead.)

Rounding follows the unit carried by the key's name: frequencies (`_hz`) to 0.01 Hz as the
paper prints them, lengths in mm and angles in degrees to 2 decimals, percentages, seconds and
anything else to 3-4 significant figures.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, TypedDict

if TYPE_CHECKING:  # results (and pydantic, an extra) only when a run has results
    from results import Case, Results

LOW_MODES = 3  # the modes f1..f3 (leg bending, platform torsion) against the higher ones
DASH = "–"


def significant(x: float, figures: int = 3) -> str:
    """x to `figures` significant figures, in plain decimal notation (no exponent)."""
    if x == 0 or not math.isfinite(x):
        return f"{x:g}"
    digits = max(0, figures - 1 - math.floor(math.log10(abs(x))))
    return f"{round(x, digits):.{digits}f}"


def number(key: str, x: float) -> str:
    """One value, rounded after the unit its key names (`frequencies_hz`, `height_mm`, ...)."""
    if isinstance(x, bool) or not isinstance(x, float):
        return str(x)
    if key.endswith("_hz"):
        return f"{x:.2f}"
    if key.endswith(("_mm", "_deg")):
        return f"{x:.2f}"
    if key.endswith("_percent"):
        return significant(x, 3)
    if key.endswith("seconds") or key.startswith("timings"):
        return significant(x, 3)
    text = significant(x, 4)
    return text.rstrip("0").rstrip(".") if "." in text else text


def _flatten(payload: dict, prefix: str = ""):
    for key, value in payload.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            yield from _flatten(value, f"{name}.")
        else:
            yield name, value


def payload_lines(payload: dict) -> list[str]:
    """`key: value` lines of a command's result; nested keys dotted, lists comma-separated."""
    rows = []
    for key, value in _flatten(payload):
        if isinstance(value, (list, tuple)):
            text = ", ".join(number(key, v) for v in value)
        else:
            text = number(key, value)
        rows.append((key, text))
    width = max((len(k) for k, _ in rows), default=0)
    return [f"{k:>{width}}: {v}" for k, v in rows]


def _worst(values) -> float | None:
    values = [abs(v) for v in values if v is not None]
    return max(values) if values else None


def _percent(x: float | None) -> str:
    return DASH if x is None else f"{significant(x, 3)} %"


class CaseSummary(TypedDict):
    """One row of the table a validation prints at its end."""
    name: str
    low_range: str  # "f1-f6"
    high_range: str
    low_percent: float | None  # worst |error| of the analytical model in that range
    high_percent: float | None
    fem_error_percent: float | None  # the FEM's own worst estimated error
    lowest_mac: float | None
    verdict: str


def case_summary(case: Case) -> CaseSummary:
    """The numbers of one summary row: worst |error| of the analytical model against the FEM
    per mode range, the FEM's own worst estimated error, the lowest MAC and a verdict."""
    from results.verdict import grade  # the report's own wording of agreement

    pairs = case["pairs"]
    modes = sorted(p["fem_mode"] for p in pairs)
    low = _worst(p["error_percent"] for p in pairs if p["fem_mode"] <= LOW_MODES)
    high = _worst(p["error_percent"] for p in pairs if p["fem_mode"] > LOW_MODES)
    worst = _worst(p["error_percent"] for p in pairs)
    return CaseSummary(**{
        "name": case["name"],
        "low_range": f"f1–f{min(LOW_MODES, modes[-1])}" if modes else "",
        "high_range": f"f{LOW_MODES + 1}–f{modes[-1]}" if modes and modes[-1] > LOW_MODES
        else "",
        "low_percent": low,
        "high_percent": high,
        "fem_error_percent": _worst(case.get("fem_estimated_error_percent") or []),
        "lowest_mac": min((p["mac"] for p in pairs), default=None),
        "verdict": DASH if worst is None else grade(worst),
    })


def summary(results: Results, out: Path, report: bool) -> str:
    """The table printed at the end of a validation run, and where its outputs are."""
    rows = [case_summary(c) for c in results["cases"]]
    low = next((r["low_range"] for r in rows if r["low_range"]), "f1–f3")
    high = next((r["high_range"] for r in rows if r["high_range"]), "f4–f6")
    head = ["case", f"{low} worst", f"{high} worst", "FEM est. err", "lowest MAC", "verdict"]
    body = [[r["name"], _percent(r["low_percent"]), _percent(r["high_percent"]),
             _percent(r["fem_error_percent"]),
             DASH if r["lowest_mac"] is None else f"{r['lowest_mac']:.3f}", r["verdict"]]
            for r in rows]
    widths = [max(len(row[k]) for row in [head] + body) for k in range(len(head))]

    def line(cells):
        return "  ".join(c.ljust(w) if k in (0, len(cells) - 1) else c.rjust(w)
                         for k, (c, w) in enumerate(zip(cells, widths))).rstrip()

    fidelity = results.get("fidelity") or {}
    a = fidelity.get("analytical") or {}
    model = f" ({a['setting']})" if "setting" in a else ""
    text = [f"Analytical model{model} against the FEM, worst |error| per mode range:",
            line(head)]
    text += [line(row) for row in body]
    if all(r["fem_error_percent"] is None for r in rows):
        text.append("FEM est. err: no refinement study in this profile (run the full profile).")
    text += [f"warning: {w}" for w in results["scene"]["warnings"]]
    out = Path(out).resolve()
    text.append(f"results: {out / 'results.json'}")
    if report:
        text.append(f"report:  {out / 'report.html'}  ({out / 'report.pdf'})")
    if any((out / "modes").glob("*.pvd")):
        text.append(f"mode shapes for ParaView: {out / 'modes'}/*.pvd")
    return "\n".join(text)
