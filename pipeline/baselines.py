"""Golden baselines of the Case 1 and Case 2 error tables at a CI-sized mesh.

`make test` recomputes both tables (analytical model of the scene against the FEM at the
baseline's mesh size) and compares them with tests/baselines/error_tables.json. Updating the
baseline is one explicit command (`make update-baselines`), never automatic.

Tolerances, and why:
- analytical frequencies are dense linear algebra on ~50 coordinates: reproducible to ~1e-10;
- FEM frequencies on the same mesh are reproducible to solver round-off (~1e-9 relative); the
  mesh itself is deterministic for a pinned gmsh version and pinned options;
- so an error percentage that moves by more than ERROR_TOLERANCE_PP (0.02 percentage points,
  i.e. 2e-4 relative in a frequency, ten times below the smallest physical effect the report
  discusses) means the physics or the discretisation changed;
- MAC and subspace cos^2 move by more than MAC_TOLERANCE (0.005) only if a mode shape changed.
"""
from __future__ import annotations

import json
import sys
import tempfile
from dataclasses import replace
from pathlib import Path
from typing import Any, Literal, Mapping

from typing_extensions import TypedDict

from analytical.kinematics import pose_geometry
from common.atomic import write_json_atomic
from common.errors import InputError
from runtime.cache import ResultCache
from scene import load_scene
from solvers.compare import analytical_case, error_table, fem_case, with_cache_dir


class TableRow(TypedDict):
    """One row of a case's error table, as the baseline keeps it."""
    fem_mode: int
    analytical_mode: int
    f_fem_hz: float
    f_analytical_hz: float
    error_percent: float
    mac: float


Tables = dict[str, list[TableRow]]  # case name -> its rows
Compared = Literal["error_percent", "mac", "f_fem_hz", "f_analytical_hz"]


class Baseline(TypedDict):
    """tests/baselines/error_tables.json."""
    scene: str
    mesh_size_mm: float
    analytical: dict[str, object]  # the settings the tables were computed with
    tolerances: dict[str, float]
    cases: Tables


ROOT = Path(__file__).resolve().parents[1]
BASELINE = ROOT / "tests" / "baselines" / "error_tables.json"
ERROR_TOLERANCE_PP = 0.02
MAC_TOLERANCE = 0.005
FREQUENCY_TOLERANCE = 2e-4  # relative, on each model's own frequencies


def compute_tables(scene_path: str | Path, mesh_size: float, cache_dir: Path | None = None,
                   **analytical_overrides) -> Tables:
    """Both cases' tables; with no `cache_dir`, computed afresh in a temporary one.

    `analytical_overrides` (elements, beam, ...) replace the scene's analytical settings.
    """
    if cache_dir is None:
        with tempfile.TemporaryDirectory(prefix="baseline-") as tmp:
            return compute_tables(scene_path, mesh_size, Path(tmp), **analytical_overrides)
    scene = load_scene(scene_path)
    scene = replace(scene, analytical=replace(scene.analytical, **analytical_overrides))
    scene = with_cache_dir(scene, cache_dir)
    cache = ResultCache(cache_dir)
    out: Tables = {}
    for name in scene.ci_cases:
        case = scene.case(name)
        geometry = pose_geometry(scene.manipulator, case.pose)
        fem = fem_case(scene, geometry, cache, mesh_size)
        analytical = analytical_case(scene, case, scene.analytical)
        out[name] = [table_row(row) for row in error_table(analytical, fem,
                                                           scene.analytical.modes)]
    return out


def table_row(pair: Mapping[str, Any]) -> TableRow:
    """The baseline's row of a results.Pair."""
    return TableRow(fem_mode=pair["fem_mode"], analytical_mode=pair["analytical_mode"],
                    f_fem_hz=pair["f_fem_hz"], f_analytical_hz=pair["f_analytical_hz"],
                    error_percent=pair["error_percent"], mac=pair["mac"])


def load_baseline(path: Path = BASELINE) -> Baseline:
    try:
        return json.loads(path.read_text())
    except FileNotFoundError:
        raise InputError(f"no baseline at {path}: run `make update-baselines`") from None


