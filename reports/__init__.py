"""The validation report: out/results.json (+ the FEM mode files it references) -> HTML and PDF.

Reads result files only and never recomputes physics, so a report rebuilds in seconds.
Entry points: `python -m reports --results out/results.json --out out` and
`reports.build.build_report(results_json_path, out_dir)`.
"""
