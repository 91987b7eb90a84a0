"""The tables of the studies across cases: speed vs error, both joint orders, and the
paper-reading studies (angle conventions, height calibration) where the results have them."""
from __future__ import annotations

from results import Results

from .cells import Cells, cell, head, missing
from .results import escape


def speed_table(results: Results, c: Cells) -> dict | None:
    """Time per pose and worst error of every setting, one column pair per case."""
    with_data = [(i, case) for i, case in enumerate(results["cases"]) if case["speed_vs_error"]]
    if not with_data:
        return None
    settings: list[tuple[str, str]] = []
    for _, case in with_data:
        for e in case["speed_vs_error"] or []:  # with_data: never None
            if (e["model"], e["setting"]) not in settings:
                settings.append((e["model"], e["setting"]))
    rows = []
    for model, setting in settings:
        row = [c.text(literal=model), c.text(literal=setting)]
        for i, case in with_data:
            j = next((n for n, e in enumerate(case["speed_vs_error"] or [])
                      if (e["model"], e["setting"]) == (model, setting)), None)
            q = f"/cases/{i}/speed_vs_error/{j}"
            row += ([missing()] * 2 if j is None else
                    [c.num(f"{q}/seconds", None), c.num(f"{q}/worst_error_percent", 2)])
        rows.append(row)
    return {"head": [head("model", "setting", *[case["name"] for _, case in with_data],
                          spans=[1, 1] + [2] * len(with_data)),
                     head("", "", *(["time (s)", "worst error (%)"] * len(with_data)))],
            "rows": rows, "cls": "speed"}


def joint_order_tables(results: Results, c: Cells) -> list[dict]:
    """Per case: both joint orders side by side, the FEM's frequencies and every beam model's
    error against the FEM of the same order."""
    tables = []
    for ci, study in enumerate(results["studies"]["joint_orders"]):
        readings = study["readings"]
        labels = next((list(r["models"]) for r in readings if r["models"]), [])
        n = max((len(r["fem_hz"]) for r in readings if r["fem_hz"]), default=0)
        width = 1 + len(labels)
        rows = []
        for k in range(n):
            row = [cell(f"f{k + 1}", "text")]
            for r, reading in enumerate(readings):
                q = f"/studies/joint_orders/{ci}/readings/{r}"
                if reading["error"] is not None:  # said once, in the first row
                    note = c.text(f"{q}/error", cls="text note") if k == 0 else cell("")
                    row.append(dict(note, colspan=width))
                    continue
                row += [c.num(f"{q}/fem_hz/{k}", 2)]
                row += [c.num(f"{q}/models/{escape(m)}/error_percent/{k}", 2, signed=True)
                        for m in labels]
            rows.append(row)
        titles = [f"{r['base_joint']} at the base, {r['platform_joint']} at the platform"
                  + (" (the scene's)" if r["scene_order"] else "") for r in readings]
        tables.append({"case": study["case"], "cls": "jointorders", "rows": rows, "head": [
            head("mode", *titles, spans=[1] + [width] * len(readings)),
            head("", *(["FEM (Hz)"] + [f"{m} error (%)" for m in labels]) * len(readings))]})
    return tables


def coupling_tables(results: Results, c: Cells) -> list[dict]:
    """Per case: both joint-face couplings side by side, the FEM limit of each and every
    model's error against it (with and without the joint-end model)."""
    tables = []
    for ci, study in enumerate(results["studies"]["joint_couplings"]):
        readings = study["readings"]
        labels = next((list(r["models"]) for r in readings if r["models"]), [])
        n = max((len(r["fem_limit_hz"]) for r in readings if r["fem_limit_hz"]), default=0)
        width = 2 + len(labels)
        rows = []
        for k in range(n):
            row = [cell(f"f{k + 1}", "text")]
            for r, reading in enumerate(readings):
                q = f"/studies/joint_couplings/{ci}/readings/{r}"
                if reading["error"] is not None:
                    note = c.text(f"{q}/error", cls="text note") if k == 0 else cell("")
                    row.append(dict(note, colspan=width))
                    continue
                row += [c.num(f"{q}/fem_limit_hz/{k}", 2),
                        c.num(f"{q}/fem_finest_error_percent/{k}", 3)]
                row += [c.num(f"{q}/models/{escape(m)}/error_percent/{k}", 3, signed=True)
                        for m in labels]
            rows.append(row)
        titles = [f"{r['coupling']} joint faces" + (" (the scene's)" if r["scene_coupling"]
                                                    else "") for r in readings]
        tables.append({"case": study["case"], "cls": "jointorders", "rows": rows, "head": [
            head("mode", *titles, spans=[1] + [width] * len(readings)),
            head("", *(["FEM limit (Hz)", "finest FEM's error (%)"]
                       + [f"{m} (%)" for m in labels]) * len(readings))]})
    return tables


