"""Shared fixtures: the paper's scene and its two cases; one CI-profile run of it."""
from __future__ import annotations

import fcntl
import shutil
from pathlib import Path
from types import SimpleNamespace

import pytest

from scene import load_scene

ROOT = Path(__file__).resolve().parents[1]
PAPER_SCENE = ROOT / "scenes" / "paper.toml"
REPORT_FIXTURE = ROOT / "tests" / "fixtures" / "report_results.json"


@pytest.fixture(scope="session")
def scene():
    return load_scene(PAPER_SCENE)


@pytest.fixture(scope="session")
def manipulator(scene):
    return scene.manipulator


def shared(tmp_path_factory, worker_id: str, name: str, make) -> Path:
    """A folder made once for the whole test session, whatever the number of xdist workers:
    the first worker to ask makes it (`make(folder)`) under a lock, the others wait and read
    it (a session fixture is otherwise made once per worker)."""
    if worker_id == "master":  # no xdist
        folder = tmp_path_factory.mktemp(name)
        make(folder)
        return folder
    root = tmp_path_factory.getbasetemp().parent  # shared by the workers of this session
    folder = root / name
    with open(root / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (root / f"{name}.done").exists():
            shutil.rmtree(folder, ignore_errors=True)
            folder.mkdir()
            make(folder)
            (root / f"{name}.done").touch()
    return folder


@pytest.fixture(scope="session")
def paper_ci_run(tmp_path_factory, worker_id):
    """One CI-profile run of the paper's scene from an empty cache, made once for the session
    (each run takes ~15 s; `shared` across the workers): its out/, its cache, its results, and
    where the solid end zones would have gone had the run not kept every cache under its own
    (`default_zones`, which must stay absent). Tests read it; a test that writes copies it
    (`copied`)."""

    def make(base: Path) -> None:
        import joint_ends.cache
        import pipeline.run as run

        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(joint_ends.cache, "cache_root", lambda: base / "default-cache")
            run.validate(str(PAPER_SCENE), base / "out", base / "cache", profile="ci")

    from results import read
    from studies import RECORDS

    base = shared(tmp_path_factory, worker_id, "paper-ci", make)
    return SimpleNamespace(out=base / "out", cache=base / "cache",
                           results=read(base / "out" / "results.json", RECORDS),
                           default_zones=base / "default-cache")


def copied(folder: Path, target: Path) -> Path:
    """A copy of `folder` (a warm cache or an out/ a test may change) at `target`."""
    shutil.copytree(folder, target)
    return target


@pytest.fixture(scope="session")
def fixture_report(tmp_path_factory, worker_id):
    """The report of the fixture results (tests/fixtures/report_results.json), built once for
    the session (~15 s; `shared` across the workers): (its folder, report.html, report.pdf).
    Tests only read it."""

    def make(out: Path) -> None:
        from reports.build import build_report
        from studies import RECORDS

        build_report(REPORT_FIXTURE, out, records=RECORDS)

    out = shared(tmp_path_factory, worker_id, "fixture-report", make)
    return SimpleNamespace(out=out, html=out / "report.html", pdf=out / "report.pdf")


def pytest_collection_modifyitems(config, items):
    """The modules with slow tests first (each module's tests kept together, in their order),
    so that the two workers do not end on one long FEM run while the other idles: the suite's
    wall time is its critical path, and the long tests are in those modules."""
    slow = {item.module.__name__ for item in items
            if item.get_closest_marker("slow") is not None and item.module is not None}
    items.sort(key=lambda item: (item.module is None or item.module.__name__ not in slow))


def refused(capsys, argv, *needles: str, seconds: float = 5.0) -> str:
    """The one stderr line of a refused command (run in this process), holding every needle,
    within `seconds`: exit status 2, nothing on stdout, no traceback, no warning printed (the
    probe suites also turn every warning into an error)."""
    import time

    from rps import app as cli

    start = time.perf_counter()
    try:
        status = cli.main([str(a) for a in argv])
    except SystemExit as exc:
        status = exc.code
    took = time.perf_counter() - start
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert status == 2, err
    assert out == "" and len(lines) == 1 and lines[0].startswith("error: "), err
    assert "Traceback" not in err and "Warning" not in err
    assert all(n in lines[0] for n in needles), lines[0]
    assert took < seconds, f"refused after {took:.1f} s"
    return lines[0]
