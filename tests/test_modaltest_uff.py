"""modaltest.uff and modaltest.ema: UFF round trips through pyuff (bitwise where pyuff writes
doubles, at its 6 significant digits where it does not), units, refusals; modes identified with
sdypy-EMA from a synthetic set of receptances."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

pyuff = pytest.importorskip("pyuff")
pytest.importorskip("sdypy.EMA")

from modaltest import ema, uff


def six_digits(values):
    """What pyuff's '%13.5e' (dataset 55) gives back: the double nearest the 6-digit decimal."""
    a = np.asarray(values, dtype=float)
    return np.array([float(f"{v:.5e}") for v in a.ravel()]).reshape(a.shape)


def write_sets(path, sets):
    path.write_text("")
    with warnings.catch_warnings():  # pyuff leaves a 58b's reopened handle to the GC
        warnings.simplefilter("ignore", ResourceWarning)
        pyuff.UFF(str(path)).write_sets(sets, mode="add")
    return path


def nodes_2411(ids, xyz):
    xyz = np.asarray(xyz, dtype=float)
    zeros = np.zeros(len(ids), dtype=int)
    return {"type": 2411, "node_nums": np.asarray(ids), "def_cs": zeros, "disp_cs": zeros,
            "color": zeros, "x": xyz[:, 0], "y": xyz[:, 1], "z": xyz[:, 2]}


def mode_55(ids, r1, r2, r3, hz, damping=0.0):
    return {"type": 55, "analysis_type": 2, "data_ch": 2, "spec_data_type": 8, "load_case": 1,
            "mode_n": 1, "freq": hz, "modal_damp_vis": damping, "node_nums": np.asarray(ids),
            "r1": np.asarray(r1, float), "r2": np.asarray(r2, float), "r3": np.asarray(r3, float)}


def frf_58(rsp, ref, x, data, numerator=8):
    return {"type": 58, "binary": 1, "func_type": 4, "rsp_node": rsp[0], "rsp_dir": rsp[1],
            "ref_node": ref[0], "ref_dir": ref[1], "abscissa_spacing": 0,
            "abscissa_spec_data_type": 18, "ordinate_spec_data_type": numerator,
            "orddenom_spec_data_type": 13, "x": np.asarray(x, float), "data": np.asarray(data)}


SI_UNITS = {"type": 164, "units_code": 1, "units_description": "SI", "temp_mode": 1,
            "length": 1.0, "force": 1.0, "temp": 1.0, "temp_offset": 273.15}


def test_nodes_and_modes_round_trip_at_the_precision_pyuff_writes(tmp_path):
    rng = np.random.default_rng(11)
    ids = np.array([5, 1, 12, 7])
    xyz = rng.uniform(-0.6, 0.6, (4, 3))
    # grouped by node, x, y, z: the order read_uff gives back
    dofs = uff.Dofs.from_codes([5, 5, 5, 1, 12, 12, 7, 7], [1, 2, 3, 3, 1, 2, 2, 3])
    hz = np.array([31.4159265358979, 87.1234567891, 213.987654321])
    damping = np.array([0.0123456789, 0.021, 0.0337])
    shapes = rng.standard_normal((8, 3))
    path = tmp_path / "modes.unv"
    uff.write_uff(path, uff.Nodes(ids, xyz), uff.Modes(hz, damping, dofs, shapes),
                  description="round trip\nof modes")
    content = uff.read_uff(path)

    assert content.path == str(path) and content.frfs is None
    assert content.length_unit_m == 1e-3
    np.testing.assert_array_equal(content.nodes.ids, ids)
    # 2411 holds 17 digits of the mm value: only the m -> mm -> m rounding is left (<= 1 ulp)
    assert np.array_equal(content.nodes.xyz, (xyz * 1000.0) / 1000.0)
    assert np.all(np.abs(content.nodes.xyz - xyz) <= np.spacing(np.abs(xyz)))
    modes = content.modes
    assert modes is not None and modes.damping_ratios is not None
    np.testing.assert_array_equal(modes.dofs.node, dofs.node)
    np.testing.assert_array_equal(modes.dofs.direction, dofs.direction)
    # 55 is written '%13.5e' by pyuff: exactly the 6-digit decimals come back
    np.testing.assert_array_equal(modes.frequencies_hz, six_digits(hz))
    np.testing.assert_array_equal(modes.damping_ratios, six_digits(damping))
    np.testing.assert_array_equal(modes.shapes, six_digits(shapes))
    assert np.max(np.abs(modes.shapes / shapes - 1.0)) <= 5e-6

    uff.write_uff(path, uff.Nodes(ids, xyz), uff.Modes(hz, None, dofs, shapes))
    assert uff.read_uff(path).modes.damping_ratios is None  # all zero in the file: none given


