"""The mesh of one pose as plain arrays, and its round trip through meshio.

Node order follows meshio/VTK for `tetra10` (edges 01, 12, 02, 03, 13, 23) and `triangle6`
(edges 01, 12, 20). Bodies (physical volumes) are numbered by their position in `bodies`; joint
faces (physical surfaces) are kept as triangle6 connectivity by name, e.g. "leg1_base".
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import meshio
import numpy as np

from common.errors import InputError


class MeshFormatError(InputError):
    """A stored mesh is incomplete or inconsistent."""


@dataclass(frozen=True)
class SolidMesh:
    points: np.ndarray  # (n, 3) float64, m
    tets: np.ndarray  # (ne, 10) int64, meshio tetra10 order
    tet_body: np.ndarray  # (ne,) int32, index into `bodies`
    bodies: tuple[str, ...]  # physical volume names
    faces: dict[str, np.ndarray] = field(default_factory=dict)  # name -> (nf, 6) triangle6
    info: dict = field(default_factory=dict)  # settings, gmsh version, ... (JSON-ready)

    @property
    def n_nodes(self) -> int:
        return int(self.points.shape[0])

    def digest(self) -> str:
        """SHA-256 of the arrays (not of `info`): equal digests mean identical meshes."""
        h = hashlib.sha256()
        for arr in (self.points, self.tets, self.tet_body):
            h.update(np.ascontiguousarray(arr).tobytes())
        h.update(repr(self.bodies).encode())
        for name in sorted(self.faces):
            h.update(name.encode())
            h.update(np.ascontiguousarray(self.faces[name]).tobytes())
        return h.hexdigest()

    def to_meshio(self) -> meshio.Mesh:
        """meshio.Mesh: one tetra10 block, then one triangle6 block per joint face.

        cell_data "body" holds the body index (-1 on faces) and "group" the physical group id
        (1-based, bodies first, then faces in sorted order); field_data maps names to
        [group id, dimension] as gmsh does.
        """
        face_names = sorted(self.faces)
        cells = [("tetra10", self.tets)] + [("triangle6", self.faces[n]) for n in face_names]
        nb = len(self.bodies)
        body = [self.tet_body.astype(np.int32)] + [
            np.full(len(self.faces[n]), -1, np.int32) for n in face_names]
        group = [self.tet_body.astype(np.int32) + 1] + [
            np.full(len(self.faces[n]), nb + 1 + k, np.int32) for k, n in enumerate(face_names)]
        field_data = {name: np.array(v) for name, v in self.groups().items()}
        return meshio.Mesh(self.points, cells, cell_data={"body": body, "group": group},
                           field_data=field_data)

    def groups(self) -> dict[str, list[int]]:
        """Physical group name -> [id, dimension], as in `to_meshio`'s field_data."""
        nb = len(self.bodies)
        out = {name: [k + 1, 3] for k, name in enumerate(self.bodies)}
        out.update({name: [nb + 1 + k, 2] for k, name in enumerate(sorted(self.faces))})
        return out

    @classmethod
    def from_meshio(cls, m: meshio.Mesh, groups: dict | None = None,
                    info: dict | None = None) -> "SolidMesh":
        """Inverse of `to_meshio`; `groups` (name -> [id, dim]) replaces m.field_data for
        formats that do not keep it (VTU). Raises MeshFormatError on anything inconsistent."""
        try:
            points = np.asarray(m.points, np.float64)
            if points.ndim != 2 or points.shape[1] != 3 or not np.all(np.isfinite(points)):
                raise MeshFormatError("points are not a finite (n, 3) array")
            source = groups if groups is not None else m.field_data
            groups = {str(k): (int(v[0]), int(v[1])) for k, v in source.items()}
            bodies = tuple(sorted((k for k, (g, d) in groups.items() if d == 3),
                                  key=lambda k: groups[k][0]))
            by_id = {g: k for k, (g, d) in groups.items() if d == 2}
            tet_blocks, body_blocks, faces = [], [], {}
            for block, gdata in zip(m.cells, m.cell_data["group"]):
                data = np.asarray(block.data, np.int64)
                gdata = np.asarray(gdata, np.int64).ravel()
                if block.type == "tetra10":
                    tet_blocks.append(data)
                    body_blocks.append((gdata - 1).astype(np.int32))
                elif block.type == "triangle6":
                    for gid in np.unique(gdata):
                        if int(gid) not in by_id:
                            raise MeshFormatError(f"face group {int(gid)} has no name")
                        faces[by_id[int(gid)]] = data[gdata == gid]
                else:
                    raise MeshFormatError(f"unexpected cell type {block.type!r}")
            if not tet_blocks:
                raise MeshFormatError("no tetra10 cells")
            tets, tet_body = np.concatenate(tet_blocks), np.concatenate(body_blocks)
            if tets.ndim != 2 or tets.shape[1] != 10 or len(tets) == 0:
                raise MeshFormatError("no tetra10 cells")
            if tets.min() < 0 or tets.max() >= len(points):
                raise MeshFormatError("tetra10 connectivity outside the point array")
            if tet_body.min() < 0 or tet_body.max() >= len(bodies):
                raise MeshFormatError("tetra10 body tags outside the body list")
            for f in faces.values():
                if f.ndim != 2 or f.shape[1] != 6 or f.min() < 0 or f.max() >= len(points):
                    raise MeshFormatError("triangle6 connectivity outside the point array")
        except (KeyError, IndexError, TypeError, AttributeError, ValueError) as exc:
            if isinstance(exc, MeshFormatError):
                raise
            raise MeshFormatError(f"inconsistent mesh data ({type(exc).__name__}: {exc})") from None
        return cls(points, tets, tet_body, bodies, faces, dict(info or {}))
