"""The static twins (matplotlib, Agg) of the interactive charts of the studies report.pdf
otherwise shows as tables only: input uncertainty (Sobol' indices; V&V 20 and the spread of
the frequencies), the band along the workspace map's worst path, the tool's receptance and
the stability lobes. Drawn from results.json values only (nothing computed beyond scaling a
value for its axis); every function writes one PNG, the caller decides the file name. The
polar maps of these studies are in `study_maps`.
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Mapping

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from .figures import FEM_COLOUR, SETTING_COLOURS, WIDTH, plt, save
from .setup_tables import MANIPULATOR_ROWS

BAND_COLOUR = "#1f77b4"
UNRESOLVED = "0.55"  # an index not resolved from zero (its sampling error exceeds it)
DIRECTIONS = ("x", "y", "z")
_UNIT_SUFFIX = re.compile(r"_(mm|m|gpa|mpa|pa|kg_m3|kg|deg|rad|hz|s|n_per_m|n_per_um|"
                          r"n_mm2|n_per_mm2|percent)$")


def _floats(values) -> np.ndarray:
    """Floats, NaN where a value is None."""
    return np.array([np.nan if v is None else v for v in values], float)


def input_label(key: str, unit: str = "") -> str:
    """An uncertain input's scene key in words: material.youngs_modulus_gpa -> "Young's
    modulus E (GPa)" (the set-up table's words where it names the key)."""
    last = key.rsplit(".", 1)[-1]
    words = {k: label for k, label, _, _ in MANIPULATOR_ROWS}.get(last)
    if words is None:
        words = _UNIT_SUFFIX.sub("", last).replace("_", " ")
    return f"{words} ({unit})" if unit and unit not in ("-", "–") else words


def output_label(output: str) -> str:
    """An output of the Sobol' table as a tick label: f1 -> f₁, least x -> least kₓ."""
    if output.startswith("least "):
        return f"least $k_{{{output.split()[-1]}}}$"
    found = re.fullmatch(r"f(\d+)", output)
    return f"$f_{{{found.group(1)}}}$" if found else output


# ---- uncertainty: Sobol' indices -------------------------------------------------------

def has_sobol(record: Mapping[str, Any]) -> bool:
    return any(r["total"] is not None for r in record["sobol"])


def _resolved(value: float, error: float | None) -> bool:
    return error is None or error <= abs(value)


