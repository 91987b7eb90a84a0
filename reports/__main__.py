"""`python -m reports --results out/results.json --out out`: write report.html and report.pdf."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m reports", description=__doc__)
    parser.add_argument("--results", default="out/results.json", type=Path,
                        help="results file written by the pipeline (default: out/results.json)")
    parser.add_argument("--out", default="out", type=Path,
                        help="directory for report.html, report.pdf and figures/ (default: out)")
    args = parser.parse_args(argv)
    from .build import ReportError, build_report
    try:
        html, pdf = build_report(args.results, args.out)
    except ValueError as exc:  # the results file: missing, malformed or outdated
        print(f"error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    except ReportError as exc:  # a picture or the PDF could not be rendered
        print(f"error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 1
    print(f"wrote {html} and {pdf}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
