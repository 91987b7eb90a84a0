"""Verification of the project's own solid FEM against published free-vibration benchmarks
(NAFEMS FV52, FV41 and closed forms), each at three mesh sizes with the project's stated
discretisation error. `from verification import CASES, run_case, run_all`."""
from __future__ import annotations

from .run import CASES, run_all, run_case

__all__ = ["CASES", "run_all", "run_case"]
