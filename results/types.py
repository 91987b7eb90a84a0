"""The value types of the results schema and its limits (`results.schema` documents the file).

Every frequency is finite, positive and at most MAX_FREQUENCY_HZ; the frequencies of one solve
ascend (`Hz`; limits extrapolated from several solves, and the paper's rows, need not:
`Frequencies`). A case name is a name `common.paths` turns into file names; a mode file is
named by a relative path inside the results' folder.
"""
from __future__ import annotations

from pathlib import PurePosixPath
from typing import Annotated, Literal

from pydantic import AfterValidator, ConfigDict, Field, FiniteFloat

from common.paths import name_problem

SCHEMA_VERSION = 16
Profile = Literal["full", "ci"]  # a run's profile: every case and study, or the CI's
LOW_MODES = 3  # the paper reads its errors in two ranges: modes 1-3 and the modes above
# No structural mode of a machine the scene ranges admit comes near 1 GHz; a larger value in
# a results file is a doctored or corrupted one (1e308 Hz), never a result.
MAX_FREQUENCY_HZ = 1e9
# A results file nests 9 deep (a case's leg_axis_shapes [leg][station][xyz][mode], the
# workspace maps); one nested deeper than this is refused before it is parsed (`read`), so no
# input reaches the parser's or the validator's recursion limit.
MAX_DEPTH = 32
# The largest results file measured is a few MB (a full run of a shipped scene: 1.9 MB, the
# workspace maps most of it); one above MAX_BYTES is not read. No field of a results file holds
# more text than MAX_TEXT characters (the scene's titles at most 200, its reasons 4000:
# common.settings); a longer one is refused before any report is drawn from it.
MAX_BYTES = 64_000_000
MAX_TEXT = 10_000


def _ascending(values: list[float]) -> list[float]:
    for k in range(1, len(values)):
        if values[k] < values[k - 1]:
            raise ValueError(f"frequencies must ascend, but [{k}] = {values[k]!r} comes after "
                             f"{values[k - 1]!r}")
    return values


def _file_name(name: str) -> str:
    why = name_problem(name)
    if why is not None:
        raise ValueError(f"case name {why}, so it cannot name the case's files")
    return name


def _relative(path: str | None) -> str | None:
    if path is not None and (not path or "\\" in path or "\0" in path
                             or PurePosixPath(path).is_absolute()
                             or ".." in PurePosixPath(path).parts):
        raise ValueError("expected a path relative to the results file, inside its folder")
    return path


Frequency = Annotated[FiniteFloat, Field(gt=0.0, le=MAX_FREQUENCY_HZ)]
Frequencies = list[Frequency]  # several solves' extrapolated limits, the paper's rows
Hz = Annotated[list[Frequency], AfterValidator(_ascending)]  # the modes of one solve
CaseName = Annotated[str, AfterValidator(_file_name)]
RelativePath = Annotated[str | None, AfterValidator(_relative)]
Motion = list[list[FiniteFloat]]  # [6][mode]: translation of o (m), rotation (rad)
STRICT = ConfigDict(extra="forbid", strict=True)
