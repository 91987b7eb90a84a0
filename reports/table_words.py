"""The words of a study's declared tables in the report (`generic_tables`): each column's
header with its unit, each table's caption, what a V&V 20 verdict means. The one place a
column's field name (results.json, the CSVs) meets the words a reader reads."""
from __future__ import annotations

HEADINGS = {
    "case": "case", "model": "model", "mode": "mode", "direction": "direction",
    "kind": "kind", "key": "input", "output": "output", "layer": "layer",
    "fem_mode": "FEM mode", "analytical_mode": "analytical mode",
    "e_percent": "E (%)", "u_num_percent": "u_num (%)", "u_input_percent": "u_input (%)",
    "u_val_percent": "u_val (%)", "verdict": "V&V 20 verdict",
    "nominal_hz": "nominal (Hz)", "mean_hz": "mean (Hz)", "std_hz": "std. dev. (Hz)",
    "cv_percent": "CV (%)", "q025_hz": "2.5 % (Hz)", "q975_hz": "97.5 % (Hz)",
    "mean_error_hz": "± mean (Hz)", "q025_error_hz": "± 2.5 % (Hz)",
    "q975_error_hz": "± 97.5 % (Hz)",
    "first": "first-order index", "first_error": "± first", "total": "total index",
    "total_error": "± total",
    "nominal_n_per_m": "nominal (N/m)", "mean_n_per_m": "mean (N/m)",
    "std_n_per_m": "std. dev. (N/m)", "q025_n_per_m": "2.5 % (N/m)",
    "q975_n_per_m": "97.5 % (N/m)",
    "described": "distribution", "source": "source",
    "height_mm": "height z (mm)", "tilt_deg": "tilt θ (deg)", "azimuth_deg": "azimuth φ (deg)",
    "f1_nominal_hz": "f1 nominal (Hz)", "f1_q025_hz": "f1 2.5 % (Hz)",
    "f1_median_hz": "f1 median (Hz)", "f1_q975_hz": "f1 97.5 % (Hz)",
    "least_nominal_n_per_m": "least stiffness, nominal (N/m)",
    "least_q025_n_per_m": "least stiffness 2.5 % (N/m)",
    "least_median_n_per_m": "least stiffness median (N/m)",
    "least_q975_n_per_m": "least stiffness 97.5 % (N/m)",
    "stiffness_n_per_m": "least stiffness (N/m)", "frequency_hz": "at (Hz)",
    "depth_mm": "least critical depth (mm)", "spindle_rpm": "at speed (rpm)",
    "chatter_frequency_hz": "chatter (Hz)",
    "least_depth_mm": "least critical depth (mm)", "least_rpm": "at speed (rpm)",
    "best_rpm": "best speed (rpm)", "best_depth_mm": "depth there (mm)",
    "error_percent": "error (%)", "fem_error_percent": "FEM mesh error (%)",
    "samples": "machines drawn", "least_q025_mm": "least depth 2.5 % (mm)",
    "least_q025_interval_mm": "its 95 % interval (mm)",
    "least_median_mm": "least depth median (mm)", "least_q975_mm": "least depth 97.5 % (mm)",
    "level_error_percent": "level error (%)", "refused": "not drawn because",
    "fem_direct_hz": "FEM direct (Hz)", "fem_frequency_error_percent": "FEM mesh error (%)",
    "analytical_hz": "analytical (Hz)", "frequency_error_percent": "error (%)",
    "fem_direct_m_per_n": "FEM direct (m/N)", "fem_magnitude_error_percent": "FEM mesh error (%)",
    "analytical_m_per_n": "analytical (m/N)", "magnitude_error_percent": "error (%)",
    "fem_modal_magnitude_error_percent": "FEM modal sum error (%)",
    "fem_m_per_n": "FEM (m/N)", "reason": "why",
    "least_nominal_mm": "least depth, nominal (mm)",
}

CAPTIONS = {
    ("uncertainty", "validation"): "V&V 20 per mode: the comparison error E against the FEM, "
    "the FEM's numerical uncertainty u_num, the model's input uncertainty u_input and their sum "
    "u_val (standard uncertainties, per cent of the frequency)",
    ("uncertainty", "frequencies"): "The frequencies' spread over the input draws: nominal, "
    "mean, standard deviation, coefficient of variation, 2.5 % and 97.5 % quantiles, with the "
    "sampling error (95 %) of the mean and quantiles",
    ("uncertainty", "sobol"): "Sobol' indices: the share of each output's variance an input "
    "explains alone (first order) and with its interactions (total), with their 95 % "
    "sampling errors",
    ("uncertainty", "least_stiffness"): "The least dynamic stiffness at the tool over the "
    "draws, per direction",
    ("uncertainty", "inputs"): "The uncertain inputs: their distributions and sources",
    ("uncertainty_path", "path"): "Along the workspace map's worst path: f1 and the least "
    "dynamic stiffness at the scene's values and their 95 % band over the inputs",
    ("dynamic_stiffness", "least"): "The least dynamic stiffness at the tool over the "
    "workspace map, per direction, and where it occurs",
    ("stability_map", "least"): "The least critical depth over the workspace map, and where it "
    "occurs",
    ("lobes", "least"): "Least critical depth and best speed per model (error against the "
    "FEM's lobes at the same speeds)",
    ("lobes", "band"): "The least critical depth over the speeds, over machines drawn from the "
    "scene's [uncertainty]",
    ("tool_response", "peak_frequencies"): "The receptance's peaks: frequency of each model "
    "against the solid's direct frequency response",
    ("tool_response", "peak_heights"): "The receptance's peaks: height of each model against "
    "the solid's direct frequency response",
    ("tool_response", "static"): "The static compliance at the tool",
    ("tool_response", "unmatched"): "Peaks not paired between the models",
}

# a V&V 20 verdict's opening words, and what it means: said once under the table
VERDICTS = {
    "not resolved": "|E| within 2 u_num: the FEM's own discretisation cannot resolve the "
    "difference",
    "within 2 u_val": "|E| within 2 u_val: at these input and numerical uncertainties the "
    "model's difference from the FEM does not matter",
    "the model's error matters": "|E| beyond 2 u_val: the model's error is larger than "
    "everything that could explain it",
}

UNITS = (("_n_per_m", "N/m"), ("_m_per_n", "m/N"), ("_n_per_um", "N/µm"), ("_percent", "%"),
         ("_hz", "Hz"), ("_mm", "mm"), ("_deg", "deg"), ("_rpm", "rpm"), ("_seconds", "s"),
         ("_kg", "kg"))


def words(column: str) -> str:
    """A column's header: `HEADINGS`' or, for a column not listed, its name in words with its
    unit suffix in brackets."""
    if column in HEADINGS:
        return HEADINGS[column]
    for suffix, unit in UNITS:
        if column.endswith(suffix):
            return f"{column.removesuffix(suffix).replace('_', ' ')} ({unit})"
    return column.replace("_", " ")


def verdict_words(text: str) -> str:
    """A V&V 20 verdict's opening words (`VERDICTS`), the sentence itself if it has none."""
    return next((k for k in VERDICTS if text.startswith(k)), text)
