"""Universal File Format (UFF) files read and written through pyuff (never parsed by hand):
units (164), coordinate systems (2420, 18), nodes (15, 2411), modes (55), FRFs (58). SI inside:
metres, hertz, m/N; directions unit vectors of the base frame.

Reading (`read_geometry`, `read_uff`; any refusal is a `UffError`, one line naming the file
and the problem):
- units: a file's 164 gives its factors (file units per SI unit); a file without one takes its
  geometry file's, else mm and N. (151 is the header, no units; the 58's unit exponents and
  labels are documentation, often zero: the conversion follows its data types.)
- nodes and their systems (`uff_frames`): a geometry file (`read_geometry`: 15/2411 and
  2420/18, nothing else needed) holds a campaign's nodes; a data file may hold its own, which
  win for the labels both define, and may use the geometry file's systems. A node's
  definition system places it, its displacement system turns its direction codes: code k is
  that system's axis k in the base frame (a triaxial sensor along a leg);
- modes: one 55 per mode, in file order; normal modes (analysis type 2) give the frequency and
  the modal viscous damping ratio, complex ones (3, 7) the eigenvalue in rad/s (f = |lambda| /
  2 pi, zeta = -Re lambda / |lambda|) and shapes made real by the best common phase rotation
  (`complex_to_real_shape`). Three translations per node (six only with zero rotations). A
  component exactly 0 in every mode is taken as NOT measured, left out of `Modes.dofs` (the dofs
  come grouped by node, in order of appearance, codes 1, 2, 3). Shapes keep the file's numbers;
- FRFs: 58s (ASCII or binary) of function type 4, directions +-1/2/3 (negative: minus, kept),
  rotations refused; numerator displacement, velocity or acceleration, denominator force
  (unknown types taken as these), converted to receptance in m/N (at 0 Hz a mobility or
  accelerance cannot be: that line is dropped for every FRF); one frequency axis for all;
- a shape or FRF at a node no 15/2411 defines is refused, and so is any non-finite number.

Writing (`write_uff`): 164 (code 5: mm and mN, coherent with kg, so receptances and mass-
normalised shapes keep their SI numbers), 2411 nodes in mm (global), one 55 per mode, one 58
per FRF (receptance, with its frequencies): binary by default, its header's byte count
corrected (pyuff counts 8 bytes a point where a complex record with frequencies has 24), or
ASCII (`binary=False`: pyuff's '%20.11e' values, 12 digits, and '%13.5e' frequencies, 6).
The round trip is as exact as pyuff allows: 2411 has 17 digits, a coordinate returns as
(x * 1000) / 1000 (within 1 ulp); 58b holds raw doubles, FRFs return bitwise; 55 is written
'%13.5e' (no double option), frequencies, damping ratios and shapes return as
float(f'{v:.5e}'), 6 significant digits.
"""
from __future__ import annotations

import math
import os
import re
import warnings
from typing import Any

import numpy as np
import pyuff

from common.atomic import atomic_write
from common.messages import one_line

from .measured import (
    ComplexArray,
    Dofs,
    FloatArray,
    Frfs,
    IntArray,
    Modes,
    Nodes,
    UffContent,
    UffError,
    complex_to_real_shape,
)
from .uff_frames import Geometry, frames_of, nodes_of

__all__ = ["ComplexArray", "Dofs", "FloatArray", "Frfs", "Geometry", "IntArray", "Modes",
           "Nodes", "UffContent", "UffError", "complex_to_real_shape", "read_geometry",
           "read_uff", "write_sets", "write_uff"]

MM_PER_M = 1000.0
# a modal test's file per pose: some thousand FRFs of some thousand lines is tens of MB in
# binary 58, an ASCII one a few times that; beyond, pyuff's whole-file read is the wrong tool
MAX_FILE_BYTES = 500e6
# A receptance no structure yields on any line a test exports: a machine on its base is some
# 1e-9 to 1e-5 m/N, a free 1 kg piece 1 / (m w^2) = 2.5e4 m/N at 1 mHz, and an accelerance's
# noise divided by w^2 on a first line near 0 Hz a few thousand. Above, the numbers are corrupt
# (a receptance near the largest double overflows every fit that squares it).
MAX_RECEPTANCE = 1e12  # m/N
_DEFAULT_UNITS = (MM_PER_M, 1.0)  # a file without a 164 (nor a geometry file's): mm and N
# the description left-justified in its 20 columns (FORMAT(I10,20A1,I10)), as test software
# writes it; pyuff right-justifies a shorter one ('%20s')
_WRITE_UNITS = {"type": 164, "units_code": 5, "units_description": f"{'mm (milli-newton)':<20}",
                "temp_mode": 2, "length": 1000.0, "force": 1000.0, "temp": 1.0,
                "temp_offset": 273.15}
