"""Design studies (`scene.design_file`, `studies.design`, `rps design`).

The parts as closed forms and definitions (moving mass, the Pareto front, the penalty that puts
every infeasible design behind every feasible one), the design file's one-line refusals, and a
small study end to end: it meets its constraint, its optimum is the best design it solved, the
FEM checks the optimum at its worst pose, and a second run with the same cache solves nothing
again (resumable).
"""
from __future__ import annotations

import math
from pathlib import Path

import pytest

import studies.design as design
from analytical.platform import platform_mass
from runtime.cache import ResultCache
from scene import SceneError, load_scene
from scene.design_file import load_design

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "scenes" / "paper.toml"


def write(tmp_path, text: str) -> Path:
    path = tmp_path / "design.toml"
    path.write_text(f'scene = "{PAPER}"\n' + text, encoding="utf-8")
    return path


SMALL = """
name = "lightest legs for f1 >= 40 Hz"
[variables]
"manipulator.leg_diameter_mm" = [60.0, 140.0]
[constraints]
min_frequency_hz = 40.0
min_level_band_mm = 300.0
[search]
designs = 6
[model]
beam = "euler-bernoulli"
elements = 1
"""


def test_moving_mass_is_the_legs_at_mid_stroke_the_plate_and_the_payload():
    m = load_scene(PAPER).manipulator
    legs = 3 * m.material.density * math.pi / 4 * m.leg_diameter ** 2 * 0.5 * (
        m.actuator_min + m.actuator_max)
    assert design.moving_mass(m) == pytest.approx(legs + platform_mass(m) + m.payload.mass,
                                                  rel=1e-12)
    head = load_scene(ROOT / "scenes" / "3prs-head.toml").manipulator  # legs of one length
    legs = 3 * head.material.density * math.pi / 4 * head.leg_diameter ** 2 * head.leg_length
    assert head.payload.mass > 0  # the spindle counts
    assert design.moving_mass(head) == pytest.approx(legs + platform_mass(head)
                                                     + head.payload.mass, rel=1e-12)


def test_the_front_keeps_what_nothing_beats_and_infeasible_designs_rank_last(tmp_path):
    spec = load_design(write(tmp_path, SMALL))
    r = lambda mass, hz: {"refused": None, "moving_mass_kg": mass,  # noqa: E731
                          "min_frequency_hz": hz, "level_band_mm": 500.0}
    records = [r(10, 30), r(12, 25), r(12, 45), r(15, 44), r(20, 50), r(9, 5)]
    front = design.pareto_front(spec, records)
    assert [(x["moving_mass_kg"], x["min_frequency_hz"]) for x in front] == [
        (9, 5), (10, 30), (12, 45), (20, 50)]
    worst_feasible = max(design.objective(spec, x) for x in records if design.meets(spec, x))
    below = design.objective(spec, r(9, 39))  # 2.5 % below the 40 Hz target
    assert below > worst_feasible
    assert design.objective(spec, r(9, 5)) > below  # further below, further behind
    band_short = dict(r(9, 60), level_band_mm=290.0)  # the band 3 % short of 300 mm
    assert not design.meets(spec, band_short)
    assert worst_feasible < design.objective(spec, band_short) < design.objective(spec, r(9, 5))
    assert design.objective(spec, {"refused": "no level pose"}) > max(
        design.objective(spec, x) for x in records + [band_short])


@pytest.mark.parametrize("text, message", [
    ('[variables]\n"manipulator.leg_diamter_mm" = [50.0, 90.0]\n[constraints]\n'
     "min_frequency_hz = 10.0\n", "'manipulator.leg_diamter_mm' is not a number of "
     r"\[manipulator\]"),
    ('[variables]\n"manipulator.leg_diameter_mm" = [90.0, 50.0]\n', "expected \\[low, high\\]"),
    ('[variables]\n"manipulator.leg_diameter_mm" = [0.0, 50.0]\n', "0.0 must be >= 1"),
    ('[variables]\n"fem.mesh_size_mm" = [10.0, 50.0]\n', "table one of manipulator"),
    ('[variables]\n"manipulator.leg_diameter_mm" = [50.0, 90.0]\n', "min_frequency_hz: missing"),
    ('[variables]\n"manipulator.leg_diameter_mm" = [50.0, 90.0]\n[constraints]\n'
     "min_frequency_hz = 10.0\n[search]\ndesigns = 10000000\n", "designs = 10000000"),
    ('[variables]\n"leg.housing_length_mm" = [300.0, 400.0]\n[constraints]\n'
     "min_frequency_hz = 10.0\n", "the design at the middle of its bounds is refused"),
    ('[variables]\n"manipulator.leg_diameter_mm" = [50.0, 90.0]\n[constraints]\n'
     "min_frequency_hz = 10.0\nmode = 60\n", "mode = 60: the search model has only"),
])
def test_a_design_file_is_refused_in_one_line(tmp_path, text, message):
    with pytest.raises(SceneError, match=message) as info:
        load_design(write(tmp_path, text))
    assert "\n" not in str(info.value)


