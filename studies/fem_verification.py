"""Scene study: the solid FEM, the referee of every comparison, checked against published
free-vibration benchmarks (`verification/`: NAFEMS FV52 and FV41, closed forms of the torsion
of a tube and of a thin ring's flexure, a free-free solid) at three mesh sizes each, with the
deviation from each reference, the observed order and the project's stated error
(results.studies.fem_verification).

The benchmarks do not depend on the scene: the record is computed once per version of the FEM
code (the result cache keys it by the sources of `verification/` and the model packages) and
then read back, so a run pays for it only when the referee itself changed.
"""
from __future__ import annotations

from typing import cast

import results
from runtime.cache import ResultCache

from .registry import OWN_TEMPLATE, Context, Section, Study, own

# beyond the model packages: the benchmarks, the record's schema and this module
MODULES = ("verification", "results", "studies.fem_verification")


def verification_record(cache: ResultCache, progress=None) -> results.FemVerification:
    """results.FemVerification ({"cases", "passed", "seconds"}), through the result cache."""
    from verification import run_all

    value, _, _ = cache.get_or_compute("fem-verification", {}, lambda: (run_all(progress), {}),
                                       required=("cases", "passed", "seconds"), modules=MODULES)
    return cast(results.FemVerification, value)  # the run checks it against its type


def run(ctx: Context) -> results.FemVerification:
    return verification_record(ctx.cache)


STUDY = Study(own("fem_verification", "scene", section=Section(
    "verification", "Verifying the referee: published benchmarks",
    "verification of the FEM against published benchmarks", OWN_TEMPLATE), tables=(results.Table(
        "benchmarks", ("name", "discretisation", "tolerance_percent", "passed"),
        each="cases"),)), "scene", run)
