"""CI regression of the Case 1 and Case 2 error tables against tests/baselines/.

The tolerances and their justification live in pipeline/baselines.py. To accept a change that
moves the tables on purpose: `make update-baselines`, and say why in the commit.
"""
from __future__ import annotations

import copy

import pytest

from pipeline.baselines import compare, compute_tables, load_baseline
from tests.conftest import ROOT

pytestmark = pytest.mark.slow  # whole validation runs (CI profile): tens of seconds each


@pytest.fixture(scope="module")
def baseline():
    return load_baseline()


@pytest.fixture(scope="module")
def current(baseline, tmp_path_factory):
    return compute_tables(ROOT / baseline["scene"], baseline["mesh_size_mm"] * 1e-3,
                          tmp_path_factory.mktemp("cache"))


def test_error_tables_match_the_golden_baseline(baseline, current):
    moved = compare(baseline, current)
    assert not moved, "error tables moved beyond tolerance:\n" + "\n".join(moved)


def test_a_physics_change_would_be_caught(baseline, current):
    """The comparison is not vacuous: a 0.1 % shift of one frequency is reported, readably."""
    broken = copy.deepcopy(current)
    row = broken["case2"][3]
    row["f_analytical_hz"] *= 1.001
    row["error_percent"] = 100 * (row["f_analytical_hz"] / row["f_fem_hz"] - 1)
    moved = compare(baseline, broken)
    assert len(moved) == 3 and "case2" in moved[1] and "error_percent" in moved[1]
    assert "f_analytical_hz" in moved[2]


def test_paper_faithful_model_meets_the_papers_accuracy_on_the_first_three_modes(current):
    """Issue acceptance: EB, s = 3 agrees on f1..f3 at least as well as the paper (1.03 %)."""
    for name in ("case1", "case2"):
        assert max(abs(r["error_percent"]) for r in current[name][:3]) < 1.03
        assert min(r["mac"] for r in current[name]) > 0.9


def test_best_model_is_within_one_percent_of_the_fem_on_all_six_modes(baseline, tmp_path_factory):
    """Issue acceptance: Timoshenko beams and the true plate inertia bring all six modes of both
    cases within 1 % of the FEM. The scene's default 32 mm FEM has an estimated error of at most
    0.16 % on f1..f6 (refinement study, `make`), so 0.84 % against it bounds 1 % against the
    converged reference."""
    from scene import load_scene
    default_size = load_scene(ROOT / baseline["scene"]).fem.mesh_size
    tables = compute_tables(ROOT / baseline["scene"], default_size,
                            tmp_path_factory.mktemp("cache"), beam="timoshenko",
                            platform_inertia="plate")
    for name in ("case1", "case2"):
        worst = max(abs(r["error_percent"]) for r in tables[name])
        assert worst < 0.84, (name, worst)
