"""Mode shapes for ParaView: one VTU of the whole manipulator, and a .pvd to step through modes.

The VTU holds the legs (10-node tetrahedra of the FEM) and the platform. A rigid platform is
not meshed by the FEM; for display it is built here as a plate solid of its shape and
thickness centred at o with normal R[:, 2] (a fan of wedges around o), and its points get the
rigid motion of each mode, u(x) = Delta_p + Phi_p x (x - o) (Eq. 10), from the platform's six
coordinates. Every mode is one point-data vector named with its number and frequency
(`mode_03_194.99Hz`) and scaled so that its largest displacement is DISPLAY_FRACTION of the
model's size (the diagonal of its bounding box): Warp By Vector at factor 1 shows it at a
readable amplitude. Field data: `frequencies_hz`, `mode_scale` (displayed vector = mode_scale
x the mass-normalised mode, so the raw mode is the array divided by it), `model_size_m`,
`display_fraction`.

`write_mode_collection` adds, beside `<name>.vtu`, `<name>.pvd` with one time step per mode
(time = mode number) over `<name>_modes/mode_<k>.vtu`, each holding the same solid with that
mode as `displacement`: ParaView's time controls then step through the modes.

meshio's VTU writer drops field data (its reader keeps it), so the <FieldData> block is inserted
into the written XML (ASCII DataArray, valid VTK XML; read back by meshio and by VTK/pyvista).
Every file is written to a temporary file beside the target and moved into place, the .pvd
last, so a failed export leaves no partial file.
"""
from __future__ import annotations

import math
import os
import re
from pathlib import Path
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from common.atomic import atomic_write, write_text_atomic
from common.errors import InputError

from .discretisation import Discretisation

DISPLAY_FRACTION = 0.1  # largest displayed displacement / bounding-box diagonal of the model
DISK_SEGMENTS = 72  # wedges of the displayed disk: its rim within 0.1 % of the circle
MODE_ARRAY = re.compile(r"^mode_(\d+)_")


def plate_solid(plate, segments: int = DISK_SEGMENTS) -> tuple[np.ndarray, np.ndarray]:
    """Points (n, 3) and VTK wedge cells (m, 6) of a plate (`meshing.bodies.Plate`): its
    outline (a regular polygon of `segments` sides for a disk, the corners A_i for a triangle)
    joined to the centre by wedges through the thickness. Each wedge's first triangle is on
    the -n face, ordered so that its right-hand normal points out of the wedge (VTK's rule)."""
    o = np.asarray(plate.centre, float)
    n = np.asarray(plate.normal, float)
    n = n / np.linalg.norm(n)
    ref = np.asarray(plate.corners[0], float) - o if plate.corners else np.eye(3)[np.argmin(
        np.abs(n))]
    e1 = ref - (ref @ n) * n
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    if plate.shape == "disk":
        angles = 2 * math.pi * np.arange(segments) / segments
        ring = o + plate.radius * (np.cos(angles)[:, None] * e1 + np.sin(angles)[:, None] * e2)
    elif plate.shape == "triangle":
        ring = np.asarray(plate.corners, float)
        ring = ring - ((ring - o) @ n)[:, None] * n  # on the mid-plane
        ring = ring[np.argsort(np.arctan2((ring - o) @ e2, (ring - o) @ e1))]
    else:
        raise InputError(f"platform_shape = {plate.shape!r}: expected disk or triangle")
    half = 0.5 * plate.thickness * n
    mid = np.vstack([o, ring])  # centre first, then the outline counter-clockwise about n
    points = np.vstack([mid - half, mid + half])
    m = len(ring)
    k = np.arange(m)
    nxt = (k + 1) % m
    top = m + 1
    cells = np.column_stack([np.zeros(m, int), 1 + nxt, 1 + k, np.full(m, top), top + 1 + nxt,
                             top + 1 + k])
    return points, cells


def rigid_motion(points: np.ndarray, centre, motion: np.ndarray) -> np.ndarray:
    """(n_points, 3, n_modes): u = t + w x (x - o) for motion (6, n_modes) = (t, w) at o."""
    arm = np.asarray(points, float) - np.asarray(centre, float)
    t, w = motion[:3], motion[3:]
    return t[None] + np.cross(w.T[None], arm[:, None]).transpose(0, 2, 1)


def mode_name(k: int, frequency_hz: float, count: int) -> str:
    """`mode_03_194.99Hz`: 1-based number (zero-padded to the count) and frequency."""
    width = max(2, len(str(count)))
    return f"mode_{k:0{width}d}_{frequency_hz:.2f}Hz"


def display_scales(u: np.ndarray, size: float,
                   fraction: float = DISPLAY_FRACTION) -> np.ndarray:
    """Per mode, the factor that makes the largest |u| over all points `fraction` x size."""
    amp = np.linalg.norm(u, axis=1).max(axis=0)
    return np.where(amp > 0, fraction * size / np.where(amp > 0, amp, 1.0), 0.0)


def modes_to_meshio(disc: Discretisation, modes: np.ndarray, frequencies_hz: np.ndarray,
                    plate=None, platform_motion: np.ndarray | None = None) -> meshio.Mesh:
    """modes: (n_raw, n_modes) displacement fields on dofs 3 s + c. With `plate` and
    `platform_motion` (6, n_modes), the rigid platform is added as a plate solid."""
    count = modes.shape[1]
    return solid_to_meshio(disc.node_xyz, [("tetra10", np.ascontiguousarray(
        disc.basis.element_dofs.T))], [disc.tet_body.astype(np.int32)], len(disc.bodies),
        modes.reshape(disc.n_nodes, 3, count), frequencies_hz, plate, platform_motion)


