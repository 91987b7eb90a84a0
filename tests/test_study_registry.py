"""A new study is one module and one registry line: registered at run time, touching no other
file, its typed record is in results.json (checked against its type as soon as it returns),
its table in out/tables/studies/ and its section in the report."""
from __future__ import annotations

import csv
import importlib.util
import json
from functools import partial

import pytest

import studies
from common.errors import InputError
from results import Record, Section, Table, stub, table_rows
from tests.conftest import PAPER_SCENE, copied

NEW_STUDY = '''
"""A study added by a test: the legs' slenderness over the machine's level band."""
import numpy as np
from pydantic import FiniteFloat, with_config
from typing_extensions import TypedDict

from analytical.kinematics import pose_geometry
from analytical.params import Pose
from analytical.reach import level_band
from results import STRICT, Record, Section, Table
from studies import Study

HEIGHTS = 20  # more rows than a short table keeps on one page


@with_config(STRICT)
class Slenderness(TypedDict):
    height_mm: FiniteFloat
    longest_leg_mm: FiniteFloat
    slenderness: FiniteFloat  # longest leg / leg diameter


def run(ctx):
    m = ctx.scene.manipulator
    band = level_band(m)
    rows = []
    for z in np.linspace(band.low, band.high, HEIGHTS):
        longest = float(max(pose_geometry(m, Pose(float(z))).leg_lengths))
        rows.append(Slenderness(height_mm=float(z) * 1e3, longest_leg_mm=longest * 1e3,
                                slenderness=longest / m.leg_diameter))
    return rows


STUDY = Study(Record("leg_slenderness", "scene", list[Slenderness], [],
                     Section("slenderness", "Leg slenderness", "leg slenderness"),
                     (Table("legs", ("height_mm", "longest_leg_mm", "slenderness")),)),
              "scene", run, profiles=("full", "ci"))
'''


def load_module(path, name):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture
def registered(tmp_path, monkeypatch):
    """The new study's module, and its one registry line (studies/__init__.py's STUDIES,
    from which RECORDS is made) applied for this test only."""
    path = tmp_path / "leg_slenderness.py"
    path.write_text(NEW_STUDY, encoding="utf-8")
    module = load_module(path, "leg_slenderness_study")
    monkeypatch.setattr(studies, "STUDIES", studies.STUDIES + (module.STUDY,))
    monkeypatch.setattr(studies, "RECORDS", studies.RECORDS + (module.STUDY.record,))
    return module


@pytest.mark.slow
def test_a_study_registered_at_run_time_has_its_record_table_and_section(
        registered, paper_ci_run, tmp_path):
    from pipeline.run import validate
    from reports.build import render_report

    out = tmp_path / "out"
    results = validate(str(PAPER_SCENE), out, copied(paper_ci_run.cache, tmp_path / "cache"),
                       profile="ci", report=partial(render_report, records=studies.RECORDS))
    written = json.loads((out / "results.json").read_text())
    rows = written["studies"]["leg_slenderness"]
    assert rows == results["studies"]["leg_slenderness"] and len(rows) == 20
    slender = [r["slenderness"] for r in rows]  # a level platform rises on longer legs
    assert all(a < b for a, b in zip(slender, slender[1:])) and slender[0] > 1
    assert all(r["longest_leg_mm"] == pytest.approx(r["slenderness"] * 100.0) for r in rows)
    with (out / "tables" / "studies" / "leg_slenderness-legs.csv").open() as handle:
        table = list(csv.DictReader(handle))
    assert [float(row["height_mm"]) for row in table] == [r["height_mm"] for r in rows]
    assert [float(row["slenderness"]) for row in table] == [r["slenderness"] for r in rows]
    page = (out / "report.html").read_text(encoding="utf-8")
    assert '<section id="slenderness">' in page and "Leg slenderness</h2>" in page
    assert 'href="#slenderness"' in page  # in the contents, numbered with the others
    # a long table: the first MAX_ROWS rows drawn, in words, the CSV of all of them linked
    from reports.generic_tables import MAX_ROWS

    last = MAX_ROWS - 1
    assert f'data-src="/studies/leg_slenderness/{last}/slenderness"' in page
    assert f'data-src="/studies/leg_slenderness/{last + 1}/slenderness"' not in page
    assert '<a href="tables/studies/leg_slenderness-legs.csv">' in page
    assert "longest leg (mm)</th>" in page and "height z (mm)</th>" in page


