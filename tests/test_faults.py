"""Faults (issue 11): nothing lost, nothing mixed.

Two runs on one out/, a failure inside the final swap, an immutable out/, every kind of corrupt
cache file, a killed report, the inputs that used to give tracebacks, the memory guard and a
signal during a solve. Each test states what a user must find afterwards: out/ exactly one
complete run (or exactly the previous one), no staging folder anywhere, one line on stderr.
"""
from __future__ import annotations

import copy
import errno
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import pytest

import pipeline.run as run
import runtime.outdir as outdir
from analytical.kinematics import pose_geometry
from analytical.params import Pose
from common.worker import WorkerDied, stoppable
from fem_reference import resources
from fem_reference.model import FemError, solve_pose
from pipeline.baselines import check_command, load_baseline
from runtime.cache import ResultCache
from solvers.compare import fem_case, fem_options, fem_runtime
from tests.conftest import PAPER_SCENE, ROOT, copied

FIXTURES = ROOT / "tests" / "fixtures"
ENV = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1")


def command(module: str, *args, cwd=ROOT, **popen) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", module, *map(str, args)], cwd=cwd, env=ENV,
                            text=True, **popen)


def finished(module: str, *args, cwd=ROOT) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", module, *map(str, args)], cwd=cwd, env=ENV,
                          capture_output=True, text=True, timeout=300)


