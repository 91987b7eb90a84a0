"""Bars on the code itself: no case of any scene is named in code (cases come from the scene),
and every report module stays small enough to read in one sitting."""
from __future__ import annotations

import re
from pathlib import Path

from tests.test_architecture import ROOMS

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = tuple(ROOMS)  # every room: the list is declared once (tests/test_architecture.py)


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


def test_the_fem_takes_only_the_pose_geometry_from_the_analytical_model():
    """The referee shares the kinematics with the model it checks, never model code
    (two models that check each other must not share physics code: common/README.md)."""
    allowed = re.compile(r"from analytical\.kinematics import|import analytical\.kinematics")
    shared = re.compile(r"common\.plate|common import plate")
    found = [f"{path.relative_to(ROOT)}:{n}: {line.strip()}"
             for package in ("fem_reference", "meshing")
             for path in sorted((ROOT / package).rglob("*.py"))
             for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
             if (re.search(r"\b(from|import) analytical\b", line) and not allowed.search(line))
             or shared.search(line)]
    assert not found, found
