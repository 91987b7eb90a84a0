"""Shared fixtures: the paper's scene and its two cases; one CI-profile run of it."""
from __future__ import annotations

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


@pytest.fixture(scope="session")
def paper_ci_run(tmp_path_factory):
    """One CI-profile run of the paper's scene from an empty cache, made once for the session
    (each run takes ~15 s): its out/, its cache, its results, and where the solid end zones
    would have gone had the run not kept every cache under its own (`default_zones`, which
    must stay absent). Tests read it; a test that writes copies it (`copied`)."""
    import joint_ends.cache
    import pipeline.run as run

    base = tmp_path_factory.mktemp("paper-ci")
    default = base / "default-cache"
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(joint_ends.cache, "cache_root", lambda: default)
        results = run.validate(str(PAPER_SCENE), base / "out", base / "cache", profile="ci")
    return SimpleNamespace(out=base / "out", cache=base / "cache", results=results,
                           default_zones=default)


def copied(folder: Path, target: Path) -> Path:
    """A copy of `folder` (a warm cache or an out/ a test may change) at `target`."""
    shutil.copytree(folder, target)
    return target


@pytest.fixture(scope="session")
def fixture_report(tmp_path_factory):
    """The report of the fixture results (tests/fixtures/report_results.json), built once for
    the session (~15 s): (its folder, report.html, report.pdf). Tests only read it."""
    from reports.build import build_report
    from studies import RECORDS

    out = tmp_path_factory.mktemp("fixture-report")
    html, pdf = build_report(REPORT_FIXTURE, out, records=RECORDS)
    return SimpleNamespace(out=out, html=html, pdf=pdf)
