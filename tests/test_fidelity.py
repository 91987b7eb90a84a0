"""The fidelity choice: the cheapest models meeting the scene's tolerance, from measurements."""
from __future__ import annotations

import pytest

from scene import FidelitySettings
from studies.choice import FEM_ERROR_SHARE, choose_analytical, choose_fem_size

SIZES = [0.04, 0.032, 0.025, 0.02]


def test_fem_size_is_the_coarsest_within_a_fifth_of_the_tolerance():
    errors = [[[0.3, 0.2], [0.19, 0.15], [0.12, 0.1], [0.08, 0.05]],
              [[0.25, 0.2], [0.21, 0.1], [0.1, 0.1], [0.07, 0.06]]]  # two cases
    choice = choose_fem_size(SIZES, errors, tolerance_percent=1.0)
    assert choice.met and choice.size == 0.025 and choice.worst_error_percent == 0.12
    assert choice.worst_error_percent <= FEM_ERROR_SHARE * 1.0


def test_fem_size_not_met_takes_the_finest_and_says_so():
    errors = [[[0.3], [0.2], [0.15], [0.11]]]
    choice = choose_fem_size(SIZES, errors, tolerance_percent=0.5)
    assert not choice.met and choice.size == 0.02 and "finest" in choice.reason


def test_analytical_choice_is_the_fastest_meeting_the_tolerance_over_every_case():
    candidates = {
        "EB, s=1": [{"seconds": 1e-4, "worst_error_percent": 5.0},
                    {"seconds": 1e-4, "worst_error_percent": 0.5}],  # fails on one case
        "EB, s=3": [{"seconds": 3e-4, "worst_error_percent": 0.9},
                    {"seconds": 3e-4, "worst_error_percent": 0.95}],
        "Timoshenko, s=3": [{"seconds": 3.1e-4, "worst_error_percent": 0.6},
                            {"seconds": 3.1e-4, "worst_error_percent": 0.6}],  # a tie: better
        "Timoshenko, s=10": [{"seconds": 3e-3, "worst_error_percent": 0.55},
                             {"seconds": 3e-3, "worst_error_percent": 0.5}],
    }
    choice = choose_analytical(candidates, tolerance_percent=1.0)
    assert choice.met and choice.setting == "Timoshenko, s=3"
    strict = choose_analytical(candidates, tolerance_percent=0.1)
    assert not strict.met and strict.setting == "Timoshenko, s=10"
    assert "no analytical setting meets" in strict.reason


@pytest.mark.parametrize("kwargs,needle", [({"modes": 0}, "modes = 0"),
                                           ({"tolerance_percent": -1.0}, "tolerance_percent")])
def test_fidelity_settings_are_validated(kwargs, needle):
    with pytest.raises(ValueError, match=needle):
        FidelitySettings(**kwargs)


def test_the_runs_own_size_joins_its_refinement_study_once():
    """A size read in mm (0.032 m) and one computed in leg diameters (0.32 x 0.1 m) are the
    same size: the study gets it once (two sizes a bit apart would make Richardson's step
    divide by ~0), and a size between the sequence's is inserted in order."""
    from solvers.refinement import size_index, study_sizes

    design = (0.4 * 0.1, 0.32 * 0.1, 0.25 * 0.1, 0.2 * 0.1)
    read = 0.032 * (1 + 1e-12)  # the same size, its last bits from another path
    assert read != design[1]
    assert study_sizes(design, read) == tuple(sorted(design, reverse=True))
    assert size_index(study_sizes(design, read), read) == 1
    assert study_sizes(design, 0.03) == (design[0], design[1], 0.03, design[2], design[3])
    assert study_sizes(design, 0.01)[-1] == 0.01 and study_sizes(design) == design


def test_the_fem_seconds_of_sizes_outside_a_study_are_unknown_not_an_error():
    """The workspace sweep's coarse mesh (1.25 h beyond the sequence) was timed by no study:
    its seconds are None; sizes of the study are summed (to 1e-9) and the median taken."""
    from studies.fidelity import _fem_seconds_of

    studies = {"a": {"mesh_sizes_mm": [40.0, 32.0], "seconds": [1.0, 2.0]},
               "b": {"mesh_sizes_mm": [40.0, 32.0], "seconds": [3.0, 4.0]}}
    assert _fem_seconds_of(studies, 0.04, 0.05) is None
    assert _fem_seconds_of(studies, 0.04 * (1 + 1e-12), 0.032) == 5.0