def sobol_bars(record: Mapping[str, Any], path: Path) -> None:
    """Per output (f1.., least k_x..), each input's total Sobol' index (a bar with its 95 %
    sampling error) and its first-order index (a diamond); an index whose error exceeds it is
    drawn hatched grey (bar) or grey (diamond): not resolved from zero."""
    rows = [r for r in record["sobol"] if r["total"] is not None]
    if not rows:
        raise ValueError("no Sobol' index to draw")
    outputs = list(dict.fromkeys(r["output"] for r in rows))
    keys = list(dict.fromkeys(r["key"] for r in rows))
    units = {i["key"]: i["unit"] for i in record["inputs"]}
    width = 0.8 / len(keys)
    fig, ax = plt.subplots(figsize=(WIDTH, 2.9))
    unresolved = False
    for k, key in enumerate(keys):
        colour = SETTING_COLOURS[k % len(SETTING_COLOURS)]
        for j, output in enumerate(outputs):
            row = next((r for r in rows if r["key"] == key and r["output"] == output), None)
            if row is None:
                continue
            x = j + (k - (len(keys) - 1) / 2) * width
            total, error = row["total"], row["total_error"]
            seen = _resolved(total, error)
            unresolved |= not seen
            ax.bar(x, total, width * 0.88, color=colour if seen else "none",
                   edgecolor=colour if seen else UNRESOLVED, hatch=None if seen else "/////",
                   lw=0.6, yerr=error or 0.0, capsize=1.5,
                   error_kw=dict(lw=0.7, ecolor="0.15" if seen else UNRESOLVED))
            first = row["first"]
            if first is not None:
                seen = _resolved(first, row["first_error"])
                unresolved |= not seen
                ax.plot([x], [first], "D", ms=3.2, mfc="white", mew=0.9,
                        mec=colour if seen else UNRESOLVED, zorder=4)
    ax.axhline(0, color="0.3", lw=0.6)
    ax.set_xticks(range(len(outputs)), [output_label(o) for o in outputs])
    ax.set_xlim(-0.5, len(outputs) - 0.5)
    ax.set_ylabel("Sobol' index (–)")
    ax.set_xlabel("output: k-th lowest frequency, or least dynamic stiffness along a direction")
    ax.grid(axis="x", visible=False)
    handles: list[Any] = [Patch(color=SETTING_COLOURS[k % len(SETTING_COLOURS)],
                                label=input_label(key, units.get(key, "")))
                          for k, key in enumerate(keys)]
    handles.append(Line2D([], [], ls="none", marker="D", ms=3.5, mfc="white", mec="0.2",
                          label="first-order index"))
    if unresolved:
        handles.append(Patch(facecolor="none", edgecolor=UNRESOLVED, hatch="/////",
                             label="below its sampling error (not resolved)"))
    fig.legend(handles=handles, loc="lower center", ncol=3, frameon=False, fontsize=6.8,
               bbox_to_anchor=(0.5, 0.0))
    fig.tight_layout(rect=(0, 0.07 * (1 + (len(handles) - 1) // 3), 1, 1))
    save(fig, path)


def sobol_caption(case: Mapping[str, Any], record: Mapping[str, Any]) -> str:
    return (f"{case['description']} ({case['name']}): what drives the spread of each output "
            "(f_k: the k-th lowest frequency; least k_d: the least dynamic stiffness at the "
            "tool along d). Bars: each input's total Sobol' index (the share of the output's "
            "variance it explains with its interactions, –) with its 95 % sampling error; "
            "diamonds: its first-order index (without interactions). An index smaller than "
            "its sampling error is not resolved from zero and is drawn hatched grey (bar) or "
            f"grey (diamond), its error bar kept. {record['design']}; {record['model']}.")


# ---- uncertainty: V&V 20 and the spread of the frequencies -----------------------------

def has_validation(record: Mapping[str, Any]) -> bool:
    return bool(record["validation"] or record["modes"])


def validation_spread(record: Mapping[str, Any], path: Path) -> None:
    """Left: V&V 20 per FEM mode, the comparison error E (model - FEM, %) with +-u_val
    (thick) and +-2 u_val (thin, the verdict's bound). Right: per mode the 2.5..97.5 % band
    of the frequency over the inputs and its mean, relative to the scene's value (%)."""
    rows, modes = record["validation"], record["modes"]
    panels = [p for p, held in (("vv", rows), ("spread", modes)) if held]
    if not panels:
        raise ValueError("no V&V 20 row and no frequency statistics to draw")
    fig, axes = plt.subplots(1, len(panels), figsize=(WIDTH, 2.7), squeeze=False)
    for ax, kind in zip(axes[0], panels):
        if kind == "vv":
            x = np.array([r["fem_mode"] for r in rows], float)
            e = np.array([r["e_percent"] for r in rows], float)
            u = np.array([r["u_val_percent"] for r in rows], float)
            ax.errorbar(x, e, yerr=2 * u, fmt="none", ecolor="0.6", elinewidth=0.8,
                        capsize=3, label="± 2 u_val (the verdict's bound)")
            ax.errorbar(x, e, yerr=u, fmt="o", ms=4, color=SETTING_COLOURS[0],
                        elinewidth=2.2, capsize=0, label="E ± u_val")
            ax.set_xlabel("FEM mode (–)")
            ax.set_ylabel("E = model − FEM (%)")
            ax.set_title("V&V 20: the model against the FEM", loc="left")
        else:
            x = np.array([m["mode"] for m in modes], float)
            nominal = np.array([m["nominal_hz"] for m in modes], float)
            lo = 100 * (np.array([m["q025_hz"] for m in modes]) / nominal - 1)
            hi = 100 * (np.array([m["q975_hz"] for m in modes]) / nominal - 1)
            mean = 100 * (np.array([m["mean_hz"] for m in modes]) / nominal - 1)
            ax.bar(x, hi - lo, 0.5, bottom=lo, color=BAND_COLOUR, alpha=0.3, lw=0,
                   label="2.5–97.5 % of the samples")
            ax.plot(x, mean, "_", ms=9, mew=1.6, color=BAND_COLOUR, ls="none", label="mean")
            ax.set_xlabel("k-th lowest frequency (–)")
            ax.set_ylabel("frequency − scene's value (%)")
            ax.set_title("spread of the frequencies over the inputs", loc="left")
        ax.axhline(0, color="0.3", lw=0.7)
        ax.set_xticks(x)
        ax.legend(frameon=False, loc="upper center", bbox_to_anchor=(0.5, -0.22), ncol=2,
                  fontsize=6.5)
    fig.tight_layout()
    save(fig, path)


def validation_caption(case: Mapping[str, Any], record: Mapping[str, Any]) -> str:
    both = bool(record["validation"] and record["modes"])
    parts = []
    if record["validation"]:
        parts.append(("left, " if both else "")
                     + "V&V 20 per FEM mode: the comparison error E of the analytical model "
                     "against the FEM (%) with its validation uncertainty u_val (thick bar, the "
                     "FEM's numerical and the input uncertainty, %) and 2 u_val (thin bar: an E "
                     "inside it does not matter at these tolerances)")
    if record["modes"]:
        parts.append(("right, " if both else "")
                     + "per mode, the 2.5–97.5 % band of the frequency over the uncertain "
                     "inputs and its mean, relative to the frequency at the scene's values "
                     f"(%), from {record['runs']} model runs")
    return (f"{case['description']} ({case['name']}): {'; '.join(parts)} "
            f"({record['model']}).")


# ---- uncertainty along the worst path --------------------------------------------------

def path_band(record: Mapping[str, Any], path: Path) -> None:
    """Along the worst path (one pose per layer): f1 at the scene's values and its 95 % band;
    beside it the least dynamic stiffness at the tool (log) where the record holds it."""
    poses = record["poses"]
    if not poses:
        raise ValueError("the path has no pose")
    stiffness = any(p["least_nominal_n_per_m"] is not None for p in poses)
    fig, axes = plt.subplots(1, 2 if stiffness else 1, figsize=(WIDTH if stiffness else
                                                                 WIDTH * 0.6, 2.5),
                             squeeze=False)
    z = _floats(p["height_mm"] for p in poses)
    panels = [("f1", "_hz", "first frequency f1 (Hz)", SETTING_COLOURS[0])]
    if stiffness:
        panels.append(("least", "_n_per_m", "least dynamic stiffness (N/m)", FEM_COLOUR))
    for ax, (name, unit, label, colour) in zip(axes[0], panels):
        nominal = _floats(p[f"{name}_nominal{unit}"] for p in poses)
        lo = _floats(p[f"{name}_q025{unit}"] for p in poses)
        hi = _floats(p[f"{name}_q975{unit}"] for p in poses)
        ax.fill_between(z, lo, hi, color=BAND_COLOUR, alpha=0.2, lw=0,
                        label="95 % band of the inputs")
        ax.plot(z, nominal, marker="o", ms=3, lw=1.2, color=colour,
                label="at the scene's values")
        if name == "least":
            ax.set_yscale("log")
        ax.set_xlabel("height of the layer z (mm)")
        ax.set_ylabel(label)
    axes[0, 0].legend(frameon=False, loc="best", fontsize=6.8)
    fig.tight_layout()
    save(fig, path)


def path_caption(record: Mapping[str, Any]) -> str:
    stiffness = any(p["least_nominal_n_per_m"] is not None for p in record["poses"])
    return ("Along the workspace map's worst path (" + record["path"] + "; " + record["model"]
            + "): the first frequency f1 (Hz) at the scene's values (line) and the 95 % band "
            f"of {record['samples']} draws of the uncertain inputs (shaded) against the "
            "height of the layer (mm)" + (", and beside it the least dynamic stiffness at the "
                                          "tool (N/m, log scale), the same way"
                                          if stiffness else "") + ".")