def test_a_study_returning_a_wrong_record_is_refused_when_it_returns():
    record = Record("leg_slenderness", "scene", list[dict[str, float]], [])
    with pytest.raises(InputError, match=r"^results: leg_slenderness\[0\]\.x: input should "
                                         r"be a valid number"):
        record.checked([{"x": "long"}])


def test_results_holding_a_study_nobody_declared_are_refused_in_one_line(paper_ci_run):
    import results

    data = json.loads((paper_ci_run.out / "results.json").read_text())
    data["studies"]["leg_slenderness"] = []
    with pytest.raises(InputError, match="studies.leg_slenderness: not a field of the results, "
                                         "nor a study this version declares"):
        results.validated(data, studies.RECORDS)
    del data["studies"]["workspace"]
    data["studies"].pop("leg_slenderness")
    with pytest.raises(InputError, match="studies.workspace: field required"):
        results.validated(data, studies.RECORDS)


def test_a_table_column_the_record_cannot_hold_is_refused_at_declaration():
    from results import HardCase

    with pytest.raises(InputError, match="record x: table t: column 'nope' is not a field"):
        Record("x", "scene", list[HardCase], [], None, (Table("t", ("claim", "nope")),))


def test_a_section_on_the_reports_own_anchor_or_redeclared_is_refused():
    from results import unique

    mine = Record("x", "scene", list[dict[str, float]], [], Section("summary", "Mine"))
    with pytest.raises(InputError, match="anchor summary is the report's own"):
        unique([mine])
    a = Record("a", "scene", list[dict[str, float]], [], Section("s", "One"))
    b = Record("b", "scene", list[dict[str, float]], [], Section("s", "Two"))
    with pytest.raises(InputError, match="anchor s is declared twice, differently"):
        unique([a, b])


def test_the_stub_and_the_tables_of_a_case_study_come_from_its_declaration():
    record = Record("first_mode", "case", dict[str, float] | None, None,
                    Section("first-mode", "First mode"), (Table("f1", ("hz",)),))
    assert stub([record], "case") == {"first_mode": None}
    assert stub([record], "scene") == {}
    held = {"studies": {}, "cases": [{"name": "a", "first_mode": {"hz": 12.5}},
                                     {"name": "b", "first_mode": None}]}
    assert table_rows(record, record.tables[0], held) == [
        {"": "/cases/0/first_mode", "case": "a", "hz": 12.5}]


def test_the_stored_report_fixture_reads_a_study_declared_after_it_as_not_run(registered):
    """A new study needs no full run to regenerate tests/fixtures/report_results.json: a
    declared study the stored file lacks is read as its empty value (it did not run), and the
    report built from it names the study among those not run; a study nobody declared is
    still refused."""
    import results
    from reports.document import section_order
    from tests.conftest import REPORT_FIXTURE

    raw = json.loads(REPORT_FIXTURE.read_text(encoding="utf-8"))
    assert "leg_slenderness" not in raw["studies"]
    held = results.read(REPORT_FIXTURE, studies.RECORDS)
    assert held["studies"]["leg_slenderness"] == []
    record = registered.STUDY.record
    assert table_rows(record, record.tables[0], held) == []  # no rows: a table left out
    assert ("slenderness", record.section) in section_order(studies.RECORDS)
    raw["studies"]["leg_slenderness"] = []
    others = tuple(r for r in studies.RECORDS if r.key != "leg_slenderness")
    with pytest.raises(InputError, match="leg_slenderness: not a field of the results"):
        results.validated(raw, others)


def test_the_studies_room_lists_every_registered_study():
    """studies/README.md's table names the module of every registered study (the registry,
    `studies.STUDIES`, is the one list; the README is held to it)."""
    import sys
    from pathlib import Path

    text = (Path(studies.__file__).parent / "README.md").read_text(encoding="utf-8")
    where = {id(getattr(m, "STUDY", None)): name for name, m in list(sys.modules.items())
             if name.startswith("studies.")}
    for study in studies.STUDIES:
        name = where[id(study)].split(".")[1]  # the module (or package) declaring it
        assert f"`{name}.py`" in text or f"`{name}/`" in text, name
