"""The results file's schema (`out/results.json`), declared once: the pipeline writes it, the
reports read it, the report test fixture is built through it.

Every object is a TypedDict whose keys are all required (a value the run did not compute is
null, never a missing key), checked by pydantic in strict mode with unknown keys rejected:
`validated(results, records)` before writing, `read(path, records)` when reading. The
studies' records (`Studies`, and a `Case` beyond its `CaseCore`) are the keys the registry
of study records declares (`records`: `studies.RECORDS`), each checked against its declared
type: every declared one present, no other. A file of another schema version gets one line
naming its version. Change a field here and bump SCHEMA_VERSION.

Units are in the key names (_hz, _mm, _m, _deg, _percent, seconds); modes are 1-based in
`pairs` and 0-based in lists. Every frequency is finite, positive and at most
MAX_FREQUENCY_HZ; the frequencies of one solve ascend (`Hz`; limits extrapolated from several
solves, and the paper's rows, need not: `Frequencies`). A case name is a name `common.paths`
turns into file names, and no two give the same one; a mode file is named by a relative
path inside the results' folder. Mode shapes are mass-normalised; a platform motion is
[6][mode]: the translation of the platform centre o (m) then the rotation (rad), base axes.
"""
from __future__ import annotations

import json
import re
import stat
from pathlib import Path
from typing import Any, Mapping, Sequence, cast, get_type_hints

import numpy as np
from pydantic import TypeAdapter, ValidationError, with_config
from typing_extensions import TypedDict  # pydantic reads it on Python < 3.12

from common.errors import InputError
from common.paths import UnsafeName, distinct_stems

from .case_records import Case, CaseCore, Environment, SceneSummary
from .declare import Record, Scope, check, in_scope, location, refusal, stub
from .study_records import Fidelity, Studies
from .types import MAX_BYTES, MAX_DEPTH, MAX_TEXT, SCHEMA_VERSION, STRICT, Profile


@with_config(STRICT)
class Results(TypedDict):
    schema: int
    profile: Profile
    scene: SceneSummary
    environment: Environment
    fidelity: Fidelity
    cases: list[Case]
    studies: Studies
    fixture_note: str | None  # set only by the report test fixture


_RESULTS = TypeAdapter(Results)
_CORE = {"studies": frozenset(), "cases": CaseCore.__required_keys__}


def study_type(scope: Scope, key: str) -> Any:
    """The type of one of the project's own study records (`Studies`, `Case`), as its
    `Record` declares it."""
    return get_type_hints(Studies if scope == "scene" else Case, include_extras=True)[key]


def validated(results: Mapping[str, object], records: Sequence[Record],
              where: str = "results", complete: bool = False) -> Results:
    """The results checked against the schema and every study record against its declared
    type (`records`: the registry, `studies.RECORDS`); InputError with one line naming the
    first offending field (and its value). A study key the registry does not declare is
    refused like any other field; a declared one missing is refused too, unless `complete`:
    then it is read as its empty value (the study did not run: a file written before the study
    was declared, such as the report's test fixture)."""
    version = results.get("schema") if isinstance(results, dict) else None
    if version != SCHEMA_VERSION:
        raise InputError(f"{where}: results schema {version!r}, this version reads schema "
                         f"{SCHEMA_VERSION}: rerun `make` to regenerate it")
    long = _long_text(results)
    if long is not None:
        loc, size = long
        raise InputError(f"{where}: {location(loc)}: a text of {size:,} characters, more than "
                         f"the {MAX_TEXT:,} a results file holds in one field")
    scene, case = in_scope(records, "scene"), in_scope(records, "case")
    if complete:
        results = _completed(results, scene, case)
    core, held = _split(results, {r.key for r in scene}, {r.key for r in case}, where)
    try:
        out = _RESULTS.validate_python(core)
    except ValidationError as exc:
        raise refusal(exc, where) from None
    if not out["cases"]:
        raise InputError(f"{where}: cases: the results hold no case")
    try:
        distinct_stems((c["name"] for c in out["cases"]), "case name")
    except UnsafeName as exc:
        raise InputError(f"{where}: cases: {exc}") from None
    out["studies"] = cast(Studies, {  # every key a declared record's, each checked
        r.key: check(r, held[("studies", r.key)], where, ("studies", r.key)) for r in scene})
    for i, entry in enumerate(out["cases"]):
        for r in case:
            entry[r.key] = check(r, held[("cases", i, r.key)], where,  # type: ignore[literal-required]
                                 ("cases", i, r.key))
    return out


def _completed(results: Mapping[str, object], scene: Sequence[Record],
               case: Sequence[Record]) -> dict:
    """The results with every declared record they lack at its empty value (a copy); a
    record that is never empty (a study that always runs) is left missing, to be refused as
    such."""
    scene, case = [r for r in scene if _may_be_empty(r)], [r for r in case if _may_be_empty(r)]
    out: dict[str, Any] = dict(results)
    studies, cases = out.get("studies"), out.get("cases")
    if isinstance(studies, dict):
        out["studies"] = {**stub(scene, "scene"), **studies}
    if isinstance(cases, list):
        out["cases"] = [{**stub(case, "case"), **c} if isinstance(c, dict) else c
                        for c in cases]
    return out


