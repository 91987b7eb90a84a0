"""The tables of one case: the comparison of both models (with the paper's rows where the case
has them), the analytical model variants, the FEM idealisations and the FEM's mesh-refinement
sequence."""
from __future__ import annotations

from results import Case, Pair, Results

from .cells import Cells, cell, head, missing
from .results import escape


def _by_mode(pairs: list[Pair]) -> list[int]:
    return sorted(range(len(pairs)), key=lambda j: pairs[j]["fem_mode"])


def comparison_table(results: Results, i: int, c: Cells) -> dict:
    """Mode by mode: the paper's rows (where the case has them), our FEM with its estimated
    error, our analytical model, the errors and the MAC."""
    case = results["cases"][i]
    has_paper = case["paper"] is not None
    has_ref = any(p["fem_estimated_error_percent"] is not None for p in case["pairs"])
    has_vs_ref = any(p["error_vs_reference_percent"] is not None for p in case["pairs"])
    labels = ["FEM mode", "model mode"]
    if has_paper:
        labels += ["paper FEA (Hz)", "paper theory (Hz)", "paper error (%)"]
    labels += ["our FEM (Hz)"] + (["FEM est. error (%)"] if has_ref else [])
    labels += ["our analytical (Hz)", "error vs FEM (%)"]
    labels += (["error vs FEM limit (%)"] if has_vs_ref else []) + ["MAC"]
    rows = []
    for j in _by_mode(case["pairs"]):
        pair = case["pairs"][j]
        k = pair["fem_mode"] - 1
        q = f"/cases/{i}/pairs/{j}"
        first = c.num(f"{q}/fem_mode", None)
        first["suffix"] = "†" if pair["repeated"] else ""
        row = [first, c.num(f"{q}/analytical_mode", None)]
        if has_paper:
            p = f"/cases/{i}/paper"
            row += [c.num(f"{p}/fea_hz/{k}", 2), c.num(f"{p}/theory_hz/{k}", 2),
                    c.num(f"{p}/error_percent/{k}", 2, signed=True)]
        row += [c.num(f"{q}/f_fem_hz", 2)]
        if has_ref:
            row += [c.num(f"{q}/fem_estimated_error_percent", 3)]
        row += [c.num(f"{q}/f_analytical_hz", 2), c.num(f"{q}/error_percent", 2, signed=True)]
        if has_vs_ref:
            row += [c.num(f"{q}/error_vs_reference_percent", 2, signed=True)]
        rows.append(row + [c.num(f"{q}/mac", 3)])
    return {"head": [head(*labels)], "rows": rows, "cls": "compare",
            "repeated": any(p["repeated"] for p in case["pairs"])}


VARIANTS_PER_TABLE = 5  # variant column pairs a table: the page's width at 7.8 pt


def variants_tables(results: Results, i: int, c: Cells) -> list[dict]:
    """Every analytical model variant's frequency and error, FEM mode by FEM mode, in tables
    of at most VARIANTS_PER_TABLE variants each (nothing past the page)."""
    labels = list(results["cases"][i]["models"] or {})
    return [_variants_table(results, i, c, labels[k:k + VARIANTS_PER_TABLE])
            for k in range(0, len(labels), VARIANTS_PER_TABLE)]


def _variants_table(results: Results, i: int, c: Cells, labels: list[str]) -> dict:
    case = results["cases"][i]
    models = case["models"] or {}
    rows = []
    for j in _by_mode(case["pairs"]):
        mode = case["pairs"][j]["fem_mode"]
        row = [c.num(f"/cases/{i}/pairs/{j}/fem_mode", None),
               c.num(f"/cases/{i}/pairs/{j}/f_fem_hz", 2)]
        for label in labels:
            jj = next((n for n, p in enumerate(models[label]["pairs"])
                       if p["fem_mode"] == mode), None)
            q = f"/cases/{i}/models/{escape(label)}/pairs/{jj}"
            row += ([missing()] * 2 if jj is None else
                    [c.num(f"{q}/f_analytical_hz", 2), c.num(f"{q}/error_percent", 2, signed=True)])
        rows.append(row)
    return {"head": [head("FEM", "our FEM", *labels, spans=[1, 1] + [2] * len(labels)),
                     head("mode", "(Hz)", *(["(Hz)", "error (%)"] * len(labels)))],
            "rows": rows, "cls": "variants"}


