"""Every JSON file a command writes for a user's script, declared once: its file name, the
record it holds (its `record` name and `schema` version, the file's first two keys), its type
(a strict TypedDict: units in the field names, unknown keys refused), the command that writes
it and what it is for. A file is checked against its declaration when written, before it is
swapped into its folder, and can be read back through the same declaration; docs/outputs.md is
generated from the declarations (`markdown`).

    FRF.write(stage, body)            # stage/frf.json, checked; InputError in one line if not
    data = FRF.read("out/frf.json")   # checked, one line naming the file if not

results.json has its own, stricter machinery (results/schema.py: the study registry); its
declaration is listed here too so that the reference names every file.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from types import UnionType
from typing import Annotated, Any, Iterable, Mapping, Union, get_args, get_origin

from pydantic import FiniteFloat, with_config
from typing_extensions import NotRequired, Required, TypedDict, get_type_hints, is_typeddict

from common.atomic import write_text_atomic
from common.errors import InputError

from .campaign_records import SCHEMA as CAMPAIGN_SCHEMA
from .campaign_records import Correlation, Identification
from .declare import check_type, csv_text
from .lobe_records import LobesFile
from .study_records import FemVerification
from .tool_records import FrfFile, OutputPose
from .types import STRICT
from .uncertainty_records import UncertaintyFile


@dataclass(frozen=True)
class Rows:
    """A CSV table of an output file, declared: one row per item reached by `each` (field
    names and "*" for every item of a list: "poses/*/pairs/*"), one column per (header,
    pointer) of `columns`, the pointer relative to the item ("ci95/0": a list's first item;
    "../name": a field of the item's parent). Written as tables/<record>-<name>.csv."""

    name: str
    each: str
    columns: tuple[tuple[str, str], ...]

    def rows(self, value: Any) -> list[dict[str, Any]]:
        """The table's rows over a file's content (every item `each` reaches, in order)."""
        items: list[tuple[Any, tuple[Any, ...]]] = [(value, ())]  # (item, enclosing objects)
        for token in filter(None, self.each.split("/")):
            items = ([(x, up) for item, up in items for x in item] if token == "*"
                     else [(item[token], (*up, item)) for item, up in items])
        return [{header: _at(item, up, pointer) for header, pointer in self.columns}
                for item, up in items]


def _at(item: Any, enclosing: tuple[Any, ...], pointer: str) -> Any:
    """The value `pointer` names from `item` (each leading "../" climbs to the next object
    enclosing it)."""
    tokens = pointer.split("/")
    up = 0
    while tokens and tokens[0] == "..":
        tokens, up = tokens[1:], up + 1
    value = item if up == 0 else enclosing[-up]
    for token in tokens:
        value = value[int(token)] if isinstance(value, list) else value[token]
    return value


@dataclass(frozen=True)
class Output:
    """One output file's declaration (module docstring)."""

    file: str  # its name in the command's output folder
    record: str  # the value of its "record" key
    schema: int  # the value of its "schema" key: bumped when a field changes
    type: Any  # the TypedDict of the whole file, "record" and "schema" included
    command: str  # what writes it
    doc: str  # what it holds, one paragraph
    tables: tuple[Rows, ...] = ()  # its CSV tables, written beside it by `write`

    def payload(self, body: Mapping[str, Any]) -> dict[str, Any]:
        """The file's content: its record name and schema first, then `body`."""
        return {"record": self.record, "schema": self.schema,
                **{k: v for k, v in body.items() if k not in ("record", "schema")}}

    def checked(self, value: Any, where: str | None = None) -> Any:
        """`value` (the whole file) checked against the declaration and returned as it is;
        InputError naming `where` (default: the file's name) and the first offending field."""
        where = where or self.file
        if not isinstance(value, dict) or value.get("record") != self.record:
            found = value.get("record") if isinstance(value, dict) else None
            raise InputError(f"{where}: not a {self.file} (its record is {found!r}, expected "
                             f"{self.record!r})")
        if value.get("schema") != self.schema:
            raise InputError(f"{where}: {self.file} of schema {value.get('schema')!r}; this "
                             f"version reads schema {self.schema}: write it again")
        check_type(self.type, value, where)
        return value  # as computed, its header first (the checked copy reorders fields)

    def write(self, folder: Path, body: Mapping[str, Any]) -> Path:
        """folder/<file>: `body` with its header, checked, then written atomically; and its
        declared tables as folder/tables/<record>-<name>.csv."""
        path = self.write_to(Path(folder) / self.file, body)
        if self.tables:
            (Path(folder) / "tables").mkdir(exist_ok=True)
            value = self.payload(body)
        for table in self.tables:
            write_text_atomic(Path(folder) / "tables" / f"{self.record}-{table.name}.csv",
                              csv_text(table.rows(value)))
        return path

    def write_to(self, path: Path, body: Mapping[str, Any]) -> Path:
        """`body` with its header, checked, then written atomically to `path`."""
        value = self.payload(body)
        self.checked(value, f"{self.file} (as written by {self.command})")
        try:
            text = json.dumps(value, indent=1, allow_nan=False) + "\n"
        except ValueError as exc:  # a NaN or infinity in a field declared a float
            raise InputError(f"{self.file} (as written by {self.command}): {exc}; not "
                             "written") from None
        write_text_atomic(path, text)
        return path

    def read(self, path: str | Path) -> Any:
        """A file of this declaration, read and checked; InputError (one line) otherwise."""
        path = Path(path)
        try:
            value = json.loads(path.read_text(encoding="utf-8"))
        except OSError as exc:
            raise InputError(f"{path}: cannot be read ({exc.strerror})") from None
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise InputError(f"{path}: not JSON ({' '.join(str(exc).split())})") from None
        return self.checked(value, str(path))


@with_config(STRICT)
class VerificationFile(FemVerification):
    record: str
    schema: int


@with_config(STRICT)
class Answer(TypedDict):
    """What `rps analytical` and `rps fem` print with --json, the fields both share."""
    record: str
    schema: int
    case: str
    pose: OutputPose
    warnings: list[str]  # the scene's (a machine that strains a shared idealisation)
    model: str  # "analytical" or "fem"
    frequencies_hz: list[FiniteFloat]  # ascending
    dofs: int
    seconds: FiniteFloat


@with_config(STRICT)
class AnalyticalAnswer(Answer):
    settings_from: str
    elements: int
    beam: str
    shear: str
    joint_ends: str
    legs: str
    platform_inertia: str
    end_zone_diameters: NotRequired[FiniteFloat]  # with solid joint ends
    leg_lengths_mm: list[FiniteFloat]
    actuation_mm: list[FiniteFloat]


@with_config(STRICT)
class FemAnswer(Answer):
    mesh_size_mm: FiniteFloat
    mesh_size_from: str
    platform: str
    coupling: str
    legs: str
    min_scaled_jacobian: FiniteFloat
    timings: dict[str, FiniteFloat]  # per stage of the solve, s
    refinement_mm: NotRequired[list[FiniteFloat]]  # with --estimate-error: the sizes solved
    estimated_error_percent: NotRequired[list[FiniteFloat]]  # per mode, at the size asked
    extrapolated_hz: NotRequired[list[FiniteFloat | None]]  # the limit h -> 0 per mode
    observed_order: NotRequired[list[FiniteFloat | None]]


FRF = Output("frf.json", "frf", 1, FrfFile, "rps frf",
             "The dynamic compliance at the tool of one pose: the 3x3 receptance over the band "
             "by modal superposition with the residual flexibility of the modes left out, each "
             "mode's frequency, damping and tool shape (a chatter model's input), the peaks and "
             "the least dynamic stiffness per direction. Beside it, frf.unv holds the nine "
             "receptances as UFF 58 for test software.")
UNCERTAINTY = Output(
    "uncertainty.json", "uncertainty", 1, UncertaintyFile, "rps uncertainty",
    "The scene's [uncertainty] propagated through the fast model at one pose: per mode the "
    "statistics of the frequency and the Sobol' indices of every input, each with its "
    "sampling error (and the same for the least dynamic stiffness at the tool).")
def _columns(*names: str) -> tuple[tuple[str, str], ...]:
    """Columns named as the fields they hold."""
    return tuple((n, n) for n in names)


CORRELATION = Output(
    "correlation.json", "correlation", CAMPAIGN_SCHEMA, Correlation, "rps correlate",
    "A modal test campaign against the model: per pose the test's and the model's modes, the "
    "MAC matrix, the pairs by shape and frequency with their errors, the unpaired modes with "
    "the reason, the nodes on their bodies. Beside it, tables/correlation-*.csv.",
    (Rows("pairs", "poses/*/pairs/*", (("pose", "../name"), *_columns(
        "test_mode", "model_mode", "test_hz", "model_hz", "error_percent", "mac",
        "repeated"))),
     Rows("unpaired", "poses/*/unpaired_test_modes/*", (("pose", "../name"), *_columns(
         "test_mode", "test_hz", "reason")))))
IDENTIFICATION = Output(
    "identification.json", "identification", CAMPAIGN_SCHEMA, Identification, "rps identify",
    "Scene keys fitted to a campaign's paired test frequencies: each key's value with its 95 % "
    "interval and whether the data determine it, the fit per mode before and after, the V&V "
    "20 rows, and the correlation after the fit. Beside it, identified.toml (the scene with the "
    "fitted values) and tables/identification-*.csv.",
    (Rows("parameters", "parameters/*", (*_columns(
        "key", "unit", "initial", "value", "identifiable", "at_bound", "relative_std_percent",
        "reason"), ("ci95_low", "ci95/0"), ("ci95_high", "ci95/1"), ("low", "bounds/0"),
        ("high", "bounds/1"))),
     Rows("fit", "fit/*/modes/*", (("pose", "../pose"), *_columns(
         "test_mode", "test_hz", "before_hz", "after_hz", "error_before_percent",
         "error_after_percent", "mac_after"))),
     Rows("validation", "validation/*", _columns(
         "pose", "test_mode", "model_mode", "test_hz", "model_hz", "e_percent",
         "e_identified_percent", "u_num_percent", "u_input_percent", "u_d_percent",
         "u_val_percent", "verdict"))))
VERIFICATION = Output(
    "verification.json", "verification", 1, VerificationFile, "rps verify",
    "The solid FEM against published free-vibration benchmarks, each at three mesh sizes: "
    "per reference mode the answers, the deviation, the observed order and the stated error.")
ANALYTICAL_ANSWER = Output(
    "rps analytical --json", "analytical", 1, AnalyticalAnswer, "rps analytical --json",
    "One JSON object on stdout: the analytical model's frequencies at one pose, its settings "
    "and where they come from, the legs' lengths, and the time it took.")
FEM_ANSWER = Output(
    "rps fem --json", "fem", 1, FemAnswer, "rps fem --json",
    "One JSON object on stdout: the solid FEM's frequencies at one pose, its mesh and its "
    "options; with --estimate-error the refinement study's stated error and limit.")
LOBES = Output(
    "lobes.json", "lobes", 1, LobesFile, "rps lobes",
    "One pose's milling stability lobe diagram: per spindle speed the least axial depth that "
    "chatters, its chatter frequency and kind (Hopf or flip), by semi-discretization (with "
    "its depth at half the intervals and its stated discretisation error) or the zero-order "
    "method, the zero-order estimate beside it, the least depth and the best speed, the cut "
    "and the tool modes it used. Beside it, lobes.png (the diagram) and lobes.csv (one row a "
    "speed).")
OUTPUTS = (FRF, UNCERTAINTY, CORRELATION, IDENTIFICATION, VERIFICATION, LOBES,
           ANALYTICAL_ANSWER, FEM_ANSWER)


# ------------------------------------------------------------------ the reference (generated)
def _name(kind: Any) -> str:
    return getattr(kind, "__name__", str(kind))


def describe(kind: Any) -> tuple[str, list[Any]]:
    """(the type in words, the TypedDicts it holds, to be described in turn)."""
    origin, args = get_origin(kind), get_args(kind)
    if origin in (Required, NotRequired, Annotated):  # FiniteFloat is an Annotated float
        return describe(args[0])
    if origin in (Union, UnionType):
        parts = [describe(a) for a in args if a is not type(None)]
        text = " or ".join(p[0] for p in parts)
        return (text + " or null" if type(None) in args else text,
                [t for p in parts for t in p[1]])
    if origin is list:
        text, inner = describe(args[0])
        return f"list of {text}", inner
    if origin is dict:
        text, inner = describe(args[1])
        return f"map of text to {text}", inner
    if is_typeddict(kind):
        return f"`{kind.__name__}`", [kind]
    if kind is Any:
        return "any", []
    words = {float: "number", int: "integer", str: "text", bool: "true or false"}
    return words.get(kind, _name(kind).lower()), []


def _fields(kind: Any) -> list[tuple[str, str, bool, list[Any]]]:
    hints = get_type_hints(kind, include_extras=True)
    optional: frozenset[str] = getattr(kind, "__optional_keys__", frozenset())
    out = []
    for name, hint in hints.items():
        text, inner = describe(hint)
        out.append((name, text, name in optional or get_origin(hint) is NotRequired, inner))
    return out


def markdown(outputs: Iterable[Output]) -> str:
    """docs/outputs.md: every declared output file, its fields and the objects they hold."""
    lines = ["# Output files", "",
             "Generated from the declarations (`results/outputs.py`, `studies/design.py`, "
             "`pipeline/bench_records.py`)"
             " by `rps scene-docs`; do not edit by hand. Every file below starts with "
             '`"record"` (its name here) and `"schema"` (its version, bumped when a field '
             "changes), is checked against this declaration when written, and can be read "
             "back through it (`Output.read`). Units are in the field names (`_hz`, `_mm`, "
             "`_deg`, `_percent`, `_n_per_m`, `seconds`); a null is a value the command did "
             "not compute; a field marked optional is present only where its note says.", ""]
    for output in outputs:
        lines += [f"## `{output.file}`", "",
                  f"Record `{output.record}`, schema {output.schema}; written by "
                  f"`{output.command}`. {output.doc}", ""]
        lines += [f"- `tables/{output.record}-{t.name}.csv`: one row per `{t.each}`; columns "
                  + ", ".join(f"`{h}`" + ("" if h == p else f" (`{p}`)") for h, p in t.columns)
                  for t in output.tables] + ([""] if output.tables else [])
        done: set[Any] = set()
        queue = [output.type]
        while queue:
            kind = queue.pop(0)
            if kind in done:
                continue
            done.add(kind)
            lines += [f"**`{kind.__name__}`**" + (f": {' '.join(kind.__doc__.split())}"
                                                  if kind.__doc__ and kind is not output.type
                                                  else ""), "",
                      "| field | type |", "|---|---|"]
            for name, text, optional, inner in _fields(kind):
                lines.append(f"| `{name}` | {text}{' (optional)' if optional else ''} |")
                queue += [k for k in inner if k not in done]
            lines.append("")
    return "\n".join(lines).rstrip() + "\n"
