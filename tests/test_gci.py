"""The grid convergence index (Roache; Celik et al. 2008) beside Richardson's estimate.

Specification: the GCI of a sequence is exact arithmetic on its three finest solutions, so it is
held to the published worked example and to sequences whose limit and order are known exactly;
where no order can be observed it falls back to the two-mesh form (safety factor 3 at the theory
order); the stated error of a study is the larger of the two estimates on every size and mode.
"""
from __future__ import annotations

import numpy as np
import pytest

from fem_reference.convergence import (
    GCI_SAFETY_THREE,
    GCI_SAFETY_TWO,
    P_FIT_MAX,
    P_THEORY,
    celik_order,
    gci,
    study_from_values,
    two_mesh_gci,
)


def test_celik_worked_example_reattachment_length():
    """Celik et al., J. Fluids Eng. 130:078001 (2008), Table 1, column phi = x_r / H (a 2D
    flow: h = N^(-1/2)): grids of 18,000 / 8,000 / 4,500 cells, phi = 6.063 / 5.972 / 5.863;
    the table gives p = 1.53, phi_ext21 = 6.1685 and GCI_fine21 = 2.2 %."""
    h = np.array([4500.0, 8000.0, 18000.0]) ** (-1.0 / 2.0)
    g = gci(h, [5.863, 5.972, 6.063])
    assert g.safety_factor == GCI_SAFETY_THREE
    assert g.observed_order == pytest.approx(1.53, abs=0.005)
    assert g.extrapolated_hz == pytest.approx(6.1685, abs=5e-5)
    assert 100 * g.relative_error[-1] == pytest.approx(2.2, abs=0.05)


def test_a_diverging_sequence_has_no_observed_order():
    """Differences that shrink more slowly than any power law allows at these size ratios
    (e32 / e21 = 0.5 < 0.9) are no convergence: no order, the two-mesh form stands in."""
    h = np.array([0.04, 0.032, 0.025])
    f = [10.0, 10.01, 10.03]  # the finer, the farther apart
    assert celik_order(h, f) is None
    assert gci(h, f).safety_factor == GCI_SAFETY_TWO


@pytest.mark.parametrize("p", [1.0, P_THEORY, 2.0, 3.5])
@pytest.mark.parametrize("sizes", [(0.04, 0.032, 0.025), (0.05, 0.03, 0.02, 0.016)])
def test_an_exact_power_law_gives_its_order_limit_and_1_25_times_its_error(p, sizes):
    h = np.asarray(sizes)
    f = 100.0 + 37.0 * h**p
    g = gci(h, f)
    assert g.observed_order == pytest.approx(p, rel=1e-8)
    assert g.extrapolated_hz == pytest.approx(100.0, rel=1e-12)
    true = np.abs(f - 100.0) / f
    np.testing.assert_allclose(g.relative_error, GCI_SAFETY_THREE * true, rtol=1e-7)


@pytest.mark.parametrize("h, p", [((0.04, 0.032, 0.025), 6.0), ((0.0145, 0.0134, 0.0124), 23.0)])
def test_an_order_above_the_formal_one_is_capped_and_so_errs_large(h, p):
    """(Closely spaced sizes, as the effective sizes of the harmonic meridians, show orders
    far above the formal one: they are found and capped, not taken for "no order".)"""
    h = np.asarray(h)
    f = 50.0 + 9e3 * (h / h[0]) ** p
    g = gci(h, f)
    assert g.observed_order == pytest.approx(p, rel=1e-8)
    assert g.order == P_FIT_MAX
    assert g.relative_error[-1] > GCI_SAFETY_THREE * (f[-1] - 50.0) / f[-1]


@pytest.mark.parametrize("f", [(10.0, 10.2, 10.1), (10.0, 10.0, 10.0 + 1e-6),
                               (10.3, 10.1, 10.1)])
def test_without_an_observed_order_the_two_mesh_form_stands_in(f):
    h = np.array([0.04, 0.032, 0.025])
    assert celik_order(h, f) is None
    g = gci(h, f)
    assert g.safety_factor == GCI_SAFETY_TWO and g.order == P_THEORY
    change = np.abs(np.diff(f)).max()
    assert g.relative_error[-1] == pytest.approx(
        GCI_SAFETY_TWO * change / ((h[-2] / h[-1]) ** P_THEORY - 1) / f[-1])


def test_a_converged_sequence_has_no_error():
    g = gci([0.04, 0.032, 0.025], [7.0, 7.0, 7.0])
    assert g.relative_error == [0.0, 0.0, 0.0]


def test_two_mesh_gci_is_three_times_the_richardson_step_at_the_theory_order():
    fine, coarse, ratio = np.array([100.0, 200.0]), np.array([100.4, 201.0]), 1.25
    step = np.abs(fine - coarse) / (ratio**P_THEORY - 1) / fine
    np.testing.assert_allclose(two_mesh_gci(fine, coarse, ratio), 100 * 3 * step)


def test_the_stated_error_of_a_study_is_the_larger_estimate_on_every_size_and_mode():
    sizes = [0.05, 0.04, 0.032, 0.025]
    h = np.asarray(sizes)
    freqs = np.column_stack([100 + 40 * h**1.2, 200 + 5e4 * h**3.8, 300 + 20 * h**2])
    volume = 1e-3
    raw = (3 * volume / h**3).astype(int)  # h_eff = (V / nodes)^(1/3) = h
    study = study_from_values(sizes, freqs, raw, raw, [{}] * 4, volume)
    stated = study.stated_errors
    assert np.all(stated >= study.relative_errors) and np.all(stated >= study.gci_errors)
    assert np.all((stated == study.relative_errors) | (stated == study.gci_errors))
    d = study.to_dict()
    assert d["stated_error"] == stated.tolist()
    assert d["max_relative_error"] == [float(row.max()) for row in stated]