def compare(baseline: Baseline, current: Tables) -> list[str]:
    """Readable lines for every value that moved beyond its tolerance (empty: all fine)."""
    problems = []
    header = f"{'case':6} {'mode':>4} {'quantity':>16} {'baseline':>10} {'now':>10} {'tol':>8}"
    for name, rows in baseline["cases"].items():
        now_rows = current.get(name)
        if now_rows is None or len(now_rows) != len(rows):
            problems.append(f"{name}: table has {0 if now_rows is None else len(now_rows)} "
                            f"rows, baseline {len(rows)}")
            continue
        for old, new in zip(rows, now_rows):
            checks: list[tuple[Compared, float, float]] = [
                ("error_percent", abs(new["error_percent"] - old["error_percent"]),
                 ERROR_TOLERANCE_PP),
                ("mac", abs(new["mac"] - old["mac"]), MAC_TOLERANCE),
                ("f_fem_hz", abs(new["f_fem_hz"] / old["f_fem_hz"] - 1), FREQUENCY_TOLERANCE),
                ("f_analytical_hz", abs(new["f_analytical_hz"] / old["f_analytical_hz"] - 1),
                 FREQUENCY_TOLERANCE),
            ]
            if new["analytical_mode"] != old["analytical_mode"]:
                problems.append(f"{name:6} {old['fem_mode']:>4} {'paired mode':>16} "
                                f"{old['analytical_mode']:>10} {new['analytical_mode']:>10}")
            for quantity, moved, tol in checks:
                if moved > tol:
                    problems.append(f"{name:6} {old['fem_mode']:>4} {quantity:>16} "
                                    f"{old[quantity]:>10.4f} {new[quantity]:>10.4f} {tol:>8g}")
    return [header] + problems if problems else []


def update_command(scene_path: str) -> int:
    """Rewrite the error tables of `scene_path` and the golden results of every shipped scene
    (a CI run of each: a few minutes); explicit, never automatic."""
    scene = load_scene(scene_path)
    size = scene.fem_study.ci_mesh_size
    tables = compute_tables(scene_path, size)
    write_json_atomic(BASELINE, Baseline(
        scene=str(scene_path), mesh_size_mm=size * 1e3,
        analytical={"elements": scene.analytical.elements, "beam": scene.analytical.beam,
                    "platform_inertia": scene.analytical.platform_inertia},
        tolerances={"error_percent_pp": ERROR_TOLERANCE_PP, "mac": MAC_TOLERANCE,
                    "frequency_relative": FREQUENCY_TOLERANCE},
        cases=tables))
    print(f"wrote {BASELINE.relative_to(ROOT)}")
    for path in sorted((ROOT / "scenes").glob("*.toml")):
        print(f"wrote {write_results_golden(path).relative_to(ROOT)}")
    return 0


RESULTS_GOLDENS = ROOT / "tests" / "baselines" / "results"


def write_results_golden(scene_path: Path) -> Path:
    """The digest (`pipeline.digest`) of a fresh CI run of one shipped scene, as its golden."""
    from .digest import digest
    from .run import validate

    with tempfile.TemporaryDirectory() as tmp:
        results = validate(str(scene_path), Path(tmp) / "out", Path(tmp) / "cache",
                           profile="ci")
    target = RESULTS_GOLDENS / f"{Path(scene_path).stem}.json"
    target.parent.mkdir(parents=True, exist_ok=True)
    write_json_atomic(target, digest(results))
    return target


def results_tables(path: str | Path, baseline: Baseline) -> Tables:
    """The error tables of the baseline's cases as a results file holds them (`validate`'s
    results.json); ValueError naming the file when it is unreadable, lacks a case, or was
    computed at another FEM mesh size or with other analytical settings than the baseline."""
    from results import read as load_results
    from studies import RECORDS

    results = load_results(path, RECORDS)
    tables: Tables = {}
    for name in baseline["cases"]:
        case = next((c for c in results["cases"] if c.get("name") == name), None)
        if case is None:
            raise InputError(f"{path}: no case {name!r} (the baselines cover "
                             f"{', '.join(baseline['cases'])})")
        size = case["fem"].get("mesh_size_mm")
        if not isinstance(size, (int, float)) or abs(size / baseline["mesh_size_mm"] - 1) > 1e-9:
            raise InputError(f"{path}: case {name!r} has its FEM at mesh_size_mm = {size!r}, "
                             f"the baselines at {baseline['mesh_size_mm']:g}: not comparable")
        analytical = case["analytical"]  # the model of the case's table (the run's choice)
        for key, value in baseline.get("analytical", {}).items():
            if analytical.get(key) != value:
                raise InputError(f"{path}: analytical {key} = {analytical.get(key)!r}, the "
                                 f"baselines' {value!r}: not comparable")
        try:
            tables[name] = [table_row(row) for row in case["pairs"]]
        except (KeyError, TypeError) as exc:
            raise InputError(f"{path}: case {name!r} pairs lack {exc}") from None
    return tables


def check_command(results: str | None = None) -> int:
    """Compare the error tables with the baseline: recomputed afresh, or read from `results`
    (a results.json at the baseline's mesh size). 0: within tolerance, 1: moved."""
    baseline = load_baseline()
    if results is None:
        current = compute_tables(baseline["scene"], baseline["mesh_size_mm"] * 1e-3)
    else:
        current = results_tables(results, baseline)
    lines = compare(baseline, current)
    if lines:
        print("error tables moved beyond tolerance:", *lines, sep="\n", file=sys.stderr)
        return 1
    print("error tables match the baseline" + (f" ({results})" if results else ""))
    return 0
