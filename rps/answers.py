"""The JSON objects the commands print with --json, declared like the files they write
(`results.outputs.Output`: a record name and schema version first, a strict type, checked
before it is printed; docs/outputs.md lists them). `rps analytical` and `rps fem` have theirs in
results.outputs; these are the command line's own. Imported only when a command prints JSON
(pydantic is an extra)."""
from __future__ import annotations

from pydantic import FiniteFloat, with_config
from typing_extensions import NotRequired, TypedDict

from results import Workspace
from results.outputs import Output
from results.tool_records import OutputPose
from results.types import STRICT


@with_config(STRICT)
class WorkspaceAnswer(Workspace):
    """The frequency map over the regular workspace, its time and the scene's warnings."""
    record: str
    schema: int
    seconds: FiniteFloat
    warnings: list[str]


@with_config(STRICT)
class MinimumAnswer(TypedDict):
    """The least f_K over the reachable workspace (`--minimum K`) and where it is."""
    record: str
    schema: int
    mode: int
    frequency_hz: FiniteFloat
    pose: OutputPose
    on_boundary: bool
    at_band_end: bool
    coarse_grid_hz: FiniteFloat
    poses_solved: int
    settings: str
    seconds: FiniteFloat
    warnings: list[str]


@with_config(STRICT)
class ModesAnswer(TypedDict):
    """The model's modes written at chosen points (`rps modes`), and the sensors suggested."""
    record: str
    schema: int
    case: str
    pose: OutputPose
    out: str  # the UFF file written
    points: int
    frequencies_hz: list[FiniteFloat]
    sensors: NotRequired[str]  # with --suggest: the CSV of the sensor directions kept


@with_config(STRICT)
class CacheKind(TypedDict):
    entries: int
    bytes: int


@with_config(STRICT)
class CacheAnswer(TypedDict):
    """Where the caches are and how big (`rps cache info`)."""
    record: str
    schema: int
    directory: str
    exists: bool
    kinds: dict[str, CacheKind]
    entries: int
    bytes: int


WORKSPACE_ANSWER = Output("rps workspace --json", "workspace", 1, WorkspaceAnswer,
                          "rps workspace --json", "The lowest frequencies over the regular "
                          "workspace (the paper's Fig. 6), each mode followed by its shape.")
MINIMUM_ANSWER = Output("rps workspace --minimum K --json", "workspace-minimum", 1,
                        MinimumAnswer, "rps workspace --minimum K --json",
                        "The least f_K over the whole reachable workspace and its pose.")
MODES_ANSWER = Output("rps modes --json", "modes", 1, ModesAnswer, "rps modes --json",
                      "What `rps modes` wrote: the model's modes at the points as UFF, and "
                      "the sensor directions by effective independence.")
CACHE_ANSWER = Output("rps cache info --json", "cache", 1, CacheAnswer, "rps cache info --json",
                      "The cache directory, its entries and bytes per kind.")
ANSWERS = (WORKSPACE_ANSWER, MINIMUM_ANSWER, MODES_ANSWER, CACHE_ANSWER)
