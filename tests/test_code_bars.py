"""Bars on the code itself: no case of any scene is named in code (cases come from the scene),
and every report module stays small enough to read in one sitting."""
from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("analytical", "meshing", "fem_reference", "pipeline", "reports")


def test_no_case_name_is_written_in_code():
    named = [f"{path.relative_to(ROOT)}:{n}" for package in PACKAGES
             for path in sorted((ROOT / package).rglob("*")) if path.is_file()
             and path.suffix in (".py", ".j2", ".css")
             for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
             if re.search(r"case[12]", line)]
    assert not named, named


def test_report_modules_stay_under_250_lines():
    long = {p.name: n for p in (ROOT / "reports").glob("*.py")
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > 250}
    assert not long, long