@pytest.fixture(scope="module")
def small_study(tmp_path_factory):
    """The small study, run once: (spec, its cache, its result)."""
    folder = tmp_path_factory.mktemp("design")
    spec = load_design(write(folder, SMALL))
    cache = ResultCache(folder / "cache")
    return spec, cache, design.run_design(spec, cache)


def test_a_small_study_end_to_end_and_resumable(small_study, monkeypatch):
    spec, cache, result = small_study
    assert result["designs_solved"] <= spec.search.designs
    best = result["optimum"]
    assert best is not None and best["min_frequency_hz"] >= 40.0
    feasible = [r for r in result["designs"] if design.meets(spec, r)]
    assert best["moving_mass_kg"] == min(r["moving_mass_kg"] for r in feasible)
    assert best in result["front"]
    # the target binds: lighter designs were solved and fell short of it
    assert any(r["moving_mass_kg"] < best["moving_mass_kg"] and not design.meets(spec, r)
               for r in result["designs"])
    check = result["fem_check"]
    assert check["within_tolerance"] == (abs(check["error_percent"])
                                         <= check["tolerance_percent"])
    assert check["fem_hz"] > 0 and check["mac"] > 0.9
    solved = []
    real = design.workspace_minimum
    monkeypatch.setattr(design, "workspace_minimum",
                        lambda *a, **k: solved.append(1) or real(*a, **k))
    again = design.run_design(spec, cache)
    assert not solved  # every design from the cache
    assert again["optimum"] == best


def test_the_design_report_shows_the_front_and_the_optimum(small_study, tmp_path):
    """The report is drawn from the study's record alone: its numbers are the record's."""
    from reports.design_report import render_design_report

    result = small_study[2]
    paths = render_design_report(result, tmp_path)
    assert all(p.is_file() and p.stat().st_size > 0 for p in paths)
    assert (tmp_path / "front.png").is_file() and (tmp_path / "map.png").is_file()
    html = (tmp_path / "design.html").read_text(encoding="utf-8")
    best = result["optimum"]
    assert f"{best['moving_mass_kg']:.3f} kg" in html
    assert f"{best['min_frequency_hz']:.3f} Hz" in html
    assert f"{result['fem_check']['error_percent']:+.3f} %" in html
    import shutil

    if shutil.which("pdftotext"):  # its pages in the report's fonts, nothing past them
        from tests.test_report_pages import words_past_the_page

        assert words_past_the_page(tmp_path / "design.pdf") == []


