"""A UFF file's coordinate systems (datasets 2420, 18) and its nodes (15, 2411) in the base
frame: where each node is (m) and the axes its direction codes 1, 2, 3 mean (unit vectors of
the base frame). Pure functions of pyuff's dicts; `uff.read_geometry` / `uff.read_uff` read
the files.

The conventions (the UFF specification's text, pyuff's fields):
- 2420 (I-DEAS, NX): per system a label, a type (0 Cartesian, 1 cylindrical, 2 spherical) and
  a 4 x 3 "transformation matrix": rows 1-3 the local x, y, z axes as direction cosines in the
  global (part) frame, row 4 the origin (file length units). A local point q is at
  o + R^T q. (The rows are the axes: in NX's export `tests/data/uff/NX simulation output.uff`
  each beam node's system has its x along the beam and the other two turned about it, which
  the transposed reading would not give.) The matrix must be a rotation within 1e-6.
- 18 (the older form, Testlab's): origin, a point on +x and a point in the +xz plane, in a
  reference system (field 3; 0 the global frame), resolved through its references.
- A node's definition system (15 field 2) holds its coordinates; a 2411's coordinates are in
  the part (global) frame whatever its field 2 (the export system) says. Its displacement
  system (field 3 of both) holds its measured directions: code k is that system's axis k.
- Labels: 0 is the global frame; 1 too when no 2420/18 defines it (the I-DEAS default test
  software writes); any other label a node uses must be defined (in the file, or in the
  campaign's geometry file). Cylindrical and spherical systems are refused when a node or an
  18 uses them (their angle unit and axes order differ between writers).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from .measured import Dofs, FloatArray, Nodes, UffError

ORTHONORMAL = 1e-6  # |R R^T - I| of a 2420 matrix read from its 17 digits: a rotation
_KINDS = {0: "Cartesian", 1: "cylindrical", 2: "spherical"}


@dataclass(frozen=True, eq=False)
class Frame:
    """A coordinate system: its axes (columns: unit vectors of the base frame), origin (m),
    type (0 Cartesian, 1 cylindrical, 2 spherical) and the dataset that defines it."""

    axes: FloatArray  # (3, 3)
    origin: FloatArray  # (3,)
    kind: int
    where: str


GLOBAL = Frame(np.eye(3), np.zeros(3), 0, "the global frame")


@dataclass(frozen=True, eq=False)
class Geometry:
    """Nodes in the base frame (m) and each node's measuring axes: axes[i][:, k] is the unit
    vector direction code k + 1 means at node i; `frames` the file's coordinate systems (for
    the files that refer to them), `units` its 164's (length, force) per SI unit, None without
    one."""

    path: str
    nodes: Nodes
    axes: FloatArray  # (n, 3, 3)
    frames: Mapping[int, Frame]
    units: tuple[float, float] | None

    def position(self) -> dict[int, int]:
        return {int(n): i for i, n in enumerate(self.nodes.ids)}

    def dofs(self, node_ids: Any, codes: Any) -> Dofs:
        """Dofs of UFF direction codes (+-1..3) at known nodes, in the base frame."""
        at = self.position()
        c = np.asarray(codes, dtype=np.int64)
        rows = np.array([at[int(n)] for n in np.asarray(node_ids).tolist()], dtype=np.int64)
        picked = self.axes[rows, :, np.abs(c) - 1] if len(rows) else np.zeros((0, 3))
        return Dofs(np.asarray(node_ids), np.sign(c)[:, None] * picked)


def frames_of(sets: list[tuple[int, dict[str, Any]]], length: float) -> dict[int, Frame]:
    """Every coordinate system a file's 2420s and 18s define (18s through their references),
    by label; `length` file length units per metre."""
    found: dict[int, Frame] = {}
    points: dict[int, tuple[int, Any, str]] = {}  # 18: label -> (reference, (o, x, xz), where)
    for index, d in sets:
        if d["type"] == 2420:
            for label, kind, m in zip(d["CS_sys_labels"], d["CS_types"], d["CS_matrices"]):
                where = f"dataset {index} (2420)"
                found[int(label)] = _from_matrix(np.asarray(m, dtype=np.float64), int(kind),
                                                 length, f"{where}, system {int(label)}")
        elif d["type"] == 18:
            for label, kind, ref, o, x, xz in zip(d["cs_num"], d["cs_type"], d["ref_cs_num"],
                                                  d["ref_o"], d["x_point"], d["xz_point"]):
                where = f"dataset {index} (18), system {int(label)}"
                if int(kind) != 0:
                    found[int(label)] = Frame(np.eye(3), np.zeros(3), int(kind), where)
                else:
                    metres = tuple(np.asarray(v, dtype=np.float64) / length for v in (o, x, xz))
                    points[int(label)] = (int(ref), metres, where)
    for label in points:
        found[label] = _resolved(label, points, found, ())
    return found


def _from_matrix(m: np.ndarray, kind: int, length: float, where: str) -> Frame:
    if m.shape != (4, 3) or not np.all(np.isfinite(m)):
        raise UffError(f"{where}: its matrix is not 4 x 3 finite numbers")
    rows = m[:3]
    if (np.abs(rows @ rows.T - np.eye(3)).max() > ORTHONORMAL
            or np.linalg.det(rows) <= 0.0):
        raise UffError(f"{where}: rows 1-3 of its matrix are not a rotation (orthonormal "
                       f"within {ORTHONORMAL:g}, right-handed)")
    axes = rows.T / np.linalg.norm(rows.T, axis=0)
    return Frame(axes, m[3] / length, kind, where)


def _resolved(label: int, points: dict[int, tuple[int, Any, str]], found: dict[int, Frame],
              seen: tuple[int, ...]) -> Frame:
    """An 18's system in the base frame (its points in metres), its reference resolved
    first."""
    if label in found:
        return found[label]
    ref, (o, x, xz), where = points[label]
    if label in seen:
        raise UffError(f"{where}: its reference systems go round in a circle "
                       f"({' -> '.join(str(s) for s in (*seen, label))})")
    if ref == 0 or (ref == 1 and ref not in points and ref not in found):
        base = GLOBAL
    elif ref in points:
        base = _resolved(ref, points, found, (*seen, label))
    elif ref in found:
        base = found[ref]
    else:
        raise UffError(f"{where}: its reference system {ref} is not defined in the file")
    if base.kind != 0:
        raise UffError(f"{where}: its reference system {ref} is "
                       f"{_KINDS.get(base.kind, f'of type {base.kind}')}; only Cartesian "
                       "systems are read")
    ex, v = x - o, xz - o
    ez = v - (v @ ex) / (ex @ ex) * ex if ex @ ex > 0.0 else v
    if not (np.all(np.isfinite([*o, *x, *xz])) and np.linalg.norm(ex) > 0.0
            and np.linalg.norm(ez) > 1e-9 * np.linalg.norm(v)):
        raise UffError(f"{where}: its points do not define axes (the +x point on the origin, "
                       "or the +xz point on the x axis)")
    ex, ez = ex / np.linalg.norm(ex), ez / np.linalg.norm(ez)
    local = np.column_stack([ex, np.cross(ez, ex), ez])
    found[label] = Frame(base.axes @ local, base.origin + base.axes @ o, 0, where)
    return found[label]


def nodes_of(sets: list[tuple[int, dict[str, Any]]], length: float,
             frames: Mapping[int, Frame]) -> tuple[Nodes, FloatArray] | None:
    """The nodes of a file's 15s and 2411s in the base frame (m) and their measuring axes;
    None without any. `frames`: the systems by label (the file's, and the geometry file's)."""
    ids: list[int] = []
    xyz: list[FloatArray] = []
    axes: list[FloatArray] = []
    for index, d in sets:
        if d["type"] not in (15, 2411):
            continue
        raw = np.column_stack([d["x"], d["y"], d["z"]]).astype(np.float64) / length
        for node_id, p, defined, measured in zip(d["node_nums"], raw, d["def_cs"], d["disp_cs"]):
            node = int(node_id)
            where = f"dataset {index} ({d['type']}), node {node}"
            if d["type"] == 15:  # in its definition system (2411: in the part frame)
                frame = _frame(frames, int(defined), where)
                p = frame.origin + frame.axes @ p
            ids.append(node)
            xyz.append(p)
            axes.append(_frame(frames, int(measured), where).axes)
    if not ids:
        return None
    return Nodes(np.array(ids), np.array(xyz)), np.array(axes)


def _frame(frames: Mapping[int, Frame], label: int, where: str) -> Frame:
    if label == 0 or (label == 1 and 1 not in frames):
        return GLOBAL
    if label not in frames:
        raise UffError(f"{where}: coordinate system {label}, which no 2420/18 defines (in "
                       "the file or the campaign's geometry file)")
    frame = frames[label]
    if frame.kind != 0:
        kind = _KINDS.get(frame.kind, f"of type {frame.kind}")
        raise UffError(f"{where}: coordinate system {label} is {kind} ({frame.where}); only "
                       "Cartesian systems are read")
    return frame
