"""The solid FEM against published free-vibration benchmarks (verification/): one marked test
per case (`pytest -m verification`), and fast unmarked tests of the machinery (the record's
structure on a cheap case, pairing by shape on a tiny problem)."""
from __future__ import annotations

import json

import numpy as np
import pytest
from pydantic import TypeAdapter

import results as schema
import verification
from verification import run as vrun
from verification.cases import FV41_TORSION
from verification.shapes import RIGID_RATIO, component_fractions, kth_of_kind, rigid_count

MODE_KEYS = {"label": str, "reference_hz": float, "hz": list, "deviation_percent": float,
             "stated_error_percent": float, "richardson_error_percent": float,
             "gci_percent": float, "tolerance_percent": float, "within_tolerance": bool,
             "bounded": bool, "counted": bool, "passed": bool}
CASE_KEYS = {"name", "title", "source", "discretisation", "what",
             "reference_uncertainty_percent", "tolerance_percent", "tolerance_reason",
             "mesh_sizes_mm", "dofs", "seconds", "modes", "checks", "bound_note", "passed"}


def assert_record(record: dict) -> None:
    """The record has exactly the documented keys and types, and is JSON-ready."""
    assert set(record) == CASE_KEYS
    assert record["discretisation"] in ("tetrahedra", "harmonic")
    n = len(record["mesh_sizes_mm"])
    assert n >= 3 and len(record["dofs"]) == n and len(record["seconds"]) == n
    assert all(a > b for a, b in zip(record["mesh_sizes_mm"], record["mesh_sizes_mm"][1:]))
    for mode in record["modes"]:
        assert set(mode) == set(MODE_KEYS) | {"observed_order", "note"}
        for key, kind in MODE_KEYS.items():
            assert isinstance(mode[key], kind), (key, mode[key])
        assert len(mode["hz"]) == n
        assert mode["observed_order"] is None or isinstance(mode["observed_order"], float)
        assert mode["stated_error_percent"] == max(mode["richardson_error_percent"],
                                                   mode["gci_percent"])
    for check in record["checks"]:
        assert set(check) == {"what", "value", "limit", "op", "passed", "counted"}
    json.dumps(record)
    TypeAdapter(schema.Benchmark).validate_python(record)  # what results.json holds


def test_a_cheap_case_gives_a_complete_record(monkeypatch):
    """The torsion case at coarse sizes: every key and type, the closed form met."""
    coarse = vrun.replace_sizes(FV41_TORSION, (1.0, 0.5, 0.25))
    monkeypatch.setattr(vrun, "CASE_LIST", (coarse,))
    record = vrun.run_case("fv41-torsion")
    assert_record(record)
    assert record["mesh_sizes_mm"] == [1e3, 500.0, 250.0]
    assert abs(record["modes"][0]["deviation_percent"]) < 1e-3


def test_pairing_by_shape_picks_the_mode_of_its_kind():
    """Three dofs-per-node toy spectrum: a rigid mode, then a z mode, then an x mode, then a z
    mode: the first "in-plane" (x) mode is the third of the list, whatever its index."""
    hz = np.array([1e-6, 10.0, 11.0, 12.0])
    vectors = np.zeros((6, 4))
    vectors[[0, 3], 0] = 1.0  # rigid, along x
    vectors[[2, 5], 1] = 1.0  # z
    vectors[[0, 3], 2] = [1.0, -1.0]  # x
    vectors[[2, 5], 3] = [1.0, -1.0]  # z
    fz = component_fractions(vectors, np.eye(6))[2]
    kinds = ["bending" if x > 0.5 else "in-plane" for x in fz]
    assert rigid_count(hz)[0] == 1 and rigid_count(hz)[2] == pytest.approx(RIGID_RATIO * 10)
    assert kth_of_kind(hz, kinds, "in-plane", 1) == 2
    assert kth_of_kind(hz, kinds, "bending", 2) == 3
    with pytest.raises(LookupError):
        kth_of_kind(hz, kinds, "in-plane", 2)


def test_the_cases_are_declared_in_order():
    assert verification.CASES == ("fv52", "fv41", "fv41-torsion", "ring", "fv41-3d", "fv42")


def test_the_sphere_s_exact_radial_frequencies_are_its_frequency_equation_s_roots():
    """FV42's reference: the roots of the free hollow sphere's radial frequency equation,
    checked against the values NAFEMS publishes for modes 1-3 (to their 5 figures) and
    against a thin shell's breathing limit, f = sqrt(2 E / rho / (1 - nu)) / (2 pi R)."""
    from verification.cases import STEEL, sphere_radial_hz

    assert [round(sphere_radial_hz(k), 1) for k in (1, 2)] == [369.9, 838.0]
    assert sphere_radial_hz(3) == pytest.approx(1451.2, abs=0.05)
    e, rho, nu = STEEL.youngs_modulus, STEEL.density, 0.3
    thin = np.sqrt(2 * e / rho / (1 - nu)) / (2 * np.pi * 5.0)
    assert sphere_radial_hz(1, 4.99, 5.01) == pytest.approx(thin, rel=1e-4)


@pytest.mark.verification
@pytest.mark.parametrize("name", verification.CASES)
def test_case_passes(name):
    record = verification.run_case(name)
    assert_record(record)
    failing = [m["label"] for m in record["modes"] if m["counted"] and not m["passed"]]
    assert not failing, failing
    assert all(c["passed"] for c in record["checks"] if c["counted"]), record["checks"]
    # what is not counted says why, and every benchmark still verifies something
    assert all(m["note"] for m in record["modes"] if not m["counted"])
    assert any(m["counted"] for m in record["modes"])
    if record["reference_uncertainty_percent"] == 0:  # a closed form: our own error decides
        assert all(m["bounded"] for m in record["modes"]), record["modes"]
    assert record["passed"]