_READ = {15, 18, 55, 58, 164, 2411, 2420}
_NUMERATOR_POWER = {0: 0, 8: 0, 11: 1, 12: 2}  # unknown, displacement, velocity, acceleration
_DENOMINATOR = {0, 9, 13}  # unknown, reaction force, excitation force
_ABSCISSA = {0, 18}  # unknown, frequency (Hz)
_Sets = list[tuple[int, dict[str, Any]]]  # (dataset number in the file, pyuff's dict)


def read_geometry(path: str | os.PathLike[str], shown: str | None = None) -> Geometry:
    """A campaign's geometry file: nodes (15, 2411) and coordinate systems (2420, 18) in SI,
    the nodes in the base frame (module docstring); it may hold nothing else."""
    name = os.fspath(path)
    label = name if shown is None else shown
    try:
        sets = _read_sets(name)
        units = _units(sets)
        length = (units or _DEFAULT_UNITS)[0]
        frames = frames_of(sets, length)
        found = nodes_of(sets, length, frames)
        if found is None:
            raise UffError("no nodes (dataset 15 or 2411)")
    except UffError as exc:
        raise UffError(f"{label}: {exc}" if label else str(exc)) from None
    return Geometry(name, found[0], found[1], frames, units)


def read_uff(path: str | os.PathLike[str], shown: str | None = None,
             geometry: Geometry | None = None) -> UffContent:
    """Nodes, modes (55) and FRFs (58) of a UFF file, in SI (module docstring for the rules).
    With `geometry` (`read_geometry`'s) the file may hold no nodes: the geometry's are used,
    and its own (if any) win for the labels both define. A refusal starts with `shown`
    (default: the path; "": nothing, the caller names it)."""
    name = os.fspath(path)
    label = name if shown is None else shown
    try:
        size = os.path.getsize(name) if os.path.isfile(name) else 0
        if size > MAX_FILE_BYTES:
            raise UffError(f"{size / 1e6:.0f} MB; at most {MAX_FILE_BYTES / 1e6:.0f} MB are read "
                           "(pyuff holds a whole file in memory): split it per pose or band")
        sets = _read_sets(name)
        if not any(d["type"] == 55 or (d["type"] == 58 and d["func_type"] == 4) for _, d in sets):
            raise UffError("neither modes (dataset 55) nor FRFs (dataset 58, function type 4)")
        length, force = _units(sets) or (geometry and geometry.units) or _DEFAULT_UNITS
        nodes = _merged(sets, length, geometry)
        modes = _modes(sets, nodes)
        frfs = _frfs(sets, nodes, force / length)
        if modes is None and frfs is None:
            raise UffError("neither modes (dataset 55) nor FRFs (dataset 58, function type 4)")
    except UffError as exc:
        raise UffError(f"{label}: {exc}" if label else str(exc)) from None
    return UffContent(name, nodes.nodes, modes, frfs, 1.0 / length)


def _merged(sets: _Sets, length: float, geometry: Geometry | None) -> Geometry:
    """The file's own nodes (its systems, else the geometry file's), and the geometry file's
    nodes it does not define."""
    frames = dict(geometry.frames) if geometry is not None else {}
    frames.update(frames_of(sets, length))
    own = nodes_of(sets, length, frames)
    if own is None:
        if geometry is None:
            raise UffError("no nodes (dataset 15 or 2411), and no geometry file given")
        return geometry
    if geometry is None:
        return Geometry("", own[0], own[1], frames, None)
    mine = set(own[0].ids.tolist())
    rest = [i for i, n in enumerate(geometry.nodes.ids.tolist()) if n not in mine]
    nodes = Nodes(np.concatenate([own[0].ids, geometry.nodes.ids[rest]]),
                  np.concatenate([own[0].xyz, geometry.nodes.xyz[rest]]))
    return Geometry("", nodes, np.concatenate([own[1], geometry.axes[rest]]), frames, None)