def tree(folder: Path) -> dict[str, bytes]:
    """Every file under `folder` by relative path, with its bytes."""
    return {p.relative_to(folder).as_posix(): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def leftovers(out: Path) -> list[str]:
    """Staging folders, lock files or old trees of `out` in its parent."""
    return sorted(p.name for p in out.parent.iterdir()
                  if p.name.startswith(f".{out.name}.") or p.name == f"{out.name}.partial")


def scene_copy(tmp_path: Path, name: str, ci_cases: list[str]) -> Path:
    text = PAPER_SCENE.read_text(encoding="utf-8")
    text = text.replace('ci_cases = ["case1", "case2"]', f"ci_cases = {json.dumps(ci_cases)}")
    text = text.replace('name = "Gong & Lou 2023, 3-RPS"', f'name = "{name}"')
    path = tmp_path / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def warm(paper_ci_run, tmp_path_factory):
    """A CI-profile run of the paper's scene and the cache it filled (the session's, copied:
    these tests write into the cache)."""
    base = tmp_path_factory.mktemp("warm")
    return SimpleNamespace(out=copied(paper_ci_run.out, base / "out"),
                           cache=copied(paper_ci_run.cache, base / "cache"),
                           results=paper_ci_run.results)


def copy_of(folder: Path, target: Path) -> Path:
    shutil.copytree(folder, target)
    return target


# ---------------------------------------------------------------- one run per out/, swapped whole
@pytest.mark.slow
def test_two_runs_at_once_both_succeed_and_out_is_one_complete_run(warm, tmp_path):
    cache, out = copy_of(warm.cache, tmp_path / "cache"), tmp_path / "out"
    logs = [tmp_path / f"run{i}.err" for i in range(2)]
    with outdir.output_lock(out):  # both start while out/ is busy: both must wait, then run
        procs = [command("rps", "validate", "--scene", PAPER_SCENE, "--profile", "ci",
                         "--no-report", "--out", out, "--cache", cache,
                         stdout=subprocess.DEVNULL, stderr=log.open("w")) for log in logs]
        deadline = time.monotonic() + 120
        while not all("waiting for the run" in log.read_text() for log in logs):
            assert time.monotonic() < deadline and all(p.poll() is None for p in procs), \
                [log.read_text() for log in logs]
            time.sleep(0.1)
    assert [p.wait(timeout=300) for p in procs] == [0, 0], [log.read_text() for log in logs]
    for log in logs:
        lines = log.read_text().splitlines()
        assert len(lines) == 3 and lines[1].startswith("fidelity: "), lines
        assert lines[2] == f"wrote {out}/results.json", lines
    results = json.loads((out / "results.json").read_text())
    assert [c["name"] for c in results["cases"]] == ["case1", "case2"]
    assert sorted(tree(out)) == sorted(tree(warm.out))  # the same complete set of files
    assert leftovers(out) == []


def test_a_run_replaces_out_whole(warm, tmp_path):
    out = tmp_path / "out"
    run.validate(str(scene_copy(tmp_path, "first", ["case1"])), out, warm.cache, profile="ci")
    first = set(tree(out))
    assert "modes/case1_fem.vtu" in first and "tables/case1.csv" in first
    run.validate(str(scene_copy(tmp_path, "second", ["case2"])), out, warm.cache, profile="ci")
    second = tree(out)
    assert not [name for name in second if "case1" in name]  # nothing of the first run left
    assert json.loads(second["results.json"])["scene"]["name"] == "second"
    assert {"modes/case2_fem.vtu", "modes/case2_fem.pvd", "results.json", "tables/case2.csv",
            "tables/case2.md"} <= set(second)
    assert all(name.startswith(("modes/case2_fem", "results.json", "tables/case2",
                                "tables/studies/"))
               for name in second), sorted(second)
    assert not any("case1" in (out / name).read_text() for name in second
                   if name.startswith("tables/studies/"))  # the studies' tables are the run's
    assert leftovers(out) == []


def test_a_failure_inside_the_swap_leaves_out_exactly_as_it_was(warm, tmp_path, monkeypatch):
    out = copy_of(warm.out, tmp_path / "out")
    before = tree(out)

    def refused(a, b):
        raise OSError(errno.EPERM, os.strerror(errno.EPERM))

    monkeypatch.setattr(outdir, "exchange", refused)
    with pytest.raises(outdir.OutputError, match=f"cannot replace {out}: Operation not "
                                                 "permitted; it was left as it was"):
        run.validate(str(PAPER_SCENE), out, warm.cache, profile="ci")
    assert tree(out) == before and leftovers(out) == []


def test_without_renameat2_the_fallback_swap_restores_out_when_it_fails(warm, tmp_path,
                                                                         monkeypatch):
    out = copy_of(warm.out, tmp_path / "out")
    (out / "from-an-earlier-run.txt").write_text("old")
    before = tree(out)

    def unsupported(a, b):
        raise OSError(errno.ENOSYS, "renameat2 is not available")

    monkeypatch.setattr(outdir, "exchange", unsupported)
    real_rename = os.rename

    def rename(source, target):  # the second of the two renames fails
        if Path(source).name.startswith(".out.staging-"):
            raise OSError(errno.EIO, os.strerror(errno.EIO))
        real_rename(source, target)

    monkeypatch.setattr(outdir.os, "rename", rename)
    with pytest.raises(outdir.OutputError, match="Input/output error; it was left as it was"):
        run.validate(str(PAPER_SCENE), out, warm.cache, profile="ci")
    assert tree(out) == before and leftovers(out) == []
    monkeypatch.setattr(outdir.os, "rename", real_rename)  # the fallback itself works
    run.validate(str(PAPER_SCENE), out, warm.cache, profile="ci")
    assert "from-an-earlier-run.txt" not in tree(out) and leftovers(out) == []


def test_a_run_killed_between_the_fallback_renames_is_repaired_by_the_next(warm, tmp_path):
    out = copy_of(warm.out, tmp_path / "out")
    before = tree(out)
    os.rename(out, tmp_path / ".out.previous-dead0001")  # killed here: out/ absent
    (tmp_path / ".out.staging-dead0002").mkdir()  # and its staging folder left behind
    with outdir.staged_output(out, keep=lambda name: True):
        pass
    assert tree(out) == before and leftovers(out) == []


def test_a_stop_swallowed_by_a_finaliser_still_prevents_the_swap(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "results.json").write_text("previous run")
    before_handler = signal.getsignal(signal.SIGTERM)
    with pytest.raises(KeyboardInterrupt):
        with outdir.staged_output(out) as stage:
            (stage / "results.json").write_text("new run")
            try:  # as in a weakref callback during garbage collection: "Exception ignored"
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(1)
            except KeyboardInterrupt:
                pass
    assert tree(out) == {"results.json": b"previous run"} and leftovers(out) == []
    assert signal.getsignal(signal.SIGTERM) is before_handler


def _chattr(flag: str, path: Path) -> bool:
    try:
        return subprocess.run(["chattr", flag, str(path)], capture_output=True).returncode == 0
    except FileNotFoundError:
        return False


def test_an_immutable_out_gives_exit_2_and_is_exactly_the_previous_run(warm, tmp_path):
    out, cache = copy_of(warm.out, tmp_path / "out"), copy_of(warm.cache, tmp_path / "cache")
    before = tree(out)
    if not _chattr("+i", out):
        pytest.skip("chattr +i needs root and a file system with attributes")
    try:
        proc = finished("rps", "validate", "--scene", PAPER_SCENE, "--profile", "ci",
                        "--no-report", "--out", out, "--cache", cache)
    finally:
        _chattr("-i", out)
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [f"error: cannot replace {out}: Operation not "
                                        "permitted; it was left as it was"]
    assert tree(out) == before and leftovers(out) == []


def test_out_must_be_a_directory_of_its_own(tmp_path):
    (tmp_path / "work").mkdir()
    (tmp_path / "work" / "notes.txt").write_text("someone's work")
    for out, needle in ((".", "--out .: each run replaces the output directory whole, so it "
                              "cannot be the current directory"),
                        ("work", "--out work: holds notes.txt but none of results.json, ")):
        proc = finished("rps", "validate", "--scene", PAPER_SCENE, "--profile", "ci",
                        "--no-report", "--out", out, "--cache", tmp_path / "cache", cwd=tmp_path)
        assert proc.returncode == 2 and len(proc.stderr.splitlines()) == 1, proc.stderr
        assert needle in proc.stderr
    assert [p.relative_to(tmp_path).as_posix() for p in sorted(tmp_path.rglob("*"))] == \
        ["work", "work/notes.txt"]


@pytest.mark.parametrize("where", ["a copy into out/", "a write the OS names no file for"])
def test_a_full_disk_names_the_path_in_out(warm, tmp_path, monkeypatch, where):
    out = copy_of(warm.out, tmp_path / "out")
    before = tree(out)
    full = (errno.ENOSPC, os.strerror(errno.ENOSPC))
    if where == "a copy into out/":
        def copyfile(source, target):  # as shutil reports it: source first, target second
            raise OSError(*full, str(source), None, str(target))
        monkeypatch.setattr(run.shutil, "copyfile", copyfile)
        expected = f"cannot write {out}/modes/case1_fem.vtu: No space left on device"
    else:
        def write_tables(results, folder, records):
            raise OSError(*full)
        monkeypatch.setattr(run, "write_tables", write_tables)
        expected = f"cannot write {out}: No space left on device"
    with pytest.raises(outdir.OutputError) as info:
        run.validate(str(PAPER_SCENE), out, warm.cache, profile="ci")
    assert str(info.value) == expected
    assert tree(out) == before and leftovers(out) == []


# ---------------------------------------------------------------- caches verified on read
@pytest.fixture(scope="module")
def clean_solve(tmp_path_factory, scene):
    """One FEM solve at the CI mesh size, through a fresh cache: the reference. Tetrahedral
    legs, whose meshes go to the mesh cache (the harmonic legs' meridians are not cached)."""
    folder = tmp_path_factory.mktemp("clean-cache")
    tets = replace(scene, fem=replace(scene.fem, legs="tetrahedra"))
    geometry = pose_geometry(scene.manipulator, scene.case("case1").pose)
    value = fem_case(tets, geometry, ResultCache(folder), scene.fem_study.ci_mesh_size)
    return SimpleNamespace(folder=folder, geometry=geometry, value=value, scene=tets,
                           vtu=Path(value.vtu).read_bytes())


def _damage(path: Path, how: str) -> None:
    data = path.read_bytes()
    if how == "truncate":
        path.write_bytes(data[:len(data) // 2])
    elif how == "overwrite":
        path.write_bytes(b"\x00" * len(data))
    elif path.suffix == ".json":  # one digit of a number changed: still valid JSON
        text = data.decode()
        at = next(i for i in range(text.index('"frequencies_hz"') if "frequencies_hz" in text
                                   else text.index('"n_nodes"'), len(text))
                  if text[i].isdigit() and text[i] not in "09")
        path.write_text(text[:at] + str(int(text[at]) + 1) + text[at + 1:])
    else:  # one byte of the binary mesh or mode data flipped
        at = len(data) * 2 // 3
        path.write_bytes(data[:at] + bytes([data[at] ^ 0x01]) + data[at + 1:])


@pytest.mark.slow
@pytest.mark.parametrize("how", ["truncate", "overwrite", "edit"])
@pytest.mark.parametrize("cache, suffix", [("fem", ".json"), ("fem", ".vtu"),
                                           ("meshes", ".json"), ("meshes", ".vtu")])
def test_a_corrupt_cache_file_is_detected_dropped_and_recomputed(clean_solve, scene, tmp_path,
                                                                  capsys, cache, suffix, how):
    folder = copy_of(clean_solve.folder, tmp_path / "cache")
    (target,) = (folder / cache).glob(f"*{suffix}")
    if cache == "meshes":  # the result entry goes, so the solve reads the mesh again
        for path in (folder / "fem").glob("*.*"):
            path.unlink()
    _damage(target, how)
    capsys.readouterr()
    value = fem_case(clean_solve.scene, clean_solve.geometry, ResultCache(folder),
                     scene.fem_study.ci_mesh_size)
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "failed its check" in err[0] and target.stem in err[0], err
    assert not value.record["cache_hit"]
    for key in ("frequencies_hz", "dofs", "platform_motion"):
        assert value.record[key] == clean_solve.value.record[key]
    assert (value.station_shapes == clean_solve.value.station_shapes).all()
    assert Path(value.vtu).read_bytes() == clean_solve.vtu
    again = fem_case(clean_solve.scene, clean_solve.geometry, ResultCache(folder),
                     scene.fem_study.ci_mesh_size)
    assert again.record["cache_hit"] and capsys.readouterr().err == ""  # the new entry verifies


def test_a_corrupt_mode_file_never_reaches_out(warm, tmp_path, capsys):
    cache = copy_of(warm.cache, tmp_path / "cache")
    good = (warm.out / "modes" / "case1_fem.vtu").read_bytes()
    (entry,) = [p for p in (cache / "fem").glob("*.vtu") if p.read_bytes() == good]
    _damage(entry, "edit")
    out = tmp_path / "out"
    results = run.validate(str(PAPER_SCENE), out, cache, profile="ci")
    assert "failed its check" in capsys.readouterr().err
    assert (out / "modes" / "case1_fem.vtu").read_bytes() == good
    assert [c["fem"]["frequencies_hz"] for c in results["cases"]] == \
        [c["fem"]["frequencies_hz"] for c in warm.results["cases"]]


# ---------------------------------------------------------------- a killed report
@pytest.fixture
def report_out(tmp_path):
    out = tmp_path / "out"
    shutil.copytree(FIXTURES / "modes", out / "modes")
    shutil.copy(FIXTURES / "report_results.json", out / "results.json")
    return out


def _start_report_and_wait_for_staging(out: Path) -> subprocess.Popen:
    proc = command("rps", "report", "--results", out / "results.json", "--out", out,
                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    while not list(out.parent.glob(".out.staging-*/figures")):
        assert proc.poll() is None and time.monotonic() < deadline, proc.stderr.read()
        time.sleep(0.05)
    time.sleep(0.5)  # rendering
    return proc


@pytest.mark.parametrize("how", [signal.SIGTERM, signal.SIGINT, signal.SIGKILL])
def test_a_killed_report_leaves_out_as_it_was_and_nothing_behind(report_out, how):
    before = tree(report_out)
    proc = _start_report_and_wait_for_staging(report_out)
    proc.send_signal(how)
    _, err = proc.communicate(timeout=60)
    assert tree(report_out) == before, err
    if how == signal.SIGKILL:  # no cleanup possible: the next start removes the staging folder
        assert proc.returncode == -signal.SIGKILL and leftovers(report_out)
        with outdir.staged_output(report_out, keep=lambda name: True):
            pass
        assert tree(report_out) == before
    else:
        assert proc.returncode == 130, err
        assert err.splitlines()[-1] == ("error: interrupted; the output directory was left "
                                        "as it was") and "Traceback" not in err, err
    assert leftovers(report_out) == []


# ---------------------------------------------------------------- one line, exit 2
@pytest.mark.parametrize("module, args, needle", [
    ("rps", ["fem", "--scene", PAPER_SCENE, "--size", "1e-110"], "--size 1e-110 mm: must"),
    ("rps", ["fem", "--scene", PAPER_SCENE, "--size", "0.02"], "max_dofs"),
    ("rps", ["readme", "--results", "{}"], "schema None"),
    ("rps", ["analytical", "--scene", "density_kg_m3 = 1e-300"],
     "density_kg_m3 = 1e-300: must be >= 500 and <= 25000 kg/m3"),
    ("rps", ["check-baselines", "--results", "truncated"], "not valid JSON"),
    ("rps", ["report", "--results", "{}", "--out", "out"], "schema None"),
    ("rps", ["report", "--results", "truncated", "--out", "out"], "not valid JSON"),
])
def test_inputs_that_gave_tracebacks_give_one_line_and_exit_2(tmp_path, module, args, needle):
    files = {"{}": "{}",
             "truncated": (FIXTURES / "report_results.json").read_text()[:500],
             "density_kg_m3 = 1e-300": PAPER_SCENE.read_text().replace(
                 "density_kg_m3 = 7820.0", "density_kg_m3 = 1e-300")}
    given = []
    for arg in args:
        if arg in files:
            path = tmp_path / f"input{len(given)}"
            path.write_text(files[arg])
            arg = path
        given.append(arg)
    proc = finished(module, *given, cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and needle in lines[0], lines
    assert not (tmp_path / "out").exists() and not (tmp_path / ".cache").exists()


def test_check_baselines_reads_the_results_it_is_given(warm, tmp_path, capsys):
    """A CI-profile results file (FEM at the baselines' size) holding the baselines' model."""
    baseline = load_baseline()
    results = copy.deepcopy(warm.results)
    results["cases"] = [c for c in results["cases"] if c["name"] in baseline["cases"]]
    for case in results["cases"]:
        case["analytical"].update(baseline["analytical"])
        for pair, row in zip(case["pairs"], baseline["cases"][case["name"]]):
            pair.update(row)
    path = tmp_path / "results.json"
    path.write_text(json.dumps(results))
    assert check_command(str(path)) == 0
    results["cases"][0]["pairs"][2]["error_percent"] += 0.1
    path.write_text(json.dumps(results))
    assert check_command(str(path)) == 1
    assert "error_percent" in capsys.readouterr().err
    results["cases"][0]["fem"]["mesh_size_mm"] = 32.0
    path.write_text(json.dumps(results))
    with pytest.raises(ValueError, match="mesh_size_mm = 32.0, the baselines at 40"):
        check_command(str(path))
    path.write_text(json.dumps(warm.results))  # the run's own chosen model: not comparable
    with pytest.raises(ValueError, match="not comparable"):
        check_command(str(path))


# ---------------------------------------------------------------- memory and time guards
def test_the_memory_estimate_names_size_estimate_and_limit():
    with pytest.raises(resources.MemoryLimitError) as info:
        resources.check_memory(395_373, 0.1, 0.009, available=20e9)
    assert str(info.value).startswith("mesh_size_mm = 9: the solve needs about 17.1 GB "
                                      "(395,373 dofs")
    assert "above the limit of 10 GB (half of the 20 GB available)" in str(info.value)
    assert resources.check_memory(44_229, 0.1, 0.02, available=20e9) < 1e9


def test_a_wide_thick_elastic_plate_is_estimated_by_its_own_section(scene):
    """The fill model was fitted on legs; a meshed plate thicker than half the legs fills like
    a leg twice its thickness (measured: guard.section_width). Legs alone keep their width."""
    from fem_reference.guard import section_width
    from meshing.bodies import pose_assembly

    m = replace(scene.manipulator, leg_diameter=0.0189, platform_radius=0.222,
                platform_thickness=0.041, base_radius=0.241, actuator_min=0.285,
                actuator_max=0.374)
    geometry = pose_geometry(m, Pose(0.306))
    assert section_width(pose_assembly(m, geometry, elastic_platform=False)) == \
        pytest.approx(0.0189)
    assert section_width(pose_assembly(m, geometry, elastic_platform=True)) == \
        pytest.approx(0.082)
    paper = pose_assembly(scene.manipulator, pose_geometry(scene.manipulator, Pose(0.5436)),
                          elastic_platform=True)
    assert section_width(paper) == pytest.approx(0.1)  # the paper's legs still set it


def test_solves_at_once_share_the_memory_limit():
    """Each of n parallel solves measures the free memory before the others take theirs, so
    each may take 1 / n of the limit: two 6 GB solves fit one at a time in 20 GB, not at once."""
    need = resources.check_memory(200_000, 0.1, 0.011, available=20e9)
    assert 5e9 < need < 10e9
    with pytest.raises(resources.MemoryLimitError, match=r"0.5 of half of the 20 GB available"):
        resources.check_memory(200_000, 0.1, 0.011, available=20e9, share=0.5)


def test_the_sweeps_give_each_parallel_solve_its_share(scene):
    from solvers.compare import in_parallel

    assert in_parallel(scene, 2).fem_runtime.memory_share == 0.5
    assert in_parallel(scene, 1).fem_runtime == scene.fem_runtime


def test_an_idealisation_above_its_budget_is_reported_not_solved(scene, tmp_path, monkeypatch):
    """A side study never starts a solve beyond its budget: the variant says why, the case
    goes on."""
    import studies.fem_idealisations as ideal
    from runtime.cache import ResultCache
    from solvers.compare import fem_case
    from studies import CaseContext, Context

    monkeypatch.setattr(ideal, "MAX_DOFS", 14_000)  # at 40 mm: harmonic legs 13.5k estimated,
    scene = replace(scene, fem=scene.fem.with_size(0.04))  # tetrahedra 15k, elastic plate 19k
    case = scene.case("case1")
    geometry = pose_geometry(scene.manipulator, case.pose)
    ctx = Context(scene, ResultCache(tmp_path))
    fem = fem_case(scene, geometry, ctx.cache, 0.04)
    out = ideal.run(ctx, CaseContext(case, geometry, fem, None, None, None))
    assert set(out["unsolved"]) == {"elastic platform", "tetrahedral legs"}
    assert all("above max_dofs = 14000" in why for why in out["unsolved"].values())
    assert set(out["variants"]) == {"distributing coupling"}


def test_size_9_mm_is_refused_before_meshing_on_this_machine(manipulator, scene, monkeypatch):
    geometry = pose_geometry(manipulator, scene.case("case1").pose)
    options = fem_options(scene, 0.009, legs="tetrahedra")  # the 3D mesh's memory guard

    def no_meshing(*args, **kwargs):
        raise AssertionError("meshed before the memory check")

    monkeypatch.setattr("fem_reference.tetrahedra.cached_mesh", no_meshing)
    available = resources.available_bytes()
    if available is not None and resources.MEMORY_FRACTION * available > 20.7e9:
        pytest.skip(f"this machine has {available / 1e9:.0f} GB available: 9 mm would fit")
    with pytest.raises(FemError, match=r"mesh_size_mm = 9: the solve needs about 20.7 GB .*"
                                       r"above the limit of"):
        solve_pose(manipulator, geometry, options, fem_runtime(scene))


def test_a_solve_stays_under_the_memory_it_states(tmp_path, manipulator):
    """A real solve (20 mm, in a fresh process with its worker) peaks below its estimate."""
    code = ("import resource, sys; from rps.app import main; main(sys.argv[1:]); "
            "print(max(resource.getrusage(w).ru_maxrss for w in (resource.RUSAGE_SELF, "
            "resource.RUSAGE_CHILDREN)) * 1024)")
    proc = subprocess.run([sys.executable, "-c", code, "fem", "--scene", str(PAPER_SCENE),
                           "--size", "20", "--legs", "tetrahedra", "--json"], cwd=tmp_path,
                          env=ENV,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    payload, peak = proc.stdout.splitlines()
    stated = resources.peak_bytes(json.loads(payload)["dofs"], manipulator.leg_diameter, 0.020)
    assert int(peak) < stated


def test_the_worker_returns_results_and_raises_the_solvers_errors():
    assert stoppable(divmod, 17, 5) == (3, 2)
    with pytest.raises(ZeroDivisionError):
        stoppable(divmod, 1, 0)
    with pytest.raises(WorkerDied, match="exit status 3"):
        stoppable(os._exit, 3)


def _children(pid: int) -> list[int]:
    try:
        return [int(c) for c in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]
    except OSError:
        return []


@pytest.mark.slow
@pytest.mark.parametrize("how", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_stops_a_long_solve_within_2_seconds(tmp_path, how):
    # 16 mm: the factorisation alone takes ~7 s in C, where no Python handler can run
    # as from a terminal: a test runner started in the background (`cmd &` in a script) has
    # SIGINT ignored, which its children inherit and Python then keeps ignoring
    proc = command("rps", "fem", "--scene", PAPER_SCENE, "--size", "16", "--legs",
                   "tetrahedra", cwd=tmp_path,
                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                   preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 120
    while not (workers := _children(proc.pid)):
        assert proc.poll() is None and time.monotonic() < deadline, proc.stderr.read()
        time.sleep(0.05)
    time.sleep(0.5)  # well inside the factorisation
    start = time.monotonic()
    proc.send_signal(how)
    _, err = proc.communicate(timeout=60)
    stopped = time.monotonic() - start
    assert proc.returncode == 130 and stopped < 2.0, (stopped, err)
    assert err.splitlines() == ["error: interrupted; nothing partial was kept"]
    assert not any(Path(f"/proc/{w}").exists() for w in workers)  # the worker is gone
