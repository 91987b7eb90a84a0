"""Test data as vendors export it: public sample files of pyuff's repository
(tests/data/uff/README.md says which and from where) read as far as their content goes, and
a synthetic campaign of ours re-exported as test software writes it (a separate geometry file,
nodes in their own rotated coordinate systems, accelerances along the local axes, large node
labels) giving the same modes, correlation and identification as the original."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

pyuff = pytest.importorskip("pyuff")
pytest.importorskip("sdypy.EMA")

from modaltest import uff  # noqa: E402
from modaltest.campaign import load_campaign  # noqa: E402
from modaltest.placement import NodeError  # noqa: E402
from modaltest.run import run_correlation, run_identification  # noqa: E402
from modaltest.synthesize import PoseTested, write_campaign  # noqa: E402
from tests.conftest import ROOT  # noqa: E402

DATA = ROOT / "tests" / "data" / "uff"
TESTLAB = DATA / "TestLab 161 164 18 15 82.uff"
ACTUATOR = ROOT / "scenes" / "actuator-legs.toml"
SI = {"type": 164, "units_code": 1, "units_description": f"{'SI: Meter (newton)':<20}",
      "temp_mode": 1, "length": 1.0, "force": 1.0, "temp": 1.0, "temp_offset": 273.15}


def sets_of(path: Path, number: int) -> list[dict]:
    u = pyuff.UFF(str(path))
    return [u.read_sets(i) for i, t in enumerate(u.get_set_types()) if int(t) == number]


def test_testlab_geometry_points_each_sensor_along_its_own_system():
    """Testlab's geometry (151, 164 in metres, 36 systems by points (18), 36 nodes (15) each
    measured in its own system): nodes in metres in the global frame, and node k's direction
    codes the axes of its system (+x towards the system's +x point, z in its +xz plane)."""
    g = uff.read_geometry(TESTLAB)
    (nodes,) = sets_of(TESTLAB, 15)
    (systems,) = sets_of(TESTLAB, 18)
    np.testing.assert_array_equal(g.nodes.ids, nodes["node_nums"])
    np.testing.assert_array_equal(g.nodes.xyz, np.column_stack([nodes["x"], nodes["y"],
                                                                nodes["z"]]))  # 164: metres
    frame = {int(n): i for i, n in enumerate(systems["cs_num"])}
    for i, label in enumerate(np.asarray(nodes["disp_cs"], int)):
        k = frame[label]
        axes = g.axes[i]
        np.testing.assert_allclose(axes.T @ axes, np.eye(3), atol=1e-12)
        assert np.linalg.det(axes) == pytest.approx(1.0)
        x = systems["x_point"][k] - systems["ref_o"][k]
        np.testing.assert_allclose(axes[:, 0], x / np.linalg.norm(x), atol=1e-12)
        assert (systems["xz_point"][k] - systems["ref_o"][k]) @ axes[:, 1] == pytest.approx(0)
    # SYS1: its +x point 1 m along global -x from its origin, its xz point 1 m below
    np.testing.assert_allclose(g.dofs([1, 1], [1, -3]).direction, [[-1, 0, 0], [0, 0, 1]],
                               atol=1e-7)  # the file's 6 digits (-8.74228e-08)


def test_a_measured_accelerance_reads_as_receptance_with_the_testlab_geometry():
    """A hammer test's FRFs (pyuff's data/measurement.uff, 2018: accelerance, numerator 12
    over force 13, no nodes, no 164) read with a geometry file: the nodes and the units
    (metres, newtons) are the geometry's, every value divided by -(2 pi f)^2, the 0 Hz line
    dropped; without a geometry file it is refused in one line."""
    path = DATA / "measurement.uff"
    with pytest.raises(uff.UffError, match="no nodes .* no geometry file given"):
        uff.read_uff(path)
    geometry = uff.read_geometry(TESTLAB)
    content = uff.read_uff(path, geometry=geometry)
    raw = sets_of(path, 58)
    frfs = content.frfs
    assert content.length_unit_m == 1.0 and len(frfs.values) == len(raw) == 3
    x = np.asarray(raw[0]["x"])
    np.testing.assert_array_equal(frfs.frequency_hz, x[1:])
    for row, d in enumerate(raw):
        assert d["func_type"] == 4 and d["ordinate_spec_data_type"] == 12
        expected = np.asarray(d["data"])[1:] / -(2 * np.pi * x[1:]) ** 2
        np.testing.assert_allclose(frfs.values[row], expected, rtol=1e-15)
        np.testing.assert_array_equal(frfs.reference.direction[row],
                                      geometry.dofs([d["ref_node"]], [d["ref_dir"]]).direction[0])


def test_nx_node_systems_put_their_x_along_the_beam():
    """NX's export (164 mm, 2420, 2411 of a beam's 18 nodes, each with its own displacement
    system): the nodes in metres on one line, and each system's x axis along that line: the
    2420 matrix's rows are the axes (its transpose would put them across the beam)."""
    g = uff.read_geometry(DATA / "NX simulation output.uff")
    assert g.units == (1000.0, 1000.0) and len(g.nodes.ids) == 18
    xyz = g.nodes.xyz
    line = xyz[np.argmax(xyz[:, 2])] - xyz[np.argmin(xyz[:, 2])]
    line /= np.linalg.norm(line)
    assert np.abs(np.cross(xyz - xyz[0], line)).max() < 1e-9  # one straight line
    assert np.all(np.abs(g.axes[:, :, 0] @ line) > 1 - 1e-6)  # x along it, for every node
    assert np.all(np.abs(np.einsum("nji,j->ni", g.axes, line)[:, 1:]) < 2e-3)


@pytest.mark.parametrize("name, scale", [
    ("Artemis export - Geometry RPBC_setup_05_14102016_105117.uff", 1e-3),  # no 164: mm
    ("mesh_Oros-modal_uff15_uff2412.uff", 1e-3)])  # its 15s in system 1, an 18 identity
def test_geometry_files_of_other_software_read(name, scale):
    path = DATA / name
    g = uff.read_geometry(path)
    nodes = sets_of(path, 15)
    xyz = np.concatenate([np.column_stack([d["x"], d["y"], d["z"]]) for d in nodes])
    np.testing.assert_allclose(g.nodes.xyz, xyz * scale, rtol=1e-15)
    np.testing.assert_array_equal(g.axes, np.tile(np.eye(3), (len(xyz), 1, 1)))


def test_modes_files_read_with_a_geometry_file(tmp_path):
    """Normal modes (55, analysis 2) at nodes 1-4 with Testlab's geometry: their dofs along
    each node's system; complex modes (55, analysis 3) at labels 111111 and 60101 (ME'scope-
    style large labels) with a geometry file of ours giving those nodes."""
    testlab = uff.read_geometry(TESTLAB)
    normal = uff.read_uff(DATA / "uff55_translation.uff", geometry=testlab).modes
    assert len(normal.frequencies_hz) == len(sets_of(DATA / "uff55_translation.uff", 55))
    for node, direction in zip(normal.dofs.node, normal.dofs.direction):
        at = testlab.position()[int(node)]
        assert np.isclose(np.abs(testlab.axes[at].T @ direction).max(), 1.0)
    ours = tmp_path / "nodes.unv"
    uff.write_uff(ours, uff.Nodes([111111, 60101], [[0.1, 0.0, 0.0], [0.2, 0.0, 0.0]]))
    path = DATA / "uff55 sample_test record10.uff"
    complex_modes = uff.read_uff(path, geometry=uff.read_geometry(ours)).modes
    (raw,) = sets_of(path, 55)
    assert raw["analysis_type"] == 3
    eig = complex(raw["eig"])
    assert complex_modes.frequencies_hz[0] == pytest.approx(abs(eig) / (2 * math.pi))
    assert set(complex_modes.dofs.node.tolist()) <= {111111, 60101}


@pytest.mark.parametrize("name, why", [
    ("binary8byte.uff", "neither modes (dataset 55) nor FRFs"),  # a binary 58 of time data
    ("non_ascii_header.uff", "response at node 0"),  # an FRF with no node (0) and no direction
    ("Artemis export - Geometry RPBC_setup_05_14102016_105117.uff", "neither modes")])
def test_vendor_files_without_what_we_read_are_refused_in_one_line(name, why):
    with pytest.raises(uff.UffError) as caught:
        uff.read_uff(DATA / name, geometry=uff.read_geometry(TESTLAB))
    message = str(caught.value)
    assert message.startswith(f"{DATA / name}: ") and why in message and "\n" not in message


@pytest.mark.parametrize("where", ["campaign", "pose"])
def test_a_geometry_not_of_our_machine_names_a_node_on_no_body(tmp_path, where):
    """The campaign loader reads the geometry file a campaign (or a pose) names and places its
    nodes: the Artemis model's nodes are on no body of our machine, refused in one line."""
    sets = [{"type": 55, "analysis_type": 2, "data_ch": 2, "spec_data_type": 8,
             "load_case": 1, "mode_n": 1, "freq": 30.0, "modal_damp_vis": 0.0,
             "node_nums": np.array([16, 17]), "r1": np.array([1.0, 0.5]), "r2": np.zeros(2),
             "r3": np.zeros(2)}]
    (tmp_path / "mode.unv").write_text("")
    uff.write_sets(str(tmp_path / "mode.unv"), sets)
    artemis = DATA / "Artemis export - Geometry RPBC_setup_05_14102016_105117.uff"
    key = f'geometry = "{artemis.as_posix()}"\n'
    (tmp_path / "campaign.toml").write_text(
        f'scene = "{ACTUATOR.as_posix()}"\n' + (key if where == "campaign" else "")
        + '[[pose]]\nname = "p"\nheight_mm = 600.0\ndata = "mode.unv"\n'
        + (key if where == "pose" else ""))
    with pytest.raises(NodeError) as caught:
        load_campaign(tmp_path / "campaign.toml")
    message = str(caught.value)
    assert "pose[0].data" in message and "node 16" in message and "on no body" in message
    assert "\n" not in message


@pytest.mark.parametrize("geometry, why", [
    ("nowhere.unv", "no such file"),
    ("binary8byte.uff", "no nodes (dataset 15 or 2411)")])
def test_a_bad_geometry_file_is_refused_on_the_command_line_naming_the_key(
        capsys, tmp_path, geometry, why):
    """Exit status 2, one line naming the campaign's `geometry` key as typed, nothing
    written; the geometry file is read before any pose's data (and before any solve)."""
    from rps.app import main
    (tmp_path / "campaign.toml").write_text(
        f'scene = "{ACTUATOR.as_posix()}"\ngeometry = "{(DATA / geometry).as_posix()}"\n'
        '[[pose]]\nname = "p"\nheight_mm = 600.0\ndata = "absent.unv"\n')
    out = tmp_path / "out"
    assert main(["correlate", "--campaign", str(tmp_path / "campaign.toml"),
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and why in err, err
    assert f"campaign.toml.geometry = {(DATA / geometry).as_posix()!r}: " in err, err
    assert not out.exists()


def export_as_vendor(original: Path, pose: str, out: Path, placements, geometry) -> None:
    """The pose's file (2411 global + receptances along x, y, z) written again as test
    software would: geometry.unv (164 SI, one 2420 system a node: leg sensors with x along
    their leg, platform sensors turned about z, the driving point's system a permutation of
    the axes; 15 in local coordinates) and the data (164 SI, accelerances along the local
    axes, the 0 Hz line left out, nodes numbered from 900000)."""
    content = uff.read_uff(original / f"{pose}.unv")
    nodes, frfs = content.nodes, content.frfs
    rng = np.random.default_rng(7)
    reference = int(frfs.reference.node[0])
    rows = []
    for node, p in zip(nodes.ids.tolist(), placements):
        if node == reference:
            rows.append(np.roll(np.eye(3), 1, axis=0))  # x = global y, y = z, z = x
        elif p.leg is not None:
            e = geometry.leg_directions[p.leg]
            z = np.cross(e, [0.0, 0.0, 1.0]) / np.linalg.norm(np.cross(e, [0.0, 0.0, 1.0]))
            rows.append(np.vstack([e, np.cross(z, e), z]))
        else:
            c, s = math.cos(a := rng.uniform(0, 2 * math.pi)), math.sin(a)
            rows.append(np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]))
    labels = {n: 900000 + 10 * i for i, n in enumerate(nodes.ids.tolist())}
    local = np.round(rng.uniform(-0.05, 0.05, (len(rows), 3)), 5)  # m, exact in 15's 6 digits
    systems = list(range(1, len(rows) + 1))
    out.mkdir()
    uff.write_sets(str(out / "geometry.unv"), [SI, {
        "type": 2420, "Part_UID": 1, "Part_Name": "vendor", "CS_sys_labels": systems,
        "CS_types": [0] * len(rows), "CS_colors": [8] * len(rows),
        "CS_names": [f"sensor {k}" for k in systems],
        "CS_matrices": [np.vstack([r, p - r.T @ q]) for r, p, q in
                        zip(rows, nodes.xyz, local)]}, {
        "type": 15, "node_nums": [labels[n] for n in nodes.ids.tolist()], "def_cs": systems,
        "disp_cs": systems, "color": [1] * len(rows), "x": local[:, 0], "y": local[:, 1],
        "z": local[:, 2]}])
    at = {n: i for i, n in enumerate(nodes.ids.tolist())}
    ref_local = rows[at[reference]] @ frfs.reference.direction[0]
    axis = int(np.argmax(np.abs(ref_local)))
    ref_code = int(np.sign(ref_local[axis])) * (axis + 1)
    line = frfs.frequency_hz > 0
    f = frfs.frequency_hz[line]
    vectors: dict[int, np.ndarray] = {}
    for node, d, h in zip(frfs.dofs.node.tolist(), frfs.dofs.direction, frfs.values):
        vectors[node] = vectors.get(node, 0) + d[:, None] * h[None, line]
    records = [SI]
    for node, vector in vectors.items():
        for k, a in enumerate(rows[at[node]] @ vector * -(2 * np.pi * f) ** 2):
            records.append({"type": 58, "binary": 1, "func_type": 4, "rsp_node": labels[node],
                            "rsp_dir": k + 1, "ref_node": labels[reference],
                            "ref_dir": ref_code, "abscissa_spacing": 0,
                            "abscissa_spec_data_type": 18, "ordinate_spec_data_type": 12,
                            "orddenom_spec_data_type": 13, "x": f, "data": a})
    uff.write_sets(str(out / f"{pose}.uff"), records)


def test_a_campaign_re_exported_as_a_vendor_would_identifies_the_same(tmp_path):
    """A synthetic FRF campaign and the same test exported as test software writes it: the same
    modes, pairs and identified key. Not to the last bit: the extraction amplifies round-off
    (the FRFs an ulp apart, which the accelerance and the rotations are, move its poles some
    5e-10 and its damping 2e-8, measured), and pLSCF weighs each output by its largest value,
    so sensors along the legs weigh the same motion otherwise (measured: frequencies 6e-10,
    damping 3e-8, MAC 2e-9, the key 1e-9). Tolerances 30 times those."""
    key = "stiffness.actuator_axial_n_per_um"
    tilted = PoseTested("tilted", 640.0, 30.0, 10.0)
    path = write_campaign(ACTUATOR, {key: 110.0}, [tilted], tmp_path / "original", [key],
                          frf_damping=0.02)
    original = load_campaign(path)
    tp = original.poses[0]
    export_as_vendor(tmp_path / "original", "tilted", tmp_path / "vendor", tp.placements,
                     tp.geometry)
    text = path.read_text().replace('data = "tilted.unv"', 'data = "tilted.uff"')
    text = text.replace('scene = "', f'geometry = "geometry.unv"\nscene = "{path.parent}/')
    (tmp_path / "vendor" / "campaign.toml").write_text(text)
    vendor = load_campaign(tmp_path / "vendor" / "campaign.toml")

    a, b = tp.modes, vendor.poses[0].modes
    assert len(a.frequencies_hz) == len(b.frequencies_hz) == 6
    np.testing.assert_allclose(b.frequencies_hz, a.frequencies_hz, rtol=2e-8)
    np.testing.assert_allclose(b.damping_ratios, a.damping_ratios, rtol=1e-6)
    assert all(n >= 900000 for n in vendor.poses[0].nodes.ids)
    pairs = [run_correlation(c, c.analytical, "t")["poses"][0]["pairs"] for c in
             (original, vendor)]
    assert [(p["test_mode"], p["model_mode"]) for p in pairs[0]] == [
        (p["test_mode"], p["model_mode"]) for p in pairs[1]]
    for p, q in zip(*pairs):
        assert q["mac"] == pytest.approx(p["mac"], abs=1e-7)
        assert q["error_percent"] == pytest.approx(p["error_percent"], abs=2e-6)
    found = [run_identification(c, c.analytical, "t")[0]["parameters"][0] for c in
             (original, vendor)]
    assert found[1]["value"] == pytest.approx(found[0]["value"], rel=3e-8)
    assert found[0]["value"] == pytest.approx(110.0, rel=1e-6)