def _read_sets(name: str) -> _Sets:
    if not os.path.isfile(name):
        raise UffError("not a regular file" if os.path.exists(name) else
                       "a symbolic link that leads nowhere (broken, or a loop)"
                       if os.path.islink(name) else "no such file")
    try:
        uff = pyuff.UFF(name)
        types = [int(t) for t in uff.get_set_types()]
    except Exception as exc:
        raise UffError(f"cannot be read ({one_line(exc)})") from None
    if not any(t > 0 for t in types):
        raise UffError("not a universal file (no dataset between '-1' delimiter lines)")
    _check_whole(name, uff, types)
    out = []
    for i, t in enumerate(types):
        if t in _READ:
            try:
                out.append((i + 1, uff.read_sets(i)))
            except Exception as exc:
                raise UffError(f"dataset {i + 1} (type {t}) cannot be read by pyuff: "
                               f"{one_line(exc)}") from None
    return out


def _check_whole(name: str, uff: Any, types: list[int]) -> None:
    """Refuse a file that goes on after its last complete dataset: a dataset opened by a '-1'
    line and never closed is a file cut short (a copy or a download broken off), whose
    complete datasets alone would be read as if they were all. pyuff pairs the delimiter
    lines and keeps where each dataset ends; what follows the last one's closing line must
    be blank."""
    ends = getattr(uff, "_block_ind", None)  # pyuff's (start, end) of each dataset
    if ends is None or not len(ends):
        return
    with open(name, "rb") as fh:
        fh.seek(int(ends[-1][1]) + 1)
        tail = fh.read()
    if not tail.startswith(b"    -1"):  # not where pyuff said: no claim either way
        return
    rest = re.split(rb"\r\n|\r|\n", tail, maxsplit=1)  # past the closing '-1' line
    if len(rest) == 2 and rest[1].strip(b" \t\r\n\x00\x1a"):  # NUL, ^Z: padding
        raise UffError(f"ends inside a dataset begun after dataset {len(types)} (type "
                       f"{types[-1]}): the file is cut short (a truncated copy?) or holds "
                       "text outside the '-1' delimiter lines; none of it is read")


def _units(sets: _Sets) -> tuple[float, float] | None:
    """(file length units per metre, file force units per newton) of the file's 164; None
    without one."""
    found = {(float(d["length"]), float(d["force"])) for _, d in sets if d["type"] == 164}
    if not found:
        return None
    if len(found) > 1:
        raise UffError(f"{len(found)} different unit systems (dataset 164)")
    length, force = found.pop()
    if not (math.isfinite(length) and length > 0.0 and math.isfinite(force) and force > 0.0):
        raise UffError(f"dataset 164: unusable unit factors (length {length}, force {force})")
    return length, force