@pytest.mark.parametrize("where, message", [
    (["--out", "{tmp}/missing/design.json"], "does not exist"),
    (["--out", "{tmp}"], "is a directory"),
    (["--report", "{tmp}/stranger"], "not an output directory"),
])
def test_where_the_study_goes_is_checked_before_it_starts(tmp_path, monkeypatch, capsys,
                                                          where, message):
    """A study takes minutes: an --out or --report that cannot take it is refused (exit 2,
    one line) before any design is solved; a --report folder of an earlier study is not."""
    import rps.app as cli

    (tmp_path / "stranger").mkdir()
    (tmp_path / "stranger" / "notes.txt").write_text("mine")
    monkeypatch.setattr(design, "run_design", lambda *a, **k: pytest.fail("the study ran"))
    args = [a.format(tmp=tmp_path) for a in where]
    path = write(tmp_path, SMALL)
    assert cli.main(["design", "--design", str(path), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err


def test_a_report_folder_of_an_earlier_study_may_be_replaced(tmp_path):
    from runtime.outdir import check_output_dir

    earlier = tmp_path / "design-out"
    earlier.mkdir()
    for name in ("design.json", "design.html", "design.pdf", "front.png", "map.png"):
        (earlier / name).write_text("x")
    assert check_output_dir(earlier, "--report") == earlier.resolve()


DYNAMIC = """
name = "stiffest tool for its legs"
[variables]
"manipulator.leg_diameter_mm" = [60.0, 140.0]
[constraints]
min_dynamic_stiffness_n_per_um = 0.05
directions = ["x", "y"]
[objective]
minimise = "dynamic_stiffness"
[model]
beam = "euler-bernoulli"
elements = 1
"""


def test_the_least_dynamic_stiffness_is_an_objective_and_a_constraint(tmp_path, monkeypatch):
    """A design's least dynamic stiffness at the tool over its regular workspace is the
    dynamic map's (studies.dynamic_stiffness) weakest of the asked directions; thicker legs
    stiffen the tool; the objective maximises it and the constraint ranks a design short of
    it behind every one that meets it. (The workspace's least frequency, which every design
    also solves and other tests check, is replaced by its level band alone: seconds.)"""
    from types import SimpleNamespace

    from analytical.params import Pose
    from analytical.reach import level_band

    monkeypatch.setattr(design, "workspace_minimum", lambda m, model, mode: SimpleNamespace(
        band=level_band(m), frequency_hz=1.0, pose=Pose(level_band(m).low), boundary=False))
    spec = load_design(write(tmp_path, DYNAMIC))
    assert spec.constraints.min_dynamic_stiffness == pytest.approx(5e4)
    cache = ResultCache(tmp_path / "cache")
    thin, thick = (design.evaluate(spec, [d], cache) for d in (70.0, 130.0))
    for r in (thin, thick):
        assert r["refused"] is None and r["dynamic_worst"]["direction"] in ("x", "y")
        assert r["min_dynamic_stiffness_n_per_m"] == r["dynamic_worst"]["stiffness_n_per_m"]
    assert thick["min_dynamic_stiffness_n_per_m"] > thin["min_dynamic_stiffness_n_per_m"]
    assert design.objective(spec, thick) < design.objective(spec, thin)
    short = dict(thick, min_dynamic_stiffness_n_per_m=4e4)
    assert not design.meets(spec, short)
    assert design.objective(spec, short) > max(design.objective(spec, r) for r in (thin, thick))
    with pytest.raises(SceneError, match="directions") as info:
        load_design(write(tmp_path, DYNAMIC.replace('["x", "y"]', '["x", "w"]')))
    assert "\n" not in str(info.value)


HEAD = ROOT / "scenes" / "3prs-head.toml"
DEPTH = """
name = "the deepest stable cut"
[variables]
"manipulator.leg_diameter_mm" = [45.0, 110.0]
[constraints]
min_critical_depth_mm = 1.0
[objective]
minimise = "critical_depth"
[search]
designs = 4
"""


def test_the_least_critical_depth_is_an_objective_and_a_constraint(tmp_path, monkeypatch):
    """A design's least critical depth is the least of the scene's cut over its coarse
    stability map (studies.stability_map with the design's model and speeds): thicker legs of
    the 3-PRS head (its 30 kg spindle on them) cut deeper; the objective maximises it and the
    constraint ranks a design short of it behind every one that meets it; a scene without
    [cutting] is refused in one line. (The least frequency is replaced by the level band alone,
    and the map thinned to one layer: seconds.)"""
    from dataclasses import replace
    from types import SimpleNamespace

    from analytical.params import Pose
    from analytical.reach import level_band
    from scene.design_file import design_scene
    from studies.stability_map import stability_map

    monkeypatch.setattr(design, "workspace_minimum", lambda m, model, mode: SimpleNamespace(
        band=level_band(m), frequency_hz=1.0, pose=Pose(level_band(m).low), boundary=False))
    monkeypatch.setattr(design, "STABILITY_GRID", (1, 2, 3, 12))
    path = tmp_path / "depth.toml"
    path.write_text(f'scene = "{HEAD}"\n' + DEPTH, encoding="utf-8")
    spec = load_design(path)
    assert spec.constraints.min_critical_depth == pytest.approx(1e-3)
    cache = ResultCache(tmp_path / "cache")
    thin, thick = (design.evaluate(spec, [d], cache) for d in (50.0, 100.0))
    for r in (thin, thick):
        assert r["refused"] is None and r["stability_worst"]["kind"] in ("hopf", "flip")
    assert thick["min_critical_depth_mm"] > 1.5 * thin["min_critical_depth_mm"]
    scene = design_scene(spec, [50.0])
    direct = stability_map(replace(scene, analytical=spec.model,
                                   cutting=replace(scene.cutting, speeds=12)), 1, 2, 3)
    assert thin["min_critical_depth_mm"] == direct["least"][0]["depth_mm"]
    assert design.objective(spec, thick) < design.objective(spec, thin)
    short = dict(thick, min_critical_depth_mm=0.99)
    assert not design.meets(spec, short)
    assert design.objective(spec, short) > max(design.objective(spec, r) for r in (thin, thick))
    path.write_text(f'scene = "{PAPER}"\n' + DEPTH, encoding="utf-8")
    with pytest.raises(SceneError, match=r"has no \[cutting\] table") as info:
        load_design(path)
    assert "\n" not in str(info.value)
