"""The validation report: out/results.json (+ the FEM mode files it references) -> HTML and PDF.

Reads result files only and never recomputes physics, so a report rebuilds in seconds.
Entry points: `rps report --results out/results.json --out out` and
`reports.build.build_report(results_json_path, out_dir, records=studies.RECORDS)`: the report
is handed the registry of study records (their types, sections and tables), never imports it.
"""