def _modes(sets: _Sets, geometry: Geometry) -> Modes | None:
    known = geometry.position()
    order: dict[int, int] = {}  # node id -> position, by first appearance
    columns: list[dict[int, Any]] = []
    info: list[tuple[float, float, bool]] = []  # frequency, damping ratio, complex shape
    for index, d in sets:
        if d["type"] != 55 or d["analysis_type"] not in (2, 3, 7):
            continue
        where = f"dataset {index} (55, mode {len(info) + 1})"
        if d["analysis_type"] == 2:
            f, z = float(d["freq"]), float(d.get("modal_damp_vis", 0.0))
        else:
            eig = complex(d["eig"])
            f, z = abs(eig) / (2.0 * math.pi), (-eig.real / abs(eig) if eig != 0 else 0.0)
        ndv = d["n_data_per_node"]
        if ndv not in (3, 6) or (ndv == 6 and any(np.any(d[r] != 0) for r in ("r4", "r5", "r6"))):
            raise UffError(f"{where}: {ndv} values per node, not 3 translations (or 6, zero turns)")
        values = np.stack([np.asarray(d[r]) for r in ("r1", "r2", "r3")], axis=1)
        column: dict[int, Any] = {}
        for node_id, v in zip(np.asarray(d["node_nums"]).tolist(), values):
            if node_id not in known:
                raise UffError(f"{where}: shape at node {node_id}, which no 15/2411 defines "
                               "(in the file or the geometry file)")
            if node_id in column:
                raise UffError(f"{where}: node {node_id} given twice")
            column[node_id] = v
            order.setdefault(node_id, len(order))
        if not (math.isfinite(f) and f > 0.0):
            raise UffError(f"{where}: frequency {f:g} Hz; a mode has a positive frequency "
                           "(a rigid-body mode of a free test piece is not one of the machine's)")
        if not all(np.all(np.isfinite(v)) for v in column.values()):
            raise UffError(f"{where}: non-finite numbers in its shape")
        if not any(np.any(v != 0) for v in column.values()):
            raise UffError(f"{where}: its shape is zero at every node: no mode was measured")
        if columns and set(column) != set(columns[0]):
            raise UffError(f"{where}: shape at {len(column)} nodes, where mode 1 has it at "
                           f"{len(columns[0])} ({_node_difference(column, columns[0])}): "
                           "a partial dataset; every mode is measured at the same nodes")
        columns.append(column)
        info.append((f, z, bool(np.iscomplexobj(values))))
    if not columns:
        return None
    full = np.zeros((3 * len(order), len(columns)), dtype=np.complex128)
    for r, column in enumerate(columns):
        for node_id, v in column.items():
            full[3 * order[node_id]:3 * order[node_id] + 3, r] = v
    hz, zeta, is_complex = (np.array(v) for v in zip(*info))
    if not (np.all(np.isfinite(full)) and np.all(np.isfinite(hz)) and np.all(np.isfinite(zeta))):
        raise UffError("non-finite numbers in a mode (dataset 55)")
    measured = np.any(full != 0, axis=1)  # not all zero: each mode's shape was checked above
    full = full[measured]
    shapes = np.column_stack([complex_to_real_shape(full[:, r]) if is_complex[r]
                              else full[:, r].real for r in range(len(columns))])
    codes = np.tile(np.arange(1, 4), len(order))[measured]
    dofs = geometry.dofs(np.repeat(np.array(list(order), dtype=np.int64), 3)[measured], codes)
    return Modes(hz, zeta if np.any(zeta != 0.0) else None, dofs, shapes)


def _node_difference(column: dict[int, Any], first: dict[int, Any]) -> str:
    missing = sorted(set(first) - set(column))
    extra = sorted(set(column) - set(first))
    return (f"node {missing[0]} missing" if missing else f"node {extra[0]} added")


