"""Mode shapes to VTU through meshio: one point-data vector per mode, frequencies in field data.

meshio's VTU writer drops field data (its reader keeps it), so the <FieldData> block with the
frequencies is inserted into the written XML (ASCII DataArray, valid VTK XML; read back by meshio
and by VTK/pyvista). Written to a temporary file beside the target and moved into place, so a failed export leaves no
partial file.
"""
from __future__ import annotations

import os
from pathlib import Path

import meshio
import numpy as np

from common.atomic import atomic_write

from .discretisation import Discretisation


def modes_to_meshio(disc: Discretisation, modes: np.ndarray, frequencies_hz: np.ndarray
                    ) -> meshio.Mesh:
    """modes: (n_raw, n_modes) displacement fields on dofs 3 s + c."""
    cells = [("tetra10", np.ascontiguousarray(disc.basis.element_dofs.T))]
    u = modes.reshape(disc.n_nodes, 3, -1)
    point_data = {f"mode_{k + 1}": np.ascontiguousarray(u[:, :, k])
                  for k in range(u.shape[2])}
    return meshio.Mesh(
        disc.node_xyz, cells, point_data=point_data,
        cell_data={"body": [disc.tet_body.astype(np.int32)]},
        field_data={"frequencies_hz": np.asarray(frequencies_hz, float),
                    "bodies": np.array([len(disc.bodies)])},
    )


def write_modes_vtu(path: str | os.PathLike, disc: Discretisation, modes: np.ndarray,
                    frequencies_hz: np.ndarray) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    mesh = modes_to_meshio(disc, modes, frequencies_hz)

    def write(tmp):
        meshio.write(tmp, mesh, file_format="vtu", binary=True, compression="zlib")
        _insert_field_data(Path(tmp), mesh.field_data)

    atomic_write(path, write)
    return path


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