def convention_tables(results: Results, c: Cells) -> list[dict]:
    """Per tilted case with paper rows: every reading of its printed angles and the deviation
    of our analytical frequencies from the paper's theoretical row."""
    tables = []
    for ci, study in enumerate(results["studies"]["angle_conventions"]):
        readings = study["readings"]
        n = max((len(e["frequencies_hz"] or []) for e in readings), default=0)
        best = min((e["worst_percent"] for e in readings if e["worst_percent"] is not None),
                   default=None)
        rows = []
        for j, e in enumerate(readings):
            q = f"/studies/angle_conventions/{ci}/readings/{j}"
            row = [c.text(f"{q}/reading", cls="text reading"), c.num(f"{q}/azimuth_deg", 1),
                   c.num(f"{q}/tilt_deg", 1)]
            if e["frequencies_hz"] is None:
                row.append(c.text(f"{q}/note", cls="text note"))
                row[-1]["colspan"] = n + 1
            else:
                row += [c.num(f"{q}/deviation_percent/{k}", 2, signed=True) for k in range(n)]
                row.append(c.num(f"{q}/worst_percent", 2))
                if e["worst_percent"] == best:
                    row[-1]["cls"] += " best"
            rows.append(row)
        printed = f"(φ, θ) = ({study['azimuth_deg']:g}°, {study['tilt_deg']:g}°)"
        tables.append({"case": study["case"], "cls": "conventions", "rows": rows, "head": [
            head(f"reading of {printed}".replace("-", "−"), "azimuth φ (deg)", "tilt θ (deg)",
                 *[f"f{k + 1} dev. (%)" for k in range(n)], "worst (%)")]})
    return tables


def calibration_table(results: Results, c: Cells) -> dict | None:
    cal = results["studies"]["height_calibration"]
    if not cal:
        return None
    q = "/studies/height_calibration"
    unit = lambda text: c.text(literal=text, cls="unit")  # noqa: E731
    rows = [[c.text(literal="height recomputed from the code"),
             c.num(f"{q}/computed_height_mm", 1), unit("mm")],
            [c.text(literal="height in the scene"), c.num(f"{q}/scene_height_mm", 1), unit("mm")],
            [c.text(literal=f"worst deviation from the paper's theoretical row of {cal['case']}"),
             c.num(f"{q}/worst_deviation_percent", 2), unit("%")]]
    rows += [[c.text(literal=f"deviation of f{k + 1}", cls="text sub"),
              c.num(f"{q}/deviation_percent/{k}", 2, signed=True), unit("%")]
             for k, _ in enumerate(cal["deviation_percent"])]
    return {"head": [head("", "value", "unit")], "rows": rows, "cls": "params"}


def hard_cases_table(results: Results, c: Cells) -> dict | None:
    """Every hard case of the run: what was claimed, its tolerance, what was measured."""
    rows = []
    for k, row in enumerate(results["studies"]["hard_cases"]):
        q = f"/studies/hard_cases/{k}"
        rows.append([c.text(f"{q}/case"), c.text(f"{q}/claim"), c.sci(f"{q}/tolerance"),
                     c.sci(f"{q}/measured"), c.text(f"{q}/unit"),
                     cell("holds" if row["passed"] else "FAILS", "text")])
    if not rows:
        return None
    return {"head": [head("case", "claim", "tolerance", "measured", "unit", "")],
            "rows": rows, "cls": "hardcases"}


def verification_table(results: Results, c: Cells) -> dict | None:
    """Every reference mode of every published benchmark the FEM was run on: the reference,
    the finest mesh's answer, the deviation, the observed order, the stated error, the band."""
    record = results["studies"].get("fem_verification")
    if not record:
        return None
    rows = []
    for i, case in enumerate(record["cases"]):
        q = f"/studies/fem_verification/cases/{i}"
        for k, mode in enumerate(case["modes"]):
            m = f"{q}/modes/{k}"
            fine = len(mode["hz"]) - 1
            verdict = ("passes" if mode["passed"] else "FAILS") if mode["counted"] \
                else "not counted"
            rows.append([c.text(f"{q}/name") if k == 0 else cell("", "text"),
                         c.text(f"{m}/label"), c.num(f"{m}/reference_hz", 3),
                         c.num(f"{m}/hz/{fine}", 3), c.sci(f"{m}/deviation_percent"),
                         c.num(f"{m}/observed_order", 2), c.sci(f"{m}/stated_error_percent"),
                         c.num(f"{m}/tolerance_percent", 3),
                         cell(verdict, "text")])
    return {"head": [head("benchmark", "mode", "reference (Hz)", "FEM, finest (Hz)",
                          "deviation (%)", "order", "stated error (%)", "tolerance (%)", "")],
            "rows": rows, "cls": "verification"}