def _frfs(sets: _Sets, geometry: Geometry, factor: float) -> Frfs | None:
    known = geometry.position()
    rows: list[Any] = []
    powers: list[int] = []
    ends: list[list[int]] = []  # response node, code, reference node, code
    axis: FloatArray | None = None
    for index, d in sets:
        if d["type"] != 58 or d["func_type"] != 4:
            continue
        where = f"dataset {index} (58, FRF {len(rows) + 1})"
        end = [int(d[k]) for k in ("rsp_node", "rsp_dir", "ref_node", "ref_dir")]
        for what, node_id, code in (("response", end[0], end[1]), ("reference", end[2], end[3])):
            if node_id not in known:
                raise UffError(f"{where}: {what} at node {node_id}, which no 15/2411 defines "
                               "(in the file or the geometry file)")
            if not 1 <= abs(code) <= 3:
                raise UffError(f"{where}: {what} direction {code}, not a translation (+-1..3)")
        ends.append(end)
        num, den = d["ordinate_spec_data_type"], d["orddenom_spec_data_type"]
        if d["abscissa_spec_data_type"] not in _ABSCISSA:
            raise UffError(f"{where}: abscissa type {d['abscissa_spec_data_type']} (not Hz)")
        if num not in _NUMERATOR_POWER or den not in _DENOMINATOR:
            raise UffError(f"{where}: ordinate types {num}/{den} are not displacement, "
                           "velocity or acceleration per force; cannot convert to receptance")
        x, data = np.asarray(d["x"], dtype=np.float64), np.asarray(d["data"])
        if not np.iscomplexobj(data):
            raise UffError(f"{where}: real-valued data; an FRF is complex")
        if len(x) != len(data) or not (np.all(np.isfinite(x)) and np.all(np.isfinite(data))):
            raise UffError(f"{where}: non-finite numbers, or not one value per frequency")
        if axis is None:
            if len(x) < 2 or x[0] < 0.0 or np.any(np.diff(x) <= 0.0):
                raise UffError(f"{where}: frequencies not increasing from >= 0 Hz")
            axis = x
        elif len(x) != len(axis) or np.max(np.abs(x - axis)) > 1e-9 * np.max(np.abs(axis)):
            raise UffError(f"{where}: its frequency axis ({len(x)} lines, {x[0]:g}-{x[-1]:g} "
                           f"Hz) differs from the first FRF's ({len(axis)} lines, "
                           f"{axis[0]:g}-{axis[-1]:g} Hz)")
        rows.append(data)
        powers.append(_NUMERATOR_POWER[num])
    if axis is None:
        return None
    values = np.array(rows, dtype=np.complex128)
    if factor != 1.0:
        values = values * factor
    if any(powers) and axis[0] == 0.0:  # mobility/accelerance: no receptance at 0 Hz
        axis, values = axis[1:], values[:, 1:]
    omega = 2.0 * np.pi * axis
    for i, p in enumerate(powers):
        if p == 1:
            values[i] = values[i] / (1j * omega)
        elif p == 2:
            values[i] = values[i] / -(omega * omega)
    largest = np.abs(values).max(axis=1)  # m/N; overflows and unit slips end up far above
    if np.any(~np.isfinite(largest) | (largest > MAX_RECEPTANCE)):
        i = int(np.argmax(np.where(np.isfinite(largest), largest, np.inf)))
        raise UffError(f"dataset {_index58(sets, i)} (58, FRF {i + 1}): a receptance of "
                       f"{largest[i]:.3g} m/N (as displacement over force, SI); no structure "
                       f"yields {MAX_RECEPTANCE:g} m/N: corrupt numbers or a unit slip")
    e = np.array(ends, dtype=np.int64)
    return Frfs(axis, geometry.dofs(e[:, 0], e[:, 1]), geometry.dofs(e[:, 2], e[:, 3]), values)


def _index58(sets: _Sets, k: int) -> int:
    """The dataset number of the k-th FRF (58, function type 4) in the file."""
    return [index for index, d in sets if d["type"] == 58 and d["func_type"] == 4][k]


def write_uff(path: str | os.PathLike[str], nodes: Nodes, modes: Modes | None = None,
              frfs: Frfs | None = None, description: str = "", binary: bool = True) -> None:
    """Write nodes, modes and FRFs as 164, 2411, 55 (one per mode) and 58 (one per FRF: binary,
    or ASCII with `binary=False`), lengths in mm (module docstring for the precision); the
    file is replaced atomically."""
    name = os.fspath(path)
    text = " ".join(description.split())[:80] or "NONE"
    try:
        known = set(nodes.ids.tolist())
        mm = nodes.xyz * MM_PER_M
        zeros = np.zeros(len(nodes.ids), dtype=np.int64)
        sets: list[dict[str, Any]] = [dict(_WRITE_UNITS), {
            "type": 2411, "node_nums": nodes.ids, "def_cs": zeros, "disp_cs": zeros,
            "color": zeros, "x": mm[:, 0], "y": mm[:, 1], "z": mm[:, 2]}]
        sets += [] if modes is None else _mode_sets(modes, known, text)
        sets += [] if frfs is None else _frf_sets(frfs, known, text, binary)
    except UffError as exc:
        raise UffError(f"{name}: {exc}") from None

    def write(tmp: str) -> None:
        try:
            write_sets(tmp, sets)
        except Exception as exc:
            raise UffError(f"{name}: pyuff could not write it ({one_line(exc)})") from None

    atomic_write(name, write)


def write_sets(path: str, sets: list[dict[str, Any]]) -> None:
    """pyuff's records appended to `path` one by one, each binary 58's header then given the
    byte count it holds (pyuff writes 8 a point, where a complex record with its frequencies
    has 24: the UFF specification's field 6 of record 1, FORMAT(I6,1A1,I6,I6,I12,I12,...),
    is the number of bytes that follow the 11 ASCII records)."""
    if not os.path.exists(path):
        open(path, "wb").close()
    writer = pyuff.UFF(path)
    for record in sets:
        start = os.path.getsize(path)
        with warnings.catch_warnings():  # pyuff leaves a 58b's reopened handle to the GC
            warnings.simplefilter("ignore", ResourceWarning)
            writer.write_sets([record], mode="add")
        if record["type"] == 58 and record.get("binary"):
            _count_bytes(path, start)


