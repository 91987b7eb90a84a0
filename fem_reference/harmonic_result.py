"""The answer of a pose solved with harmonic legs (`harmonic.solve_pose_harmonic`).

Reads the legs' 3D displacement back from the harmonics (r, theta, z in a leg's frame), the
faces' projected rigid motions, the leg axes' translations and twists at stations, and writes
a structured display mesh of the legs for ParaView; it satisfies `answer.FemAnswer`, as the
tetrahedral model's `FemResult` does.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .answer import section_arms, solve_record, station_fractions, twist_from_section
from .export import solid_to_meshio, write_mesh_vtu, write_mode_collection
from .harmonic_faces import face_projection_coefficients
from .meridian import families


@dataclass
class HarmonicResult:
    """One pose solved with harmonic legs: `answer.FemAnswer`, as `tetrahedra.FemResult`
    (frequencies, leg-axis and platform motions, VTU, record), so the pipeline takes either."""

    frequencies_hz: np.ndarray  # (modes,) ascending
    dofs: int  # free coordinates after the joints (and the axis) are eliminated
    raw_dofs: int  # harmonic dofs of the legs
    mesh_size: float  # m, the meridian's element size h
    timings: dict  # seconds: mesh, assemble, solve, total
    clusters: list
    mesh_digest: str
    n_elements: int  # meridian triangles over the legs
    options: object  # options.FemOptions
    min_quality: float  # smallest triangle quality 4 sqrt(3) area / sum of squared edges
    harmonics: tuple  # harmonic orders included
    excluded_above_hz: float  # no mode of the first harmonic left out lies below this
    geometry: object = field(repr=False)
    modes_q: np.ndarray = field(repr=False)
    modes_raw: np.ndarray = field(repr=False)
    columns: dict = field(repr=False)
    legs: list = field(repr=False)  # per leg: (LegHarmonics, frame E (3, 3), raw offset)
    plate: object = field(default=None, repr=False)
    cache_hit: bool = False

    @property
    def platform_motion(self) -> np.ndarray:
        """(6, n_modes): translation of o and rotation of the rigid platform."""
        return self.modes_q[self.columns["platform"]].copy()

    def _blocks(self, leg_index: int) -> dict:
        leg, _, offset = self.legs[leg_index]
        n3 = 3 * leg.n_scalar
        return {fam: self.modes_raw[offset + k * n3: offset + (k + 1) * n3]
                for k, fam in enumerate(families(self.harmonics))}

    def face_motion(self, leg_index: int, face: int) -> np.ndarray:
        """(6, n_modes): the face's projected rigid motion (t, phi) in the leg frame (its
        joint's reference point, as `FemResult` reads it); harmonics 0 and 1 carry it."""
        leg = self.legs[leg_index][0]
        nodes = leg.face_nodes[face]
        out = 0.0
        for (n, fam), block in self._blocks(leg_index).items():
            if n <= 1:
                values = block.reshape(-1, 3, block.shape[1])[nodes]
                projection = face_projection_coefficients(leg, face, n, fam).reshape(6, -1)
                out = out + projection @ values.reshape(-1, block.shape[1])
        return out

    def local_displacements(self, leg_index: int, r, theta, z) -> np.ndarray:
        """(n_points, 3, n_modes): the 3D displacement at points (r, theta, z) of a leg, in
        the leg's frame (e1, e2, axis), summed over the harmonics (module docstring)."""
        leg = self.legs[leg_index][0]
        r, theta, z = (np.asarray(a, float).ravel() for a in (r, theta, z))
        eps = 1e-9  # points on the boundary, nudged inside for the element search
        probe = leg.basis.probes(np.vstack([np.clip(r, eps * leg.radius, (1 - eps) * leg.radius),
                                            np.clip(z, eps * leg.length, (1 - eps) * leg.length)]))
        ur = np.zeros((len(r), self.modes_raw.shape[1]))
        ut, uz = ur.copy(), ur.copy()
        for (n, fam), block in self._blocks(leg_index).items():
            vr, vt, vz = (probe @ block[c::3] for c in range(3))
            cos, sin = np.cos(n * theta)[:, None], np.sin(n * theta)[:, None]
            if n == 0:  # u_t = U_t, the torsion field (cos 0 = 1 on every component)
                ur, ut, uz = ur + vr, ut + vt, uz + vz
            elif fam == "c":  # (cos, sin, cos)
                ur, ut, uz = ur + vr * cos, ut + vt * sin, uz + vz * cos
            else:  # (sin, -cos, sin): family c turned by 90 / n degrees
                ur, ut, uz = ur + vr * sin, ut - vt * cos, uz + vz * sin
        c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
        return np.stack([ur * c - ut * s, ur * s + ut * c, uz], axis=1)

    def leg_axis_displacements(self, fractions) -> np.ndarray:
        """Translation of the leg axis points B_i + t (A_i - B_i) per mode, base coordinates:
        (3 legs, len(fractions), 3, n_modes). At t = 0 and 1 the face's projected rigid
        motion (its joint's reference point, as `FemResult`), inside the axis itself."""
        t = station_fractions(fractions)
        out = np.zeros((len(self.legs), len(t), 3, self.modes_raw.shape[1]))
        for i, (leg, frame, _) in enumerate(self.legs):
            out[i] = np.einsum("ab,tbm->tam", frame, self.local_displacements(
                i, np.zeros_like(t), np.zeros_like(t), t * leg.length))
            for face, end in ((0, 0.0), (1, 1.0)):
                sel = np.abs(t - end) <= 1e-9
                if sel.any():
                    out[i, sel] = (frame @ self.face_motion(i, face)[:3])[None]
        return out

    def leg_axis_twists(self, fractions) -> np.ndarray:
        """Rotation of each leg's sections about its axis (rad) at fractions t, per mode:
        (3 legs, len(fractions), n_modes), as `FemResult.leg_axis_twists`: inside, the mean
        rotation of six points at half the radius; at the joint centres the face's projected
        rigid rotation."""
        t = station_fractions(fractions)
        axis = np.array([0.0, 0.0, 1.0])  # in the leg frame
        out = np.zeros((len(self.legs), len(t), self.modes_raw.shape[1]))
        for i, (leg, _, _) in enumerate(self.legs):
            arms = section_arms(axis, 0.5 * leg.radius)
            theta = np.arctan2(arms[:, 1], arms[:, 0])
            u = self.local_displacements(i, np.repeat(0.5 * leg.radius, len(t) * len(arms)),
                                         np.tile(theta, len(t)),
                                         np.repeat(t * leg.length, len(arms)))
            out[i] = twist_from_section(axis, arms, u.reshape(len(t), len(arms), 3, -1))
            for face, end in ((0, 0.0), (1, 1.0)):
                sel = np.abs(t - end) <= 1e-9
                if sel.any():
                    out[i, sel] = self.face_motion(i, face)[5][None]  # phi_z, the twist
        return out

    def display_mesh(self, rings: int = 3, sectors: int = 24):
        """Points, meshio cell blocks and body ids of a structured display of the legs (wedges
        around the axis, hexahedra outside), and the modes' displacements at the points."""
        points, wedges, hexes, u, body_w, body_h = [], [], [], [], [], []
        start = 0
        for i, (leg, frame, _) in enumerate(self.legs):
            layers = max(8, int(math.ceil(leg.length / leg.radius)))
            z = np.linspace(0.0, leg.length, layers + 1)
            theta = 2 * math.pi * np.arange(sectors) / sectors
            rr = leg.radius * np.arange(1, rings + 1) / rings
            # per layer: the axis point, then rings x sectors
            r_pts = np.concatenate([[0.0], np.repeat(rr, sectors)])
            t_pts = np.concatenate([[0.0], np.tile(theta, rings)])
            per = len(r_pts)
            rz = np.tile(r_pts, layers + 1)
            tz = np.tile(t_pts, layers + 1)
            zz = np.repeat(z, per)
            base = np.asarray(self.geometry.base_points[i], float)
            local = np.stack([rz * np.cos(tz), rz * np.sin(tz), zz], axis=1)
            points.append(base + local @ frame.T)
            u.append(np.einsum("ab,pbm->pam", frame, self.local_displacements(i, rz, tz, zz)))
            k = np.arange(sectors)
            nxt = (k + 1) % sectors
            for layer in range(layers):
                lo, hi = start + layer * per, start + (layer + 1) * per
                ring1 = 1 + k
                ring1n = 1 + nxt
                wedges.append(np.column_stack([np.full(sectors, lo), lo + ring1n, lo + ring1,
                                               np.full(sectors, hi), hi + ring1n, hi + ring1]))
                for j in range(rings - 1):
                    a, b = 1 + j * sectors + k, 1 + j * sectors + nxt
                    c, d = 1 + (j + 1) * sectors + nxt, 1 + (j + 1) * sectors + k
                    hexes.append(np.column_stack([lo + a, lo + d, lo + c, lo + b,
                                                  hi + a, hi + d, hi + c, hi + b]))
            body_w.append(np.full(layers * sectors, i, np.int32))
            body_h.append(np.full(layers * sectors * (rings - 1), i, np.int32))
            start += per * (layers + 1)
        cells = [("wedge", np.vstack(wedges)), ("hexahedron", np.vstack(hexes))]
        return (np.vstack(points), cells, [np.concatenate(body_w), np.concatenate(body_h)],
                np.concatenate(u))

    def write_vtu(self, path, pvd: bool = False) -> None:
        """Mode shapes for ParaView: the legs' 3D displacement on a structured display mesh
        (from the harmonics) and the rigid platform, as `FemResult.write_vtu`."""
        points, cells, body, u = self.display_mesh()
        write_mesh_vtu(path, solid_to_meshio(points, cells, body, len(self.legs), u,
                                               self.frequencies_hz, self.plate,
                                               self.platform_motion))
        if pvd:
            write_mode_collection(path)

    def to_dict(self) -> dict:
        return solve_record(self, harmonics=list(self.harmonics),
                            excluded_harmonics_above_hz=self.excluded_above_hz)
