"""The static twins (matplotlib, Agg) of the tool's receptance and of a case's stability lobes
(report.pdf; report.html draws them with plotly): from results.json values only, each function
writing one PNG. The uncertainty figures are `study_figures`', the polar maps `study_maps`'.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

import numpy as np

from . import lobes_plot
from .figures import FEM_COLOUR, SETTING_COLOURS, WIDTH, plt, save
from .study_figures import BAND_COLOUR, DIRECTIONS, _floats

# ---- the tool's receptance --------------------------------------------------------------

def tool_directions(record: Mapping[str, Any]) -> list[str]:
    curves = record["curves"]
    if not curves["frequency_hz"]:
        return []
    return [d for d in DIRECTIONS
            if d in curves["analytical_m_per_n"] or d in curves["fem_m_per_n"]]


def tool_response(record: Mapping[str, Any], path: Path) -> None:
    """|H_xx|, |H_yy|, |H_zz| of the tool point (m/N, log) against frequency, one panel per
    direction: the analytical model (line), the FEM's modal sum (dashed), the solid's direct
    response at each of its peaks (circles)."""
    directions = tool_directions(record)
    if not directions:
        raise ValueError("the tool response has no curve")
    curves = record["curves"]
    f = _floats(curves["frequency_hz"])
    fig, axes = plt.subplots(1, len(directions), figsize=(WIDTH, 2.5), squeeze=False)
    for c, (ax, d) in enumerate(zip(axes[0], directions)):
        if d in curves["analytical_m_per_n"]:
            ax.plot(f, _floats(curves["analytical_m_per_n"][d]), color=SETTING_COLOURS[0],
                    lw=1.2, label="analytical model")
        if d in curves["fem_m_per_n"]:
            ax.plot(f, _floats(curves["fem_m_per_n"][d]), color=FEM_COLOUR, lw=1.2, ls="--",
                    label="FEM, modal sum")
        peaks = [p for p in record["peaks"] if p["direction"] == d]
        if peaks:
            ax.plot([p["fem_direct_hz"] for p in peaks], [p["fem_direct_m_per_n"] for p in peaks],
                    "o", ms=6, mfc="none", mec="k", mew=1.1, label="FEM, direct response")
        ax.set_yscale("log")
        ax.set_title(f"$|H_{{{d}{d}}}|$", loc="left")
        ax.set_xlabel("frequency (Hz)")
        if c == 0:
            ax.set_ylabel("|H| (m/N)")
    handles: dict[str, Any] = {}
    for ax in axes[0]:
        for h, label in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(label, h)
    fig.legend(list(handles.values()), list(handles), loc="lower center", ncol=3,
               frameon=False, fontsize=7, bbox_to_anchor=(0.5, 0.0))
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    save(fig, path)


def _point(record: Mapping[str, Any]) -> str:
    return "(" + ", ".join(f"{v:g}" for v in record["point_mm"]) + ") mm"


def tool_caption(case: Mapping[str, Any], record: Mapping[str, Any]) -> str:
    shown = ", ".join(f"|H_{d}{d}|" for d in tool_directions(record))
    return (f"{case['description']} ({case['name']}): the receptance {shown} of the tool "
            f"point {_point(record)} from the platform centre (m/N, log scale) against "
            f"frequency (Hz): lines the analytical model ({record['analytical']}), dashed "
            f"the FEM's modal sum (h = {record['fem_mesh_size_mm']:g} mm), circles the "
            "solid's direct frequency response at each of its peaks, all at one damping: "
            f"{record['check_damping']}.")


# ---- the stability lobes ----------------------------------------------------------------

CURVES = ("analytical", "fem", "fem_coarse")


def has_lobes(record: Mapping[str, Any]) -> bool:
    return any(v is not None for key in CURVES for v in record[key]["critical_depth_mm"])


def _shown_band(record: Mapping[str, Any]) -> Mapping[str, Any] | None:
    band = record.get("band")
    return band if band and not band["refused"] and band["spindle_rpm"] else None


def case_lobes(record: Mapping[str, Any], path: Path) -> None:
    """The case's lobes through `lobes_plot.draw_lobe_set`: the analytical model's, the FEM's
    at the run's mesh and one size coarser, the analytical model's least depth marked; the 95 %
    band over the scene's [uncertainty] shaded under them when the record holds one; the
    legend under the diagram."""
    if not has_lobes(record):
        raise ValueError("no finite critical depth to draw")
    records = []
    for key in CURVES:
        curve = record[key]
        rec: dict[str, Any] = {"spindle_rpm": record["spindle_rpm"], "method": record["method"],
                               **curve}
        row = next((s for s in record["summary"] if s["model"] == key), None)  # analytical
        if row is not None and row["least_depth_mm"] is not None:  # (drawn of the first)
            rec["least"] = {"spindle_rpm": row["least_rpm"], "depth_mm": row["least_depth_mm"]}
        records.append((curve["model"], rec))
    fig = lobes_plot.lobe_figure(records)
    fig.set_size_inches(WIDTH, 2.5)
    ax = fig.axes[0]
    band = _shown_band(record)
    if band is not None:
        rpm, lo, hi = (_floats(band[k])
                       for k in ("spindle_rpm", "q025_depth_mm", "q975_depth_mm"))
        ax.fill_between(rpm, lo, hi, where=np.isfinite(lo) & np.isfinite(hi),
                        color=BAND_COLOUR, alpha=0.2, lw=0, zorder=0,
                        label=f"95 % of {band['samples']} machines drawn from [uncertainty]")
        finite = hi[np.isfinite(hi)]
        if finite.size:
            ax.set_ylim(0, max(ax.get_ylim()[1], float(np.percentile(finite, 98)) * 1.15))
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=3, frameon=False,
              fontsize=6.8)  # below the axes: the lobes reach the top
    save(fig, path)


def lobes_caption(case: Mapping[str, Any], record: Mapping[str, Any]) -> str:
    median = record["median_error_percent"]
    said = "" if median is None else (
        f"; the analytical model's depth is within {median:.2g} % of the FEM's at the median "
        f"speed, {record['max_error_percent']:.2g} % at worst")
    band = record.get("band")
    spread = ""
    if _shown_band(record) is not None:
        assert band is not None
        spread = (f" Shaded: 95 % of {band['samples']} machines drawn from the scene's "
                  f"[uncertainty] ({band['model']}), from the 2.5 % to the 97.5 % quantile of "
                  "their critical depth (a gap: stable up to the search's ceiling).")
    elif band and band["refused"]:
        spread = f" The band over [uncertainty] was not drawn: {band['refused']}."
    return (f"{case['description']} ({case['name']}): the critical axial depth of the "
            f"scene's cut (mm) against spindle speed (rpm) ({record['method']}; stable below a "
            f"curve; dots: flip, period doubling), from the analytical model's tool modes and "
            f"the FEM's at {record['fem_mesh_size_mm']:g} mm and "
            f"{record['coarse_mesh_size_mm']:g} mm; triangle: the analytical model's least "
            f"depth{said}.{spread}")