def _may_be_empty(record: Record) -> bool:
    try:
        check(record, record.empty, "results")
    except InputError:
        return False
    return True


def _split(results: Mapping[str, object], scene_keys: set[str], case_keys: set[str], where: str):
    """The results without their study records (checked by the schema's core) and the records
    by place; a study key missing or not declared is refused in one line."""
    held: dict[tuple, object] = {}

    def take(record: object, keys: set[str], at: tuple) -> object:
        if not isinstance(record, dict):
            return record  # the core's check names it
        extra = sorted(set(record) - keys - set(_CORE[at[0]]))
        missing = sorted(keys - set(record))
        if extra:
            raise InputError(f"{where}: {location(at + (extra[0],))}: not a field of the results, "
                             "nor a study this version declares")
        if missing:
            raise InputError(f"{where}: {location(at + (missing[0],))}: field required (the "
                             "record of a declared study)")
        held.update({at + (k,): record[k] for k in keys})
        return {k: v for k, v in record.items() if k not in keys}

    core = dict(results)
    core["studies"] = take(results.get("studies"), scene_keys, ("studies",))
    cases = results.get("cases")
    if isinstance(cases, list):
        core["cases"] = [take(c, case_keys, ("cases", i)) for i, c in enumerate(cases)]
    return core, held


def read(path, records: Sequence[Record]) -> Results:
    """Load and check a results file (`records`: the registry of study records; a declared
    study the file lacks is read as not run, its empty value); InputError (one line, naming
    the path) otherwise."""
    path = Path(path)
    try:
        info = path.stat()
    except FileNotFoundError:
        raise InputError(f"{path}: results file not found") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read results file ({exc.strerror})") from None
    if not stat.S_ISREG(info.st_mode):
        raise InputError(f"{path}: not a regular file (a results file is one)")
    if info.st_size > MAX_BYTES:
        raise InputError(f"{path}: {info.st_size / 1e6:.1f} MB, larger than any results file "
                         f"({MAX_BYTES / 1e6:g} MB at most): not read")
    try:
        with path.open("rb") as handle:  # at most MAX_BYTES, whatever stat said
            data = handle.read(MAX_BYTES + 1)
        if len(data) > MAX_BYTES:
            raise InputError(f"{path}: larger than any results file ({MAX_BYTES / 1e6:g} MB "
                             "at most): not read")
        text = data.decode("utf-8")
    except FileNotFoundError:
        raise InputError(f"{path}: results file not found") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read results file ({exc.strerror})") from None
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: not a results file (byte {exc.start} is not UTF-8 text)") \
            from None
    depth = nesting_depth(text)
    if depth > MAX_DEPTH:
        raise InputError(f"{path}: not a results file (JSON nested {depth} deep; a results "
                         f"file nests {MAX_DEPTH} at most)")
    try:
        raw = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: not valid JSON (line {exc.lineno}, column {exc.colno}: "
                         f"{exc.msg})") from None
    if not isinstance(raw, dict):
        raise InputError(f"{path}: expected a JSON object at the top level")
    return validated(raw, records, str(path), complete=True)


def nesting_depth(text: str) -> int:
    """How deep the arrays and objects of a JSON text nest (brackets inside strings ignored),
    found in one linear scan without parsing, so no nesting can exhaust the parser's stack."""
    bare = _STRINGS.sub("", text).encode("utf-8", "replace")
    codes = np.frombuffer(bare, np.uint8)
    step = np.isin(codes, _OPEN).astype(np.int64) - np.isin(codes, _CLOSE)
    return int(np.cumsum(step).max(initial=0))


_STRINGS = re.compile(r'"[^"\\]*(?:\\.[^"\\]*)*"?', re.DOTALL)  # unrolled: linear, fast
_OPEN, _CLOSE = (np.frombuffer(b"[{", np.uint8), np.frombuffer(b"]}", np.uint8))


def dumps(results: Results) -> str:
    return json.dumps(results, indent=1, allow_nan=False) + "\n"


def _long_text(value, loc=()) -> tuple[tuple, int] | None:
    """(where, length) of the first string longer than MAX_TEXT, or None (iterative: a file's
    nesting is bounded by MAX_DEPTH before it is parsed)."""
    stack = [(value, loc)]
    while stack:
        item, at = stack.pop()
        if isinstance(item, str):
            if len(item) > MAX_TEXT:
                return at, len(item)
        elif isinstance(item, dict):
            stack.extend((v, at + (str(k),)) for k, v in item.items())
            stack.extend((k, at + ("(key)",)) for k in item if len(str(k)) > MAX_TEXT)
        elif isinstance(item, list):
            stack.extend((v, at + (i,)) for i, v in enumerate(item) if isinstance(v, (str, dict,
                                                                                        list)))
    return None
