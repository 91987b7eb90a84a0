"""The report's pictures and tables of a real machine (issue 23): the leg's profile, and what sets
the lowest modes (the drive's stiffness swept, the strain energy by part). Drawn from
results.json values only."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from results import Results

from .cells import Cells, cell, head
from .figures import MODE_COLOURS, WIDTH, plt, save

PARTS = (("legs", "legs"), ("joints", "joint springs"), ("drive", "drive"),
         ("platform", "platform"))


def leg_profile(manipulator: dict, path: Path) -> None:
    """Half-section of a leg (axis horizontal, base joint at 0) at its shortest and longest:
    the housing and the rod, each solid or hollow; the joint centres and the junction."""
    leg = manipulator["leg"]
    lengths = manipulator["leg_length_range_mm"]
    fig, axes = plt.subplots(2, 1, figsize=(WIDTH, 2.4), sharex=True)
    for ax, length, label in zip(axes, lengths, ("shortest leg", "longest leg")):
        if leg["housing_length_mm"] > 0:
            parts = [(0.0, leg["housing_length_mm"], leg["housing_outer_diameter_mm"],
                      leg["housing_inner_diameter_mm"], "housing", "0.55"),
                     (leg["housing_length_mm"], length, leg["rod_outer_diameter_mm"],
                      leg["rod_inner_diameter_mm"], "rod", "0.8")]
        else:
            parts = [(0.0, length, manipulator["leg_diameter_mm"], 0.0, "leg", "0.7")]
        for start, end, outer, inner, name, shade in parts:
            for sign in (1, -1):
                ax.fill_between([start, end], sign * inner / 2, sign * outer / 2, color=shade,
                                lw=0)
            ax.text(0.5 * (start + end), 0, name, ha="center", va="center", fontsize=7)
        ax.plot([0, length], [0, 0], "k-.", lw=0.6)
        ax.plot([0, length], [0, 0], "ko", ms=3)
        ax.set_ylabel("r (mm)")
        ax.set_title(f"{label}: {length:g} mm, joint to joint", loc="left")
        ax.set_aspect("equal")
    axes[-1].set_xlabel("along the leg from the base joint (mm)")
    save(fig, path)


def stiffness_sweep(study: dict, path: Path) -> None:
    """f1-f6 of both models against the drive's stiffness (log), the rigid drive's as dashed
    lines, the scene's value and each mode's knee (a cross at 1/sqrt(2) of its rigid-drive
    frequency) marked."""
    sweep = study["sweep"]
    k = np.array([p["actuator_n_per_um"] for p in sweep])
    fig, ax = plt.subplots(figsize=(WIDTH, 3.0))
    n = len(sweep[0]["analytical_hz"])
    for j in range(n):
        colour = MODE_COLOURS[j % len(MODE_COLOURS)]
        ax.plot(k, [p["analytical_hz"][j] for p in sweep], "-", color=colour, lw=1.2,
                label=f"$f_{j + 1}$")
        ax.plot(k, [p["fem_hz"][j] for p in sweep], "o", color=colour, ms=3, mfc="none")
        if study["rigid_drive"]:
            ax.axhline(study["rigid_drive"]["analytical_hz"][j], color=colour, lw=0.6, ls="--")
    scene = sweep[0]["actuator_n_per_um"] / sweep[0]["factor"]  # the scene's own k_a
    ax.axvline(scene, color="0.3", lw=0.8, ls=":")
    ax.text(scene, ax.get_ylim()[1], " the scene's", va="top", fontsize=7)
    for j, k_knee in enumerate(study["knee_n_per_um"]):  # each mode's knee, on its line
        if k_knee is not None and study["rigid_drive"]:
            ax.plot([k_knee], [study["rigid_drive"]["analytical_hz"][j] / np.sqrt(2.0)], "x",
                    color=MODE_COLOURS[j % len(MODE_COLOURS)], ms=6)
    ax.set_xscale("log")
    ax.set_xlabel("drive axial stiffness $k_a$ (N/µm)")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(f"{study['case']}: lines the analytical model, circles the FEM, dashed the "
                 "rigid drive, crosses the knees", loc="left")
    ax.legend(ncol=3, frameon=False, loc="lower right")
    save(fig, path)


def sweep_table(results: Results, c: Cells, ci: int) -> dict:
    """The sweep of one case: per stiffness, both models' f1.. and the largest |error|."""
    study = results["studies"]["lowest_modes"][ci]
    q = f"/studies/lowest_modes/{ci}"
    points = [("rigid_drive", study["rigid_drive"])] if study["rigid_drive"] else []
    points += [(f"sweep/{j}", p) for j, p in enumerate(study["sweep"])]
    n = len(study["sweep"][0]["analytical_hz"]) if study["sweep"] else 0
    rows = []
    for where, p in points:
        row = [cell("rigid", "text") if p["factor"] is None else c.num(f"{q}/{where}/factor", None),
               cell("∞", "num") if p["factor"] is None
               else c.num(f"{q}/{where}/actuator_n_per_um", None)]
        row += [c.num(f"{q}/{where}/fem_hz/{k}", 2) for k in range(n)]
        row += [c.num(f"{q}/{where}/error_percent/{k}", 3, signed=True) for k in range(n)]
        rows.append(row)
    return {"case": study["case"], "cls": "jointorders", "rows": rows, "head": [
        head("k_a / scene's", "k_a (N/µm)", *[f"FEM f{k + 1} (Hz)" for k in range(n)],
             *[f"error f{k + 1} (%)" for k in range(n)])]}


def shares_table(results: Results, c: Cells, ci: int) -> dict:
    """Where each mode's strain energy lies, at the scene's stiffness."""
    study = results["studies"]["lowest_modes"][ci]
    q = f"/studies/lowest_modes/{ci}/shares"
    rows = []
    for j, s in enumerate(study["shares"]):
        rows.append([cell(f"f{s['mode']}", "text"), c.num(f"{q}/{j}/frequency_hz", 2)]
                    + [c.num(f"{q}/{j}/{part}_percent", 1) for part, _ in PARTS]
                    + [c.text(f"{q}/{j}/largest")])
    return {"case": study["case"], "cls": "params", "rows": rows, "head": [
        head("mode", "analytical (Hz)", *[f"{label} (%)" for _, label in PARTS], "largest")]}
