"""modaltest.uff_frames through modaltest.uff: coordinate systems (2420 by matrix, 18 by points)
placing nodes and turning their direction codes, a geometry file apart from the data, units
taken from it; and the files we write read by the UFF specification's fixed-width formats."""
from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pyuff")

from modaltest import uff  # noqa: E402

SI = {"type": 164, "units_code": 1, "units_description": "SI", "temp_mode": 1,
      "length": 1.0, "force": 1.0, "temp": 1.0, "temp_offset": 273.15}
IDS = np.array([100001, 2000003, 7, 123456789])  # labels as test software numbers them


def rotation(rng):
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def systems_2420(labels, rows, origins, kinds=None):
    """A 2420: rows 1-3 each system's axes in the global frame, row 4 its origin."""
    return {"type": 2420, "Part_UID": 1, "Part_Name": "test", "CS_sys_labels": list(labels),
            "CS_types": list(kinds or [0] * len(labels)), "CS_colors": [8] * len(labels),
            "CS_names": [f"CS{k}" for k in labels],
            "CS_matrices": [np.vstack([r, o]) for r, o in zip(rows, origins)]}


def nodes_15(ids, xyz, defined, measured):
    xyz = np.asarray(xyz, float)
    return {"type": 15, "node_nums": list(ids), "def_cs": list(defined),
            "disp_cs": list(measured), "color": [1] * len(ids),
            "x": xyz[:, 0], "y": xyz[:, 1], "z": xyz[:, 2]}


def frf(rsp, ref, f, values, numerator):
    return {"type": 58, "binary": 1, "func_type": 4, "rsp_node": int(rsp[0]),
            "rsp_dir": int(rsp[1]), "ref_node": int(ref[0]), "ref_dir": int(ref[1]),
            "abscissa_spacing": 0, "abscissa_spec_data_type": 18,
            "ordinate_spec_data_type": numerator, "orddenom_spec_data_type": 13,
            "x": np.asarray(f, float), "data": np.asarray(values)}


def written(path, sets):
    path.write_text("")
    uff.write_sets(str(path), sets)
    return path


def vector_frfs(frfs):
    """{node: (3, lines)} the FRF vector of each node (sum of direction x value)."""
    out: dict[int, np.ndarray] = {}
    for node, d, h in zip(frfs.dofs.node.tolist(), frfs.dofs.direction, frfs.values):
        out[node] = out.get(node, 0) + d[:, None] * h[None, :]
    return out