def _count_bytes(path: str, start: int) -> None:
    """Set the byte count of the binary 58 written from `start`: what lies between its 11th
    ASCII record and its closing '    -1' line (fixed columns 32-43 of its header line)."""
    with open(path, "r+b") as fh:
        fh.seek(start)
        lines = [fh.readline() for _ in range(13)]  # '-1', the header, 11 ASCII records
        header = lines[1]
        end = os.path.getsize(path) - len(b"    -1\n")
        count = end - (start + sum(len(line) for line in lines))
        if not (header[:7] == b"    58b" and 0 < count < 10**12):
            raise UffError(f"a binary 58 record's header not where it was written ({header!r})")
        fh.seek(start + len(lines[0]) + 31)
        fh.write(b"%12d" % count)


def _known(dofs: Dofs, known: set[int], what: str) -> IntArray:
    if missing := sorted(set(dofs.node.tolist()) - known):
        raise UffError(f"{what} at node {missing[0]}, which the nodes do not define")
    return dofs.codes()


def _mode_sets(modes: Modes, known: set[int], text: str) -> list[dict[str, Any]]:
    codes = _known(modes.dofs, known, "a mode-shape dof")
    order = {n: p for p, n in enumerate(dict.fromkeys(modes.dofs.node.tolist()))}
    grid = np.zeros((len(order), 3, len(modes.frequencies_hz)))
    filled = np.zeros((len(order), 3), dtype=bool)
    for i, (node_id, code) in enumerate(zip(modes.dofs.node.tolist(), codes.tolist())):
        p, a = order[node_id], abs(code) - 1
        if filled[p, a]:
            raise UffError(f"Modes.dofs: node {node_id} direction {'xyz'[a]} given twice")
        filled[p, a] = True
        grid[p, a] = modes.shapes[i] if code > 0 else -modes.shapes[i]
    ids = np.array(list(order), dtype=np.int64)
    zeta = np.zeros(len(modes.frequencies_hz)) if modes.damping_ratios is None \
        else modes.damping_ratios
    # pyuff's defaults: id3-id5 "NONE", model type 1 (structural), no modal mass or hysteresis
    return [{"type": 55, "id1": text, "id2": f"mode {r + 1}", "analysis_type": 2, "data_ch": 2,
             "spec_data_type": 8, "load_case": 1, "mode_n": r + 1, "freq": float(f),
             "modal_damp_vis": float(zeta[r]), "node_nums": ids, "r1": grid[:, 0, r].copy(),
             "r2": grid[:, 1, r].copy(), "r3": grid[:, 2, r].copy()}
            for r, f in enumerate(modes.frequencies_hz)]


def _frf_sets(frfs: Frfs, known: set[int], text: str, binary: bool) -> list[dict[str, Any]]:
    rsp = _known(frfs.dofs, known, "an FRF response")
    ref = _known(frfs.reference, known, "an FRF reference")
    # pyuff's defaults: id3-id5, entity names and labels "NONE", version and load case 0
    return [{"type": 58, "binary": int(binary), "id1": text, "id2": "receptance", "func_type": 4,
             "func_id": i + 1, "rsp_node": int(frfs.dofs.node[i]), "rsp_dir": int(rsp[i]),
             "ref_node": int(frfs.reference.node[i]), "ref_dir": int(ref[i]),
             "abscissa_spacing": 0, "abscissa_spec_data_type": 18,
             "abscissa_axis_units_lab": "Hz", "ordinate_spec_data_type": 8,
             "ordinate_len_unit_exp": 1, "ordinate_axis_units_lab": "mm",
             "orddenom_spec_data_type": 13, "orddenom_force_unit_exp": 1,
             "orddenom_axis_units_lab": "mN", "x": np.array(frfs.frequency_hz),
             "data": np.array(frfs.values[i])} for i in range(len(frfs.dofs.node))]
