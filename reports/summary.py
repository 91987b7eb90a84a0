"""What a designer acts on, said in the summary's first lines (issue 54), each from a record:
the least frequency over the workspace and where, what the scene's input uncertainty does to it,
the least dynamic stiffness at the tool, the least critical depth of the scene's cut, and what
the test campaign beside the run changed (`campaign_summary`). A line whose study did not run
is not said."""
from __future__ import annotations

import math
from typing import Any, Mapping, cast

import numpy as np

from results import Results


def _studies(results: Results) -> Mapping[str, Any]:
    return cast("Mapping[str, Any]", results["studies"])


def _where(height_mm: float, tilt_deg: float, azimuth_deg: float) -> str:
    if tilt_deg < 0.05:
        return f"z = {height_mm:.0f} mm, level"
    return f"z = {height_mm:.0f} mm, tilted {tilt_deg:.1f}° towards φ = {azimuth_deg:.0f}°"


def least_frequency(results: Results) -> str | None:
    """The least f1 over the workspace map, where, and its band over the inputs there."""
    ws = results["studies"]["workspace"]
    if not ws:
        return None
    f1 = np.array([[[np.nan if m is None or m[0] is None else m[0] for m in ring]
                    for ring in layer] for layer in ws["frequencies_hz"]], float)
    if not np.isfinite(f1).any():
        return None
    i, j, k = np.unravel_index(np.nanargmin(f1), f1.shape)
    where = _where(ws["heights_mm"][i], ws["tilts_deg"][i][j], ws["azimuths_deg"][k])
    text = (f"Least first natural frequency over the workspace map: {f1[i, j, k]:.1f} Hz at "
            f"{where} ({ws['settings']}).")
    path = _studies(results).get("uncertainty_path")
    poses = [p for p in (path or {}).get("poses") or [] if p["f1_q025_hz"] is not None]
    if poses:
        p = min(poses, key=lambda q: q["f1_nominal_hz"])
        text += (f" With the scene's input uncertainty, 95 % of machines have f1 between "
                 f"{p['f1_q025_hz']:.1f} and {p['f1_q975_hz']:.1f} Hz at the least pose of "
                 f"the path ({_where(p['height_mm'], p['tilt_deg'], p['azimuth_deg'])}; "
                 f"{p['f1_nominal_hz']:.1f} Hz at the scene's values).")
    return text


def _grouped(value: float) -> str:
    """Three significant figures, thousands set apart by thin spaces (202 000)."""
    rounded = float(f"{value:.3g}")
    return f"{rounded:,.0f}".replace(",", "\u2009") if rounded >= 1e3 else f"{rounded:.3g}"


def _listed(value) -> list:
    return [] if value is None else value if isinstance(value, list) else [value]


def _least(results: Results, study: str, value: str) -> tuple[Any, Mapping[str, Any] | None]:
    """A map study's record and its row of least `value` (None: no row holds one)."""
    record = _studies(results).get(study)
    rows = [r for r in _listed((record or {}).get("least")) if r.get(value) is not None]
    return record, min(rows, key=lambda q: q[value]) if rows else None


def least_stiffness(results: Results) -> str | None:
    """The least dynamic stiffness at the tool over the map, along its weakest direction."""
    _, r = _least(results, "dynamic_stiffness", "stiffness_n_per_m")
    if r is None:
        return None
    return (f"Least dynamic stiffness at the tool: {_grouped(r['stiffness_n_per_m'])} N/m along "
            f"{r['direction']}, at {r['frequency_hz']:.1f} Hz, "
            f"{_where(r['height_mm'], r['tilt_deg'], r['azimuth_deg'])}.")


def least_depth(results: Results) -> str | None:
    """The least critical depth of the scene's cut over the workspace map."""
    record, r = _least(results, "stability_map", "depth_mm")
    if r is None:
        return None if record is None else (
            "The scene's cut is stable at every pose of the workspace map and every speed, up "
            "to the search's ceiling.")
    return (f"Least critical depth of the scene's cut over the workspace: {r['depth_mm']:.2f} mm "
            f"at {r['spindle_rpm']:.0f} rpm (chatter at {r['chatter_frequency_hz']:.0f} Hz), "
            f"{_where(r['height_mm'], r['tilt_deg'], r['azimuth_deg'])}.")


def campaign_line(summary: Mapping[str, Any] | None) -> str | None:
    """What the test campaign beside the run changed (`campaign_summary`'s record)."""
    if not summary:
        return None
    before = summary["mean_error_percent"]
    text = (f"Test campaign {summary['campaign']} ({summary['machine']}): "
            + ("no test mode paired with the model" if before is None else
               f"the model misses the measured frequencies by {before:.1f} % on average "
               f"({summary['pairs']} paired modes)"))
    if summary["identified"] is not None:
        after = summary["mean_error_after_percent"]
        text += ("" if after is None or not math.isfinite(after) else
                 f", {after:.1f} % after identification")
        names = [p["key"] for p in summary["identified"] if p["identifiable"]]
        text += (f"; identified within its tolerance: {', '.join(names)}" if names else
                 "; no key identified within its tolerance")
        lost = [p["key"] for p in summary["identified"] if not p["identifiable"]]
        if lost:
            text += f"; not identifiable from these data: {', '.join(lost)}"
    return text + "."


def designer_lines(results: Results, campaign: Mapping[str, Any] | None) -> list[str]:
    """The summary's lines after the fidelity's, in the order a designer reads them."""
    lines = (least_frequency(results), least_stiffness(results), least_depth(results),
             campaign_line(campaign))
    return [line for line in lines if line]