def test_frfs_round_trip_bitwise(tmp_path):
    rng = np.random.default_rng(12)
    nodes = uff.Nodes([1, 2, 3], rng.uniform(-1, 1, (3, 3)))
    f = np.cumsum(rng.uniform(0.1, 0.7, 300))  # uneven on purpose: stored, not rebuilt
    values = rng.standard_normal((4, 300)) + 1j * rng.standard_normal((4, 300))
    frfs = uff.Frfs(f, uff.Dofs.from_codes([1, 2, 3, 3], [3, -2, 1, -3]),
                    uff.Dofs.from_codes([1, 1, 2, 2], [3, 3, -1, -1]), values * 1e-5)
    path = tmp_path / "frfs.uff"
    uff.write_uff(path, nodes, frfs=frfs)
    back = uff.read_uff(path).frfs

    assert back is not None
    assert np.array_equal(back.frequency_hz, f) and np.array_equal(back.values, frfs.values)
    np.testing.assert_array_equal(back.dofs.codes(), [3, -2, 1, -3])
    np.testing.assert_array_equal(back.reference.codes(), [3, 3, -1, -1])
    np.testing.assert_array_equal(back.reference.node, [1, 1, 2, 2])


@pytest.mark.parametrize("units", [None, SI_UNITS], ids=["no 164: mm", "164: metres"])
def test_units_of_a_file(tmp_path, units):
    """Lengths in mm unless a 164 says otherwise; a mobility made receptance; a component that
    is zero in every mode is not measured."""
    xyz = np.array([[0.25, -1.5, 2.125], [1.0, 0.0, -0.5]])  # exact in 15's 6 digits
    f = np.arange(0.0, 50.0, 0.5)
    velocity = (1.0 + 2.0j) * np.ones_like(f)
    sets = [{"type": 15, "node_nums": [1, 2], "def_cs": [0, 0], "disp_cs": [0, 0],
             "color": [0, 0], "x": xyz[:, 0], "y": xyz[:, 1], "z": xyz[:, 2]},
            mode_55([1, 2], [0.5, 0.25], [1.0, 0.0], [0.0, -1.0], 10.0),
            frf_58((2, 3), (1, 3), f, velocity, numerator=11)]
    content = uff.read_uff(write_sets(tmp_path / "units.unv", ([units] if units else []) + sets))

    metres = 1.0 if units else 1e-3
    assert content.length_unit_m == metres
    np.testing.assert_array_equal(content.nodes.xyz, xyz / (1.0 / metres))
    modes = content.modes
    np.testing.assert_array_equal(modes.dofs.node, [1, 1, 2, 2])  # node 1 z, node 2 y: zero
    np.testing.assert_array_equal(modes.dofs.codes(), [1, 2, 1, 3])
    np.testing.assert_array_equal(modes.shapes[:, 0], [0.5, 1.0, 0.25, -1.0])
    frfs = content.frfs
    np.testing.assert_array_equal(frfs.frequency_hz, f[1:])  # 0 Hz: no receptance
    # m/s/N (or mm/s/N without a 164) divided by i omega: m/N
    expected = velocity[1:] * metres / (2j * np.pi * f[1:])
    np.testing.assert_allclose(frfs.values[0], expected, rtol=1e-15)


def synthetic_frfs():
    """Receptances of 4 modes (1-3 % damping) at 8 dofs (one measured in -z), driving point at
    node 1 +z, 0.5 % proportional noise (seeded): (frequencies, damping ratios, shapes, Frfs)."""
    hz = np.array([42.0, 115.0, 230.0, 345.0])
    zeta = np.array([0.01, 0.02, 0.015, 0.03])
    x = (np.arange(8) + 0.5) / 8
    phi = np.array([np.sin((r + 1) * np.pi * x) + 0.3 * np.cos((r + 2) * np.pi * x)
                    for r in range(4)]).T
    codes = np.array([3, 3, -3, 3, 3, 3, 3, 3])
    phi[codes < 0] *= -1.0  # the mode shape seen along -z
    f = np.arange(0.0, 450.0 + 0.125, 0.25)
    w, wr = 2 * np.pi * f, 2 * np.pi * hz
    h = sum(np.outer(phi[:, r] * phi[0, r], 1.0 / (wr[r] ** 2 - w ** 2 + 2j * zeta[r] * wr[r] * w))
            for r in range(4))
    rng = np.random.default_rng(2024)
    h = h * (1 + 0.005 * (rng.standard_normal(h.shape) + 1j * rng.standard_normal(h.shape))
             / np.sqrt(2))
    frfs = uff.Frfs(f, uff.Dofs.from_codes(np.arange(1, 9), codes),
                    uff.Dofs.from_codes(np.ones(8, dtype=int), np.full(8, 3)), h)
    return hz, zeta, phi, frfs


