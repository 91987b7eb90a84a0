"""The answer of a pose solved with harmonic legs (`harmonic.solve_pose_harmonic`).

Reads the legs' 3D displacement back from the harmonics (r, theta, z in a leg's frame), the
faces' projected rigid motions, the leg axes' translations and twists at stations, and writes
a structured display mesh of the legs for ParaView; it satisfies `answer.FemAnswer`, as the
tetrahedral model's `FemResult` does.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np

from .answer import section_arms, solve_record, station_fractions, twist_from_section
from .export import solid_to_meshio, write_mesh_vtu, write_mode_collection
from .harmonic_faces import face_projection_coefficients, section_constants
from .meridian import families
from .options import FemOptions


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
    options: FemOptions
    min_quality: float  # smallest triangle quality 4 sqrt(3) area / sum of squared edges
    harmonics: tuple  # harmonic orders included
    excluded_above_hz: float  # no mode of the first harmonic left out lies below this
    geometry: Any = field(repr=False)  # analytical.kinematics.PoseGeometry: duck-typed,
    # the FEM never imports the analytical model
    modes_q: np.ndarray = field(repr=False)
    modes_raw: np.ndarray = field(repr=False)
    columns: dict = field(repr=False)
    legs: list = field(repr=False)  # per leg part: (meridian.PartHarmonics, raw offset)
    plate: object = field(default=None, repr=False)
    cache_hit: bool = False
    system: tuple | None = field(default=None, repr=False)  # (K_q, M_q): the direct response

    @property
    def platform_motion(self) -> np.ndarray:
        """(6, n_modes): translation of o and rotation of the rigid platform."""
        return self.modes_q[self.columns["platform"]].copy()

    @property
    def leg_count(self) -> int:
        return 1 + max(p.index for p, _ in self.legs)

    def parts_of(self, leg_index: int) -> list[int]:
        """Indices into `legs` of leg `leg_index`'s parts, base joint first."""
        return [k for k, (p, _) in enumerate(self.legs) if p.index == leg_index]

    def _blocks(self, part: int) -> dict:
        p, offset = self.legs[part]
        n3 = 3 * p.leg.n_scalar
        return {fam: self.modes_raw[offset + k * n3: offset + (k + 1) * n3]
                for k, fam in enumerate(families(self.harmonics))}

    def face_motion(self, part: int, face: int) -> np.ndarray:
        """(6, n_modes): the face's projected rigid motion (t, phi) in the leg frame (its
        reference point's, as `FemResult` reads it); harmonics 0 and 1 carry it. `part`
        indexes `legs` (the leg's index for uniform legs)."""
        leg = self.legs[part][0].leg
        nodes = leg.face_nodes[face]
        out: float | np.ndarray = 0.0
        for (n, fam), block in self._blocks(part).items():
            if n <= 1:
                values = block.reshape(-1, 3, block.shape[1])[nodes]
                projection = face_projection_coefficients(leg, face, n, fam).reshape(6, -1)
                out = out + projection @ values.reshape(-1, block.shape[1])
        return cast(np.ndarray, out)  # an array: every solve has harmonics 0 and 1

    def local_displacements(self, part: int, r, theta, z) -> np.ndarray:
        """(n_points, 3, n_modes): the 3D displacement at points (r, theta, z) of a leg part
        (z from the part's start), in the leg's frame (e1, e2, axis), summed over the
        harmonics (module docstring)."""
        leg = self.legs[part][0].leg
        r, theta, z = (np.asarray(a, float).ravel() for a in (r, theta, z))
        eps = 1e-9  # points on the boundary, nudged inside for the element search
        lo = leg.inner + eps * (leg.radius - leg.inner) if leg.inner else eps * leg.radius
        probe = leg.basis.probes(np.vstack([np.clip(r, lo, (1 - eps) * leg.radius),
                                            np.clip(z, eps * leg.length, (1 - eps) * leg.length)]))
        ur = np.zeros((len(r), self.modes_raw.shape[1]))
        ut, uz = ur.copy(), ur.copy()
        for (n, fam), block in self._blocks(part).items():
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

    def section_mean(self, part: int, z) -> np.ndarray:
        """(len(z), 3, n_modes): the mean displacement over the sections of a hollow part at
        z (from its start), leg frame: harmonics 0 and 1 only (the others average out), by
        Gauss-Legendre along the wall, u_x = pi / A int (U_r - U_t) r dr (family c),
        u_y likewise (family s), u_z = 2 pi / A int U_z r dr; the formulas of
        `face_projection_coefficients` on an inner section."""
        leg = self.legs[part][0].leg
        z = np.asarray(z, float).ravel()
        x, w = np.polynomial.legendre.leggauss(16)
        r = leg.inner + 0.5 * (x + 1) * (leg.radius - leg.inner)
        w = 0.5 * w * (leg.radius - leg.inner) * r  # r dr
        area = section_constants(leg)[0]
        eps = 1e-9
        rr, zz = np.repeat(r[None], len(z), 0), np.repeat(np.clip(
            z, eps * leg.length, (1 - eps) * leg.length)[:, None], len(r), 1)
        probe = leg.basis.probes(np.vstack([rr.ravel(), zz.ravel()]))
        out = np.zeros((len(z), 3, self.modes_raw.shape[1]))
        for (n, fam), block in self._blocks(part).items():
            if n > 1:
                continue
            vr, vt, vz = ((probe @ block[c::3]).reshape(len(z), len(r), -1) for c in range(3))
            if n == 0:
                out[:, 2] = 2 * math.pi / area * np.einsum("k,zkm->zm", w, vz)
            else:
                out[:, 0 if fam == "c" else 1] = math.pi / area * np.einsum("k,zkm->zm", w,
                                                                              vr - vt)
        return out

    def _station(self, leg_index: int, t: np.ndarray):
        """Per station fraction t of leg `leg_index`: (part index into `legs`, z in that part);
        the part containing t L, at a junction the one toward the base (the housing)."""
        parts = self.parts_of(leg_index)
        total = self.legs[parts[-1]][0].start + self.legs[parts[-1]][0].leg.length
        found = []
        for s in t * total:
            k = next((k for k in parts if s <= self.legs[k][0].start
                      + self.legs[k][0].leg.length + 1e-12 * total), parts[-1])
            found.append((k, s - self.legs[k][0].start))
        return found

    def leg_axis_displacements(self, fractions) -> np.ndarray:
        """Translation of the leg axis points B_i + t (A_i - B_i) per mode, base coordinates:
        (3 legs, len(fractions), 3, n_modes). Inside a solid part the axis point's motion; in
        a hollow part, whose axis lies outside the solid, the section's mean motion (its
        harmonics 0 and 1, `section_mean`: what a beam's axis displacement is); at a junction
        the housing's side. At t = 0 and 1 the end faces' projected rigid motion (their joint
        reference points', as `FemResult`)."""
        t = station_fractions(fractions)
        out = np.zeros((self.leg_count, len(t), 3, self.modes_raw.shape[1]))
        for i in range(self.leg_count):
            parts = self.parts_of(i)
            stations = self._station(i, t)
            for k in parts:
                p = self.legs[k][0]
                sel = np.array([kk == k for kk, _ in stations])
                if not sel.any():
                    continue
                z = np.array([zz for kk, zz in stations if kk == k])
                if p.leg.inner:
                    local = self.section_mean(k, z)
                else:
                    local = self.local_displacements(k, np.zeros_like(z), np.zeros_like(z), z)
                out[i, sel] = np.einsum("ab,tbm->tam", p.frame, local)
            for face, end, k in ((0, 0.0, parts[0]), (1, 1.0, parts[-1])):
                sel = np.abs(t - end) <= 1e-9
                if sel.any():
                    out[i, sel] = (self.legs[k][0].frame @ self.face_motion(k, face)[:3])[None]
        return out

    def leg_axis_twists(self, fractions) -> np.ndarray:
        """Rotation of each leg's sections about its axis (rad) at fractions t, per mode:
        (3 legs, len(fractions), n_modes), as `FemResult.leg_axis_twists`: inside, the mean
        rotation of six points at half the radius of a solid part, at mid-wall of a hollow
        one; at the joint centres the face's projected rigid rotation."""
        t = station_fractions(fractions)
        axis = np.array([0.0, 0.0, 1.0])  # in the leg frame
        out = np.zeros((self.leg_count, len(t), self.modes_raw.shape[1]))
        for i in range(self.leg_count):
            parts = self.parts_of(i)
            stations = self._station(i, t)
            for k in parts:
                leg = self.legs[k][0].leg
                sel = np.array([kk == k for kk, _ in stations])
                if not sel.any():
                    continue
                z = np.array([zz for kk, zz in stations if kk == k])
                arm = 0.5 * (leg.radius + leg.inner) if leg.inner else 0.5 * leg.radius
                arms = section_arms(axis, arm)
                theta = np.arctan2(arms[:, 1], arms[:, 0])
                u = self.local_displacements(k, np.repeat(arm, len(z) * len(arms)),
                                             np.tile(theta, len(z)), np.repeat(z, len(arms)))
                out[i, sel] = twist_from_section(axis, arms, u.reshape(len(z), len(arms), 3, -1))
            for face, end, k in ((0, 0.0, parts[0]), (1, 1.0, parts[-1])):
                sel = np.abs(t - end) <= 1e-9
                if sel.any():
                    out[i, sel] = self.face_motion(k, face)[5][None]  # phi_z, the twist
        return out

    def display_mesh(self, rings: int = 3, sectors: int = 24):
        """Points, meshio cell blocks and body ids (the leg's) of a structured display of the
        legs' parts (wedges around the axis of a solid part, hexahedra outside; a tube's wall
        hexahedra only), and the modes' displacements at the points."""
        points, wedges, hexes, u, body_w, body_h = [], [], [], [], [], []
        start = 0
        for k_part, (part, _) in enumerate(self.legs):
            leg, frame, i = part.leg, part.frame, part.index
            layers = max(8, int(math.ceil(leg.length / leg.radius)))
            z = np.linspace(0.0, leg.length, layers + 1)
            theta = 2 * math.pi * np.arange(sectors) / sectors
            solid = not leg.inner
            if solid:  # per layer: the axis point, then rings x sectors
                rr = leg.radius * np.arange(1, rings + 1) / rings
                r_pts = np.concatenate([[0.0], np.repeat(rr, sectors)])
                t_pts = np.concatenate([[0.0], np.tile(theta, rings)])
            else:  # rings + 1 circles through the wall
                rr = leg.inner + (leg.radius - leg.inner) * np.arange(rings + 1) / rings
                r_pts, t_pts = np.repeat(rr, sectors), np.tile(theta, rings + 1)
            per = len(r_pts)
            rz = np.tile(r_pts, layers + 1)
            tz = np.tile(t_pts, layers + 1)
            zz = np.repeat(z, per)
            base = np.asarray(self.geometry.base_points[i], float) + part.start * frame[:, 2]
            local = np.stack([rz * np.cos(tz), rz * np.sin(tz), zz], axis=1)
            points.append(base + local @ frame.T)
            u.append(np.einsum("ab,pbm->pam", frame,
                               self.local_displacements(k_part, rz, tz, zz)))
            k = np.arange(sectors)
            nxt = (k + 1) % sectors
            first = 1 if solid else 0
            n_hex = rings - 1 if solid else rings
            for layer in range(layers):
                lo, hi = start + layer * per, start + (layer + 1) * per
                if solid:
                    ring1 = 1 + k
                    ring1n = 1 + nxt
                    wedges.append(np.column_stack([np.full(sectors, lo), lo + ring1n,
                                                   lo + ring1, np.full(sectors, hi),
                                                   hi + ring1n, hi + ring1]))
                for j in range(n_hex):
                    a, b = first + j * sectors + k, first + j * sectors + nxt
                    c, d = first + (j + 1) * sectors + nxt, first + (j + 1) * sectors + k
                    hexes.append(np.column_stack([lo + a, lo + d, lo + c, lo + b,
                                                  hi + a, hi + d, hi + c, hi + b]))
            if solid:
                body_w.append(np.full(layers * sectors, i, np.int32))
            body_h.append(np.full(layers * sectors * n_hex, i, np.int32))
            start += per * (layers + 1)
        cells, body = [], []
        if wedges:
            cells.append(("wedge", np.vstack(wedges)))
            body.append(np.concatenate(body_w))
        cells.append(("hexahedron", np.vstack(hexes)))
        body.append(np.concatenate(body_h))
        return np.vstack(points), cells, body, np.concatenate(u)

    def write_vtu(self, path, pvd: bool = False) -> None:
        """Mode shapes for ParaView: the legs' 3D displacement on a structured display mesh
        (from the harmonics) and the rigid platform, as `FemResult.write_vtu`."""
        points, cells, body, u = self.display_mesh()
        write_mesh_vtu(path, solid_to_meshio(points, cells, body, self.leg_count, u,
                                               self.frequencies_hz, self.plate,
                                               self.platform_motion))
        if pvd:
            write_mode_collection(path)

    def to_dict(self) -> dict:
        return solve_record(self, harmonics=list(self.harmonics),
                            excluded_harmonics_above_hz=self.excluded_above_hz)