def solid_to_meshio(points: np.ndarray, cells: list, body: list, n_bodies: int, u: np.ndarray,
                    frequencies_hz: np.ndarray, plate=None,
                    platform_motion: np.ndarray | None = None) -> meshio.Mesh:
    """The VTU content of any display of the legs: points (n, 3), meshio cell blocks, their
    body ids, u (n, 3, n_modes); the rigid platform added as in `modes_to_meshio`."""
    frequencies_hz = np.asarray(frequencies_hz, float)
    count = u.shape[2]
    cells, body = list(cells), list(body)
    if plate is not None:
        if platform_motion is None:
            raise InputError("platform_motion is required to display a rigid platform")
        plate_points, wedges = plate_solid(plate)
        cells.append(("wedge", wedges + len(points)))
        body.append(np.full(len(wedges), n_bodies, np.int32))
        u = np.concatenate([u, rigid_motion(plate_points, plate.centre,
                                            np.asarray(platform_motion, float))])
        points = np.vstack([points, plate_points])
        n_bodies += 1
    size = float(np.linalg.norm(np.ptp(points, axis=0)))
    scales = display_scales(u, size)
    point_data = {mode_name(k + 1, frequencies_hz[k], count):
                  np.ascontiguousarray(scales[k] * u[:, :, k]) for k in range(count)}
    return meshio.Mesh(
        points, cells, point_data=point_data, cell_data={"body": body},
        field_data={"frequencies_hz": frequencies_hz, "mode_scale": scales,
                    "model_size_m": np.array([size]),
                    "display_fraction": np.array([DISPLAY_FRACTION]),
                    "bodies": np.array([n_bodies])},
    )


def write_modes_vtu(path: str | os.PathLike, disc: Discretisation, modes: np.ndarray,
                    frequencies_hz: np.ndarray, plate=None,
                    platform_motion: np.ndarray | None = None) -> Path:
    path = Path(path)
    write_mesh_vtu(path, modes_to_meshio(disc, modes, frequencies_hz, plate, platform_motion))
    return path


def write_mode_collection(vtu: str | os.PathLike) -> Path:
    """From a VTU written by `write_modes_vtu`: `<name>.pvd` beside it, one time step per mode
    (time = mode number), over `<name>_modes/mode_<k>.vtu` with the mode as `displacement`."""
    vtu = Path(vtu)
    mesh = meshio.read(vtu)
    arrays = sorted((int(m.group(1)), name) for name in mesh.point_data
                    if (m := MODE_ARRAY.match(name)))
    if not arrays:
        raise InputError(f"{vtu}: no mode_<k>_<f>Hz point arrays to collect")
    frequencies = np.ravel(mesh.field_data["frequencies_hz"])
    scales = np.ravel(mesh.field_data["mode_scale"])
    pieces = vtu.with_name(vtu.stem + "_modes")
    datasets = []
    for k, name in arrays:
        piece = pieces / f"mode_{k:0{max(2, len(str(len(arrays))))}d}.vtu"
        write_mesh_vtu(piece, meshio.Mesh(
            mesh.points, mesh.cells, point_data={"displacement": mesh.point_data[name]},
            cell_data=mesh.cell_data,
            field_data={"mode": np.array([k]), "frequency_hz": frequencies[k - 1:k],
                        "mode_scale": scales[k - 1:k],
                        **{key: mesh.field_data[key] for key in ("model_size_m",
                                                                 "display_fraction")
                           if key in mesh.field_data}}))
        datasets.append(f'    <DataSet timestep="{k}" '
                        f'file={quoteattr(piece.relative_to(vtu.parent).as_posix())}/>')
    pvd = vtu.with_suffix(".pvd")
    write_text_atomic(pvd, '<?xml version="1.0"?>\n'
                      '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
                      '  <Collection>\n' + "\n".join(datasets) + "\n  </Collection>\n"
                      "</VTKFile>\n")
    return pvd


def write_mesh_vtu(path: str | os.PathLike, mesh: meshio.Mesh) -> None:
    """Write a meshio mesh as a compressed binary VTU, atomically, its field_data (the modes'
    frequencies) inserted as a VTK FieldData block; the file behind `write_modes_vtu` and the
    harmonic legs' display mesh (`HarmonicResult.write_vtu`)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)

    def write(tmp):
        meshio.write(tmp, mesh, file_format="vtu", binary=True, compression="zlib")
        _insert_field_data(Path(tmp), mesh.field_data)

    atomic_write(path, write)


def _insert_field_data(path: Path, field_data: dict) -> None:
    arrays = []
    for name, values in field_data.items():
        v = np.asarray(values).ravel()
        kind = "Float64" if v.dtype.kind == "f" else "Int64"
        text = " ".join(repr(float(x)) if kind == "Float64" else str(int(x)) for x in v)
        arrays.append(f'<DataArray type="{kind}" Name="{name}" NumberOfTuples="{len(v)}" '
                      f'format="ascii">{text}</DataArray>')
    block = "<FieldData>" + "".join(arrays) + "</FieldData>"
    data = path.read_bytes()
    tag = b"<UnstructuredGrid>"
    at = data.index(tag) + len(tag)
    path.write_bytes(data[:at] + block.encode() + data[at:])