def fem_variants_table(results: Results, i: int, c: Cells) -> dict | None:
    """The FEM with other joint and platform idealisations: frequencies and shifts."""
    case = results["cases"][i]
    study = case["fem_variants"] or {"variants": {}, "unsolved": {}}
    variants, errors = study["variants"], study["unsolved"]
    if not variants and not errors:
        return None
    n = len(case["fem"]["frequencies_hz"])
    rows: list[dict[str, object]] = []
    for label in variants:
        q = f"/cases/{i}/fem_variants/variants/{escape(label)}"
        rows.append({"label": label, "error": None, "cells": [
            c.text(literal=f"{label}: f (Hz)")] + [c.num(f"{q}/frequencies_hz/{k}", 2)
                                                   for k in range(n)]})
        by_fem = {p["fem_mode"]: j for j, p in enumerate(variants[label]["pairs"])}
        if any(p["analytical_mode"] != p["fem_mode"] for p in variants[label]["pairs"]):
            rows.append({"label": label, "error": None, "cells": [
                c.text(literal="its mode paired with our f_k", cls="text sub")]
                + [c.num(f"{q}/pairs/{by_fem[k + 1]}/analytical_mode", None) if k + 1 in by_fem
                   else c.text(literal="–") for k in range(n)]})
        rows.append({"label": label, "error": None, "cells": [
            c.text(literal="shift vs our FEM (%)", cls="text sub")]
            + [c.num(f"{q}/shift_percent/{k}", 2, signed=True) for k in range(n)]})
    for label in errors:
        rows.append({"label": label, "cells": None,
                     "error": c.text(f"/cases/{i}/fem_variants/unsolved/{escape(label)}")})
    return {"head": [head("FEM idealisation", *[f"f{k + 1}" for k in range(n)])],
            "rows": rows, "cls": "femvariants", "width": n + 1}


def refinement_table(results: Results, i: int, c: Cells) -> dict | None:
    """The FEM at every mesh size, the h -> 0 limit, the observed orders and any status."""
    ref = results["cases"][i]["fem_refinement"]
    if not ref:
        return None
    n = len(ref["frequencies_hz"][0])
    q = f"/cases/{i}/fem_refinement"
    labels = ["h (mm)", "h eff. (mm)", "dofs", "time (s)"]
    labels += [f"f{k + 1} (Hz)" for k in range(n)] + ["GCI max (%)", "est. error max (%)"]
    rows = [[c.num(f"{q}/mesh_sizes_mm/{r}", 1),
             c.num(f"{q}/effective_mesh_sizes_mm/{r}", 1),
             c.num(f"{q}/dofs/{r}", None), c.num(f"{q}/seconds/{r}", 1)]
            + [c.num(f"{q}/frequencies_hz/{r}/{k}", 2) for k in range(n)]
            + [c.num(f"{q}/gci_percent_max/{r}", 3),
               c.num(f"{q}/estimated_error_percent_max/{r}", 3)]
            for r, _ in enumerate(ref["mesh_sizes_mm"])]

    def extra(label: str, cells: list[dict]) -> list[dict]:
        return [c.text(literal=label, cls="text label")] + [cell("")] * 3 + cells + [cell("")] * 2

    rows.append(extra("h → 0", [c.num(f"{q}/extrapolated_hz/{k}", 2) for k in range(n)]))
    rows.append(extra("order p", [c.num(f"{q}/observed_order/{k}", 2) for k in range(n)]))
    rows.append(extra("GCI: h → 0", [c.num(f"{q}/gci_extrapolated_hz/{k}", 2)
                                     for k in range(n)]))
    rows.append(extra("GCI: order p", [c.num(f"{q}/gci_order/{k}", 2) for k in range(n)]))
    last = len(ref["mesh_sizes_mm"]) - 1
    rows.append(extra("GCI of the finest (%)", [c.sci(f"{q}/gci_percent/{last}/{k}")
                                                for k in range(n)]))
    rows.append(extra("est. error of the finest (%)",
                      [c.sci(f"{q}/estimated_error_percent/{last}/{k}") for k in range(n)]))
    if any(s != "ok" for s in ref["status"]):
        rows.append(extra("status", [c.text(f"{q}/status/{k}", cls="text small")
                                     for k in range(n)]))
    return {"head": [head(*labels)], "rows": rows, "cls": "refinement"}


def repeated_limit_notes(case: Case) -> list[tuple[str, bool]]:
    """(sentence, beyond the estimate) for every repeated FEM pair whose members extrapolate to
    different limits: equal modes have one limit, so the spread is part of the FEM's error."""
    ref = case["fem_refinement"]
    if not ref:
        return []
    groups: dict[int, list[int]] = {}
    for p in case["pairs"]:
        if p["repeated"]:
            groups.setdefault(p["group"], []).append(p["fem_mode"])
    notes = []
    for modes in groups.values():
        modes = sorted(modes)
        limits = [ref["extrapolated_hz"][k - 1] for k in modes]
        if len({f"{f:.3f}" for f in limits}) == 1:  # one limit, as far as printed
            continue
        spread = 100 * (max(limits) / min(limits) - 1)
        estimated = case["fem_estimated_error_percent"]
        if estimated is None:  # indexing None would raise the same
            raise TypeError("a refined case without its FEM's estimated error")
        estimate = min(estimated[k - 1] for k in modes)
        beyond = spread > estimate
        verdict = (f"more than their estimated error ({estimate:.3f} %), so that estimate is "
                   f"too small for this pair" if beyond else
                   f"within their estimated error ({estimate:.3f} %)")
        notes.append((f"FEM modes {' and '.join(map(str, modes))} are a repeated pair (one "
                      f"frequency in the limit) but extrapolate to "
                      f"{' and '.join(f'{f:.3f}' for f in limits)} Hz, {spread:.2g} % apart: "
                      f"{verdict}.", beyond))
    return notes