def test_modes_identified_from_synthetic_frfs_written_to_uff(tmp_path, capsys):
    hz, zeta, phi, frfs = synthetic_frfs()
    nodes = uff.Nodes(np.arange(1, 9), np.column_stack([np.linspace(0, 0.7, 8), np.zeros((8, 2))]))
    path = tmp_path / "frfs.unv"
    uff.write_uff(path, nodes, frfs=frfs, description="synthetic receptances")
    content = uff.read_uff(path)
    assert content.modes is None and np.array_equal(content.frfs.values, frfs.values)

    modes = ema.identify_modes(content.frfs, ema.EmaSettings(lower_hz=20.0, upper_hz=400.0))

    assert capsys.readouterr().out == ""  # no progress bar, no print
    assert len(modes.frequencies_hz) == 4
    np.testing.assert_allclose(modes.frequencies_hz, hz, rtol=1e-3)
    np.testing.assert_allclose(modes.damping_ratios, zeta, rtol=0.05)
    np.testing.assert_array_equal(modes.dofs.codes(), frfs.dofs.codes())
    mac = (np.sum(modes.shapes * phi, axis=0) ** 2
           / (np.sum(modes.shapes ** 2, axis=0) * np.sum(phi ** 2, axis=0)))
    assert np.all(mac > 0.99), mac
    assert np.allclose(np.max(np.abs(modes.shapes), axis=0), 1.0)


def test_identification_refuses_a_band_off_the_axis_and_a_band_without_modes():
    _, _, _, frfs = synthetic_frfs()
    with pytest.raises(ema.EmaError, match="outside the FRFs' frequency axis"):
        ema.identify_modes(frfs, ema.EmaSettings(lower_hz=20.0, upper_hz=500.0))
    with pytest.raises(ema.EmaError, match="no pole stable"):
        ema.identify_modes(frfs, ema.EmaSettings(lower_hz=290.0, upper_hz=310.0))


BAD_FILES = {
    "missing": (None, "no such file"),
    "not UFF": ("this is a text file\nnot a universal file\n", "not a universal file"),
    "55 at an undefined node": ([nodes_2411([1, 2], np.eye(2, 3)),
                                 mode_55([1, 3], [1.0, 1.0], [0.0, 0.0], [0.0, 0.0], 12.0)],
                                "node 3, which no 15/2411 defines"),
    "no nodes": ([mode_55([1], [1.0], [0.0], [0.0], 12.0)], "no nodes"),
    "neither 55 nor 58": ([nodes_2411([1], np.eye(1, 3))], "neither modes"),
    "FRF axes differ": ([nodes_2411([1, 2], np.eye(2, 3)),
                         frf_58((1, 1), (2, 1), [1.0, 2.0, 3.0], np.ones(3, complex)),
                         frf_58((2, 1), (2, 1), [1.0, 2.0, 3.5], np.ones(3, complex))],
                        "differs from the first FRF's"),
    "non-finite": ([nodes_2411([1], [[0.0, np.nan, 0.0]]),
                    mode_55([1], [1.0], [0.0], [0.0], 12.0)], "non-finite"),
}


@pytest.mark.parametrize("case", list(BAD_FILES))
def test_refusals_are_one_line_naming_the_file(tmp_path, case):
    content, why = BAD_FILES[case]
    path = tmp_path / "test.unv"
    if isinstance(content, str):
        path.write_text(content)
    elif content is not None:
        write_sets(path, content)
    with pytest.raises(uff.UffError) as caught:
        uff.read_uff(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: ") and why in message and "\n" not in message


def test_write_refuses_what_uff_cannot_hold(tmp_path):
    nodes = uff.Nodes([1], [[0.0, 0.0, 0.0]])
    oblique = uff.Dofs([1], [[0.6, 0.8, 0.0]])
    with pytest.raises(uff.UffError, match="not along x, y or z"):
        uff.write_uff(tmp_path / "x.unv", nodes, uff.Modes([10.0], None, oblique, [[1.0]]))
    elsewhere = uff.Dofs.from_codes([2], [1])
    with pytest.raises(uff.UffError, match="node 2, which the nodes do not define"):
        uff.write_uff(tmp_path / "x.unv", nodes, uff.Modes([10.0], None, elsewhere, [[1.0]]))
    assert not (tmp_path / "x.unv").exists()