def test_the_same_test_in_local_systems_reads_as_in_the_global_frame(tmp_path):
    """Receptances of triaxial sensors in the global frame (2411, codes x, y, z), and the same
    test as a vendor exports it: a geometry file of nodes in their own rotated systems (2420,
    15 in local coordinates), a data file of accelerances along the local axes, its driving
    point coded -1 (the reference node's x axis is global -z). Read, both are one test: the
    same positions and the same FRF vector at every node, to round-off."""
    rng = np.random.default_rng(5)
    p = rng.uniform(-0.6, 0.6, (4, 3))
    f = np.linspace(2.0, 400.0, 150)
    h = (rng.standard_normal((4, 3, 150)) + 1j * rng.standard_normal((4, 3, 150))) * 1e-6
    reference = (IDS[0], 3)
    glob = written(tmp_path / "global.unv", [SI, {
        "type": 2411, "node_nums": IDS, "def_cs": [0] * 4, "disp_cs": [0] * 4,
        "color": [1] * 4, "x": p[:, 0], "y": p[:, 1], "z": p[:, 2]}] + [
        frf((n, k + 1), reference, f, h[i, k], 8) for i, n in enumerate(IDS) for k in range(3)])

    rows = [np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])]  # x = -z
    rows += [rotation(rng) for _ in range(3)]
    q = np.round(rng.uniform(-50.0, 50.0, (4, 3)), 2)  # mm, exact in 15's 6 digits
    origins = [p[i] * 1e3 - rows[i].T @ q[i] for i in range(4)]  # mm, 17 digits in 2420
    mm = dict(SI, units_code=5, length=1000.0, force=1000.0)
    geometry = written(tmp_path / "geometry.unv", [
        mm, systems_2420(range(11, 15), rows, origins), nodes_15(IDS, q, range(11, 15),
                                                                 range(11, 15))])
    w2 = (2 * np.pi * f) ** 2
    local = np.einsum("ikj,ijn->ikn", np.array(rows), h) * -w2  # m/s^2/N along local axes
    data = written(tmp_path / "data.unv", [SI] + [
        frf((n, k + 1), (IDS[0], -1), f, local[i, k], 12) for i, n in enumerate(IDS)
        for k in range(3)])

    one = uff.read_uff(glob)
    other = uff.read_uff(data, geometry=uff.read_geometry(geometry))

    np.testing.assert_array_equal(other.nodes.ids, IDS)
    np.testing.assert_allclose(other.nodes.xyz, one.nodes.xyz, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(other.frfs.reference.direction, one.frfs.reference.direction)
    np.testing.assert_array_equal(other.frfs.frequency_hz, f)
    assert other.length_unit_m == 1.0  # the data file's own 164
    a, b = vector_frfs(one.frfs), vector_frfs(other.frfs)
    for node in IDS.tolist():
        np.testing.assert_allclose(b[node], a[node], rtol=0, atol=1e-15 * np.abs(a[node]).max())
    for i, node in enumerate(IDS.tolist()):  # code k at a node: its system's axis k
        got = other.frfs.dofs.direction[other.frfs.dofs.node == node]
        np.testing.assert_allclose(got, rows[i], atol=1e-15)


def test_systems_by_points_and_their_references(tmp_path):
    """An 18 by origin, +x point and +xz point, one of them defined in another (its reference
    system): the nested system is the product of both; label 1 undefined is the global frame."""
    sets = [SI, {"type": 18, "cs_num": [2, 3], "cs_type": [0, 0], "ref_cs_num": [0, 2],
                 "color": [1, 1], "method": [1, 1], "cs_name": ["A", "B"],
                 "ref_o": [[1.0, 2.0, 3.0], [0.0, 0.0, 1.0]],
                 "x_point": [[1.0, 2.0, 5.0], [0.0, 3.0, 1.0]],  # A: x = +z; B: x = A's +y
                 "xz_point": [[0.0, 2.0, 3.0], [4.0, 0.0, 1.0]]},  # A: z = -x; B: z = A's +x
            nodes_15([1, 2, 3], [[0.5, 0.0, 0.0], [0.5, 0.0, 0.0], [0.5, 0.0, 0.0]],
                     [1, 2, 3], [1, 2, 3])]
    g = uff.read_geometry(written(tmp_path / "points.unv", sets))
    a = np.column_stack([[0, 0, 1], [0, 1, 0], [-1, 0, 0]])  # A's axes, y = z x x
    b = a @ np.column_stack([[0, 1, 0], [0, 0, 1], [1, 0, 0]])  # B's in A's, through A
    np.testing.assert_array_equal(g.axes[0], np.eye(3))
    np.testing.assert_allclose(g.axes[1], a, atol=1e-15)
    np.testing.assert_allclose(g.axes[2], b, atol=1e-15)
    np.testing.assert_allclose(g.nodes.xyz[1], [1.0, 2.0, 3.5], atol=1e-15)
    np.testing.assert_allclose(g.nodes.xyz[2], [1.0, 2.0, 3.0] + a @ [0.0, 0.5, 1.0], atol=1e-15)


def test_a_geometry_file_gives_the_nodes_and_the_units_a_data_file_lacks(tmp_path):
    """A data file of modes alone takes the geometry file's nodes and units (metres here); a
    data file with its own node wins for that label."""
    geometry = uff.read_geometry(written(tmp_path / "g.unv", [SI, nodes_15(
        [5, 6], [[0.25, 0.0, 0.0], [0.5, 0.0, 0.0]], [0, 0], [0, 0])]))
    assert geometry.units == (1.0, 1.0)
    mode = {"type": 55, "analysis_type": 2, "data_ch": 2, "spec_data_type": 8, "load_case": 1,
            "mode_n": 1, "freq": 12.0, "modal_damp_vis": 0.0, "node_nums": np.array([5, 6]),
            "r1": np.array([1.0, 0.5]), "r2": np.zeros(2), "r3": np.zeros(2)}
    alone = uff.read_uff(written(tmp_path / "modes.unv", [mode]), geometry=geometry)
    np.testing.assert_array_equal(alone.nodes.xyz, [[0.25, 0.0, 0.0], [0.5, 0.0, 0.0]])
    assert alone.length_unit_m == 1.0
    own = uff.read_uff(written(tmp_path / "own.unv", [nodes_15([6], [[0.75, 0.0, 0.0]], [0],
                                                               [0]), mode]), geometry=geometry)
    np.testing.assert_array_equal(own.nodes.ids, [6, 5])  # its own first
    np.testing.assert_array_equal(own.nodes.xyz, [[0.75, 0.0, 0.0], [0.25, 0.0, 0.0]])
    assert own.length_unit_m == 1.0  # no 164 of its own: the geometry file's


BAD = {
    "cylindrical": ([systems_2420([4], [np.eye(3)], [np.zeros(3)], kinds=[1]),
                     nodes_15([1], [[1.0, 0.0, 0.0]], [4], [0])], "is cylindrical"),
    "undefined system": ([nodes_15([1], [[1.0, 0.0, 0.0]], [0], [9])],
                         "coordinate system 9, which no 2420/18 defines"),
    "not a rotation": ([systems_2420([4], [np.diag([1.0, 1.0, -1.0])], [np.zeros(3)]),
                        nodes_15([1], [[1.0, 0.0, 0.0]], [0], [4])], "not a rotation"),
    "18 without axes": ([{"type": 18, "cs_num": [2], "cs_type": [0], "ref_cs_num": [0],
                          "color": [1], "method": [1], "cs_name": ["A"],
                          "ref_o": [[0.0, 0.0, 0.0]], "x_point": [[1.0, 0.0, 0.0]],
                          "xz_point": [[2.0, 0.0, 0.0]]}, nodes_15([1], [[0, 0, 0]], [0], [2])],
                        "do not define axes"),
    "no nodes": ([SI], "no nodes"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_a_bad_geometry_is_refused_in_one_line_naming_the_file(tmp_path, case):
    sets, why = BAD[case]
    path = written(tmp_path / "g.unv", sets)
    with pytest.raises(uff.UffError) as caught:
        uff.read_geometry(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: ") and why in message and "\n" not in message, message


# The UFF specification's record formats (I: integer, A: text, E/D: real; width)
FORMATS = {
    164: [[("I", 10), ("A", 20), ("I", 10)], [("D", 25)] * 3, [("D", 25)]],
    2411: [[("I", 10)] * 4, [("D", 25)] * 3],
    55: [[("A", 80)]] * 5 + [[("I", 10)] * 6, [("I", 10)] * 4, [("E", 13)] * 4],
    58: [[("A", 80)]] * 5 + [
        [("I", 5), ("I", 10), ("I", 5), ("I", 10), ("X", 1), ("A", 10), ("I", 10), ("I", 4),
         ("X", 1), ("A", 10), ("I", 10), ("I", 4)],
        [("I", 10)] * 3 + [("E", 13)] * 3] + [
        [("I", 10)] + [("I", 5)] * 3 + [("X", 1), ("A", 20), ("X", 1), ("A", 20)]] * 4,
}


def check_record(line: str, fields: list[tuple[str, int]], where: str) -> list:
    """The fields of a fixed-width record, each parsed as its type; the line no wider."""
    assert len(line) <= sum(w for _, w in fields), (where, line)
    out, at = [], 0
    for kind, width in fields:
        text = line[at:at + width]
        at += width
        if kind == "I":
            out.append(int(text))
        elif kind in "ED":
            out.append(float(text.replace("D", "E")))
        elif kind == "X":
            assert text.strip() == "", (where, line)
        else:
            out.append(text)
    return out


def datasets(raw: bytes):
    """(number, binary, header lines, binary bytes) of every dataset of a file we wrote."""
    at = 0
    while (start := raw.find(b"    -1\n", at)) >= 0:
        head_end = raw.index(b"\n", start + 7)
        head = raw[start + 7:head_end].decode()
        number, binary = int(head[:6]), head[6:7] == "b"
        if binary:
            ascii_end = head_end
            for _ in range(int(head[19:31])):
                ascii_end = raw.index(b"\n", ascii_end + 1)
            end = raw.index(b"    -1\n", ascii_end + 1 + int(head[31:43]))
            lines = raw[head_end + 1:ascii_end].decode().split("\n")
            yield number, head, lines, raw[ascii_end + 1:end]
        else:
            end = raw.index(b"\n    -1\n", head_end)
            yield number, head, raw[head_end + 1:end].decode().split("\n"), b""
        at = end + len(b"    -1\n") + (1 if not binary else 0)


@pytest.mark.parametrize("binary", [True, False], ids=["58b", "58 ASCII"])
def test_written_files_keep_the_specification_field_widths(tmp_path, binary):
    """Every dataset we write parses by the specification's fixed-width record formats; a
    binary 58 states the bytes it holds (record 1: FORMAT(I6,1A1,I6,I6,I12,I12,I6,I6,I12,I12),
    3 doubles a line: frequency, real, imaginary); the 164's description starts its field."""
    rng = np.random.default_rng(3)
    nodes = uff.Nodes(IDS, rng.uniform(-1, 1, (4, 3)))
    dofs = uff.Dofs.from_codes(np.repeat(IDS, 3), np.tile([1, 2, 3], 4))
    modes = uff.Modes([11.0, 23.5], [0.01, 0.02], dofs, rng.standard_normal((12, 2)))
    f = np.cumsum(rng.uniform(0.1, 0.7, 41))
    h = rng.standard_normal((2, 41)) + 1j * rng.standard_normal((2, 41))
    frfs = uff.Frfs(f, uff.Dofs.from_codes(IDS[:2], [3, -2]),
                    uff.Dofs.from_codes(IDS[[0, 0]], [3, 3]), h)
    path = tmp_path / "ours.unv"
    uff.write_uff(path, nodes, modes, frfs, description="widths", binary=binary)

    seen = []
    for number, head, lines, blob in datasets(path.read_bytes()):
        seen.append(number)
        for k, fields in enumerate(FORMATS[number]):
            values = check_record(lines[k], fields, f"{number} record {k + 1}")
            if number == 164 and k == 0:
                assert values[1] == f"{'mm (milli-newton)':<20}", values
        if number == 58 and binary:
            fields = [("I", 6), ("A", 1), ("I", 6), ("I", 6), ("I", 12), ("I", 12), ("I", 6),
                      ("I", 6), ("I", 12), ("I", 12)]
            values = check_record(head, fields, "58b record 1")
            assert values[1:5] == ["b", 1, 2, 11] and values[5] == len(blob) == 24 * len(f)
            np.testing.assert_array_equal(np.frombuffer(blob, "<f8")[0::3], f)
        elif number == 58:
            assert head.strip() == "58" and len(lines) == 11 + len(f)
            for line in lines[11:]:  # abscissa, real, imaginary
                check_record(line, [("E", 13), ("E", 20), ("E", 20)], "58 data")
    assert seen == [164, 2411, 55, 55, 58, 58]

    back = uff.read_uff(path).frfs
    if binary:
        assert np.array_equal(back.values, h) and np.array_equal(back.frequency_hz, f)
    else:  # pyuff's ASCII: values '%20.11e' (12 digits), frequencies '%13.5e' (6)
        np.testing.assert_allclose(back.values, h, rtol=1e-11)
        np.testing.assert_allclose(back.frequency_hz, f, rtol=5e-6)
