"""The stability lobe diagram (matplotlib, Agg) from a lobes record's values only: the critical
depth against spindle speed (stable below the curve), the flip (period-doubling) part marked,
the zero-order estimate dashed, the least depth pointed out; several records (the models and
the FEM at one pose) on one diagram with `draw_lobe_set`."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from .figures import SETTING_COLOURS, WIDTH, plt, save


def _depths(values) -> np.ndarray:
    return np.array([np.nan if v is None else v for v in values], float)


def draw_lobes(record: Mapping[str, Any], path: Path, title: str = "") -> None:
    """One diagram of one record."""
    draw_lobe_set([("", record)], path, title or record.get("source", ""), zoa=True)


def draw_lobe_set(records: Sequence[tuple[str, Mapping[str, Any]]], path: Path,
                  title: str = "", zoa: bool = False) -> None:
    """Records (label, record) over the same speeds, each its own colour."""
    save(lobe_figure(records, title, zoa), path)


def lobe_figure(records: Sequence[tuple[str, Mapping[str, Any]]], title: str = "",
                zoa: bool = False):
    """The diagram of `draw_lobe_set`, open (for a caller that adds to it, then saves it)."""
    fig, ax = plt.subplots(figsize=(WIDTH, 2.9))
    top = 0.0
    for k, (label, rec) in enumerate(records):
        rpm = np.asarray(rec["spindle_rpm"], float)
        depth = _depths(rec["critical_depth_mm"])
        colour = SETTING_COLOURS[k % len(SETTING_COLOURS)]
        name = label or f"critical depth ({rec['method']})"
        ax.plot(rpm, depth, color=colour, lw=1.1, label=name)
        flip = np.array([kd == "flip" for kd in rec["kind"]])
        if flip.any():
            ax.plot(rpm[flip], depth[flip], ".", ms=2.5, color=colour,
                    label="flip (period doubling)" if k == 0 else None)
        if zoa and k == 0:
            ax.plot(rpm, _depths(rec["zoa_depth_mm"]), "--", lw=0.8, color="0.45",
                    label="zero-order estimate")
        least = rec.get("least")
        if least is not None and k == 0:
            ax.plot([least["spindle_rpm"]], [least["depth_mm"]], "v", color="k", ms=4,
                    label=f"least {least['depth_mm']:.3g} mm at {least['spindle_rpm']:.0f} rpm")
        finite = depth[np.isfinite(depth)]
        if finite.size:
            top = max(top, float(np.percentile(finite, 98)) * 1.15)
    ax.set_ylim(0, top or 1.0)
    ax.set_xlabel("spindle speed (rpm)")
    ax.set_ylabel("critical axial depth (mm)")
    if title:
        ax.set_title(title, loc="left")
    ax.text(0.99, 0.03, "stable below the curve", transform=ax.transAxes, ha="right",
            fontsize=7, color="0.3")
    ax.legend(loc="upper left", frameon=False, ncol=2)
    return fig
