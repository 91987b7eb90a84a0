"""`python -m reports --results out/results.json --out out`: write report.html and report.pdf.

Bad input (a missing or malformed results file, an unusable output directory, a mode file that
cannot be drawn) is one line on stderr and exit status 2; an interruption (Ctrl-C, SIGTERM)
leaves the output directory as it was and exits 130.
"""
from __future__ import annotations

import argparse
import re
import signal
import sys

from common.errors import RpsError
from common.messages import EXIT_BAD_INPUT, failed
from runtime.places import path_argument


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # noqa: D401 - argparse hook: one line, exit 2
        message = re.sub(r"^argument (--[\w-]+): '", r"\1 '", message)  # a refused value
        where = "" if message.startswith("--") else f"{self.prog}: "
        self.exit(EXIT_BAD_INPUT, f"error: {where}{message}\n")


def _terminate(signum, frame):
    raise KeyboardInterrupt


def main(argv: list[str] | None = None) -> int:
    parser = _Parser(prog="python -m reports", description=__doc__)
    parser.add_argument("--results", default="out/results.json", type=path_argument,
                        help="results file written by the pipeline (default: out/results.json)")
    parser.add_argument("--out", default="out", type=path_argument,
                        help="directory for report.html, report.pdf and figures/ (default: out)")
    args = parser.parse_args(argv)
    previous = signal.signal(signal.SIGTERM, _terminate)
    from .build import build_report
    try:
        html, pdf = build_report(args.results, args.out)
    except (KeyboardInterrupt, RpsError, OSError) as exc:  # anything else is a bug: traceback
        return failed(exc, interrupted="the output directory was left as it was")
    finally:
        signal.signal(signal.SIGTERM, previous)
    print(f"wrote {html} and {pdf}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
