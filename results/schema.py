"""The results file's schema (`out/results.json`), declared once: the pipeline writes it, the
reports read it, the report test fixture is built through it.

Every object is a TypedDict whose keys are all required (a value the run did not compute is
null, never a missing key), checked by pydantic in strict mode with unknown keys rejected:
`validated(results)` before writing, `read(path)` when reading. A file of another schema
version gets one line naming its version. Change a field here and bump SCHEMA_VERSION.

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
from typing import Literal

import numpy as np
from pydantic import TypeAdapter, ValidationError, with_config
from typing_extensions import TypedDict  # pydantic reads it on Python < 3.12

from common.errors import InputError
from common.paths import UnsafeName, distinct_stems

from .case_records import Case, Environment, SceneSummary
from .study_records import Fidelity, Studies
from .types import MAX_BYTES, MAX_DEPTH, MAX_TEXT, SCHEMA_VERSION, STRICT


@with_config(STRICT)
class Results(TypedDict):
    schema: int
    profile: Literal["full", "ci"]
    scene: SceneSummary
    environment: Environment
    fidelity: Fidelity
    cases: list[Case]
    studies: Studies
    fixture_note: str | None  # set only by the report test fixture


_RESULTS = TypeAdapter(Results)


def validated(results: dict, where: str = "results") -> Results:
    """The results checked against the schema; ValueError with one line naming the first
    offending field (and its value)."""
    version = results.get("schema") if isinstance(results, dict) else None
    if version != SCHEMA_VERSION:
        raise InputError(f"{where}: results schema {version!r}, this version reads schema "
                         f"{SCHEMA_VERSION}: rerun `make` to regenerate it")
    long = _long_text(results)
    if long is not None:
        loc, size = long
        raise InputError(f"{where}: {_location(loc)}: a text of {size:,} characters, more than "
                         f"the {MAX_TEXT:,} a results file holds in one field")
    try:
        out = _RESULTS.validate_python(results)
    except ValidationError as exc:
        errors = exc.errors(include_url=False)
        first = errors[0]
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        value = "" if first["type"] == "missing" else f", got {_short(first.get('input'))}"
        message = first["msg"].removeprefix("Value error, ")
        raise InputError(f"{where}: {_location(first['loc'])}: {message[:1].lower()}"
                         f"{message[1:]}{value}{more}") from None
    if not out["cases"]:
        raise InputError(f"{where}: cases: the results hold no case")
    try:
        distinct_stems((case["name"] for case in out["cases"]), "case name")
    except UnsafeName as exc:
        raise InputError(f"{where}: cases: {exc}") from None
    return out


def read(path) -> Results:
    """Load and check a results file; ValueError (one line, naming the path) otherwise."""
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
    return validated(raw, str(path))


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


def _location(loc) -> str:
    text = ""
    for token in loc:
        text += f"[{token}]" if isinstance(token, int) else (f".{token}" if text else token)
    return text


def _short(value, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."
