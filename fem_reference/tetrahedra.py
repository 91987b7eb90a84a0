"""The tetrahedral leg discretisation: one pose as a 3D solid of 10-node tetrahedra.

solve_pose_tetrahedra(manipulator, geometry, assembly, options, runtime) -> FemResult. Steps
(timed):
  mesh      bodies of the pose -> gmsh 10-node tetrahedra (or the mesh cache)
  assemble  scikit-fem P2 stiffness and consistent mass, joint constraint map T (u = T q),
            reduced K_q = T^T K T, M_q = T^T M T (+ the rigid platform's 6x6 mass at o, Eqs. 7-9,
            integrated over its own meshed plate: rigid_platform.py)
  solve     shift-invert Lanczos for the lowest modes (in a child process: Ctrl-C stops it)
The legs and, with an elastic platform, the plate are meshed; `model.solve_pose` checks the
size (`guard.check_mesh_size`) and dispatches here for legs = "tetrahedra".
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from common.rigid_body import rigid_fit
from common.worker import WorkerDied, stoppable
from meshing.bodies import Assembly, Plate, platform_plate
from meshing.cache import cached_mesh
from meshing.geometry import GmshFailure

from .answer import (
    normalise_signs,
    section_arms,
    solve_record,
    station_fractions,
    twist_from_section,
)
from .assembly import stiffness_and_mass
from .constraints import ConstraintMap, build_constraints
from .discretisation import Discretisation, discretise
from .eigen import EigenError, lowest_modes
from .export import write_mode_collection, write_modes_vtu
from .options import FemError, FemOptions, FemRuntime
from .probes import evaluate
from .reduction import reduced_matrices

if TYPE_CHECKING:
    import scipy.sparse as sp



@dataclass
class FemResult:
    """One pose solved with tetrahedral legs: `answer.FemAnswer` (frequencies, leg-axis and
    platform motions, VTU, record), with the mesh, its discretisation and the constraint map."""

    frequencies_hz: np.ndarray  # (modes,) ascending
    dofs: int  # free dofs after the joint constraints are eliminated
    raw_dofs: int  # dofs of the unconstrained bodies
    mesh_size: float  # m
    timings: dict  # seconds: mesh, assemble, solve, total
    clusters: list  # groups of (near-)repeated modes, 0-based indices
    cache_hit: bool
    mesh_digest: str
    n_elements: int
    options: FemOptions
    min_quality: float  # smallest scaled Jacobian of the curved elements (meshing.geometry)
    geometry: Any = field(repr=False)  # analytical.kinematics.PoseGeometry: duck-typed,
    # the FEM never imports the analytical model
    assembly: Assembly = field(repr=False)  # the meshed bodies (names of legs and faces)
    disc: Discretisation = field(repr=False)
    constraints: ConstraintMap = field(repr=False)
    modes_q: np.ndarray = field(repr=False)  # (n_free, modes), M-orthonormal
    modes_raw: np.ndarray = field(repr=False)  # (raw_dofs, modes) = T modes_q
    mass_matrix: sp.csr_matrix | None = field(default=None, repr=False)  # raw consistent mass
    plate: Plate | None = field(default=None, repr=False)  # the platform (meshed or rigid)
    system: tuple | None = field(default=None, repr=False)  # (K_q, M_q): the direct response

    def _stations(self, leg: int, t: np.ndarray):
        """Per station fraction t of a leg: (part, its point on the leg axis); the part that
        contains the point, at a junction the one toward the base (the housing)."""
        parts = self.assembly.legs[leg]
        b, a = np.asarray(parts[0].start), np.asarray(parts[-1].end)
        total = float(np.linalg.norm(a - b))
        ends = [float(np.linalg.norm(np.subtract(c.end, b))) for c in parts]
        out = []
        for tt in t:
            k = next((k for k, e in enumerate(ends) if tt * total <= e + 1e-12 * total),
                     len(parts) - 1)
            out.append((parts[k], b + tt * (a - b)))
        return out

    def _section_mean(self, part, centres: np.ndarray) -> np.ndarray:
        """(len(centres), 3, n_modes): the mean displacement over the sections of a hollow part
        at `centres` on its axis (which lies outside the solid): 2 Gauss-Legendre radii through
        the wall (weights r dr; exact for a field quadratic through the wall, and clear of the
        curved surfaces, where the element search of `probes.locate` is affine) times 12
        angles (the mean over equally spaced angles is exact for the harmonics 0 and 1 that
        carry a section's rigid motion)."""
        b, a = np.asarray(part.start), np.asarray(part.end)
        axis = (a - b) / np.linalg.norm(a - b)
        x, w = np.polynomial.legendre.leggauss(2)
        r = part.inner_radius + 0.5 * (x + 1) * part.wall
        w = w * r / np.sum(w * r)
        unit = section_arms(axis, 1.0, 12)  # (12, 3)
        offsets = (r[:, None, None] * unit[None]).reshape(-1, 3)  # (2 * 12, 3)
        weights = np.repeat(w, len(unit)) / len(unit)
        pts = (centres[:, None, :] + offsets[None]).reshape(-1, 3)
        u = evaluate(self.disc, part.name, pts, self.modes_raw).reshape(len(centres),
                                                                         len(offsets), 3, -1)
        return np.einsum("k,pkcm->pcm", weights, u)

    def leg_axis_displacements(self, fractions) -> np.ndarray:
        """Translation of the leg axis points B_i + t (A_i - B_i), t in `fractions`, per mode:
        (3 legs, len(fractions), 3, n_modes), base coordinates. Inside a solid part the P2
        field is interpolated on the axis; in a hollow part, whose axis lies outside the solid,
        the section's mean motion (`_section_mean`: a beam's axis displacement); at a junction
        the housing's side. At t = 0 and t = 1 (the joint centres) the reference points' motion
        is used (B_i fixed; A_i moving with the platform)."""
        t = station_fractions(fractions)
        legs = self.assembly.legs
        out = np.zeros((len(legs), len(t), 3, self.modes_raw.shape[1]))
        for i, parts in enumerate(legs):
            inner = (t > 1e-9) & (t < 1 - 1e-9)
            if inner.any():
                stations = self._stations(i, t[inner])
                values = []
                for part, x in stations:
                    if part.hollow:
                        values.append(self._section_mean(part, x[None])[0])
                    else:
                        values.append(None)
                solid = [k for k, v in enumerate(values) if v is None]
                if solid:  # one evaluation per part, as uniform legs always had
                    for part in parts:
                        ks = [k for k in solid if stations[k][0] is part]
                        if ks:
                            pts = np.array([stations[k][1] for k in ks])
                            for k, v in zip(ks, evaluate(self.disc, part.name, pts,
                                                         self.modes_raw)):
                                values[k] = v
                out[i, inner] = np.stack(values)
            for end, face in ((0.0, parts[0].start_face), (1.0, parts[-1].end_face)):
                sel = np.abs(t - end) <= 1e-9
                if sel.any():
                    out[i, sel] = self.constraints.reference_motion(face, self.modes_raw)[:3]
        return out

    def leg_axis_twists(self, fractions) -> np.ndarray:
        """Rotation of each leg's sections about its axis (rad) at fractions t, per mode:
        (3 legs, len(fractions), n_modes). Inside the leg, the mean of (e x u) . a / r over
        `section_arms` (six points) at half the radius of a solid part, at mid-wall of a hollow
        one (exact for a rigid twist of the section); at the joint centres the face's
        projected rigid rotation."""
        t = station_fractions(fractions)
        legs = self.assembly.legs
        out = np.zeros((len(legs), len(t), self.modes_raw.shape[1]))
        for i, parts in enumerate(legs):
            b, a = np.asarray(parts[0].start), np.asarray(parts[-1].end)
            axis = (a - b) / np.linalg.norm(a - b)
            inner = (t > 1e-9) & (t < 1 - 1e-9)
            if inner.any():
                stations = self._stations(i, t[inner])
                twist = np.zeros((len(stations), self.modes_raw.shape[1]))
                for part in parts:
                    ks = [k for k, (p, _) in enumerate(stations) if p is part]
                    if not ks:
                        continue
                    centres = np.array([stations[k][1] for k in ks])
                    arm = (0.5 * (part.radius + part.inner_radius) if part.hollow
                           else 0.5 * part.radius)
                    arms = section_arms(axis, arm)  # (k, 3)
                    pts = (centres[:, None, :] + arms[None]).reshape(-1, 3)
                    u = evaluate(self.disc, part.name, pts, self.modes_raw)
                    u = u.reshape(len(centres), len(arms), 3, -1)
                    twist[ks] = twist_from_section(axis, arms, u)
                out[i, inner] = twist
            for end, face in ((0.0, parts[0].start_face), (1.0, parts[-1].end_face)):
                sel = np.abs(t - end) <= 1e-9
                if sel.any():
                    out[i, sel] = axis @ self.constraints.reference_motion(face,
                                                                          self.modes_raw)[3:]
        return out

    @property
    def platform_motion(self) -> np.ndarray:
        """(6, n_modes): translation of o and rotation of the platform. Rigid platform: its six
        coordinates; elastic: the mass-weighted best-fit rigid motion of the plate about o."""
        cols = self.constraints.columns.get("platform")
        if cols is not None:
            return self.modes_q[cols].copy()
        nodes = self.disc.body_nodes("platform")
        dofs = (3 * nodes[:, None] + np.arange(3)).ravel()
        u = self.modes_raw[dofs].reshape(len(nodes), 3, -1)
        if self.mass_matrix is None:  # solve_pose_tetrahedra always sets it
            raise TypeError("FemResult.mass_matrix is None: no mass to fit the platform with")
        return rigid_fit(self.disc.node_xyz[nodes], u, self.geometry.platform_centre,
                         mass=self.mass_matrix[dofs][:, dofs])

    def write_vtu(self, path, pvd: bool = False) -> None:
        """Mode shapes for ParaView (fem_reference.export): legs and platform in one VTU, each
        mode named with its frequency and scaled for display; with `pvd`, also the .pvd
        collection beside it to step through the modes."""
        rigid = "platform" not in self.disc.bodies
        write_modes_vtu(path, self.disc, self.modes_raw, self.frequencies_hz,
                        plate=self.plate if rigid else None,
                        platform_motion=self.platform_motion if rigid else None)
        if pvd:
            write_mode_collection(path)

    def to_dict(self) -> dict:
        return solve_record(self, rim_factor=self.options.mesh.rim_factor,
                            rim_zone_m=self.options.mesh.rim_zone,
                            rim_grading=self.options.mesh.rim_grading)


def solve_pose_tetrahedra(manipulator, geometry, assembly: Assembly, options: FemOptions,
                          runtime: FemRuntime, t0: float | None = None,
                          keep_system: bool = False) -> FemResult:
    """Natural frequencies and modes of the pose's solid model, the legs (and an elastic
    plate) meshed in 3D; `assembly` is the pose's bodies (`meshing.bodies.pose_assembly`),
    checked by `guard.check_mesh_size`; `t0` the start of the solve, for the timings (default:
    now)."""
    if t0 is None:
        t0 = time.perf_counter()
    elastic = options.platform == "elastic"
    settings = options.mesh
    try:
        solid, hit = cached_mesh(assembly, settings, runtime.cache_dir, runtime.use_cache)
    except GmshFailure as exc:
        raise FemError(f"mesh_size_mm = {settings.size * 1e3:g}: gmsh failed ({exc})") from None
    t_mesh = time.perf_counter()

    disc = discretise(solid)
    if disc.n_dofs > runtime.max_dofs:
        raise FemError(f"mesh_size_mm = {settings.size * 1e3:g}: {disc.n_dofs} dofs, above "
                       f"max_dofs = {runtime.max_dofs}")
    k, m = stiffness_and_mass(disc, manipulator.material)
    try:
        cmap = build_constraints(disc, geometry, assembly, options.coupling, options.platform,
                                 stiffness=getattr(manipulator, "stiffness", None))
    except ValueError as exc:
        raise FemError(str(exc)) from None
    t_ = cmap.T
    plate = assembly.plate or platform_plate(manipulator, geometry)
    kq, mq = reduced_matrices(k, m, t_, None if elastic else cmap.columns["platform"], plate,
                              manipulator, geometry, options, cmap.springs)
    t_asm = time.perf_counter()

    try:
        # in a child process, so Ctrl-C and SIGTERM stop a long factorisation at once
        modes = stoppable(lowest_modes, kq, mq, options.modes, backend=runtime.backend)
    except (EigenError, WorkerDied) as exc:
        raise FemError(f"mesh_size_mm = {settings.size * 1e3:g}: eigensolver failed "
                       f"({exc})") from None
    vq = normalise_signs(modes.vectors)
    v_raw = t_ @ vq
    t_end = time.perf_counter()
    result = FemResult(
        frequencies_hz=modes.frequencies_hz,
        dofs=int(kq.shape[0]),
        raw_dofs=disc.n_dofs,
        mesh_size=float(settings.size),
        timings={"mesh": t_mesh - t0, "assemble": t_asm - t_mesh, "solve": t_end - t_asm,
                 "total": t_end - t0},
        clusters=[list(map(int, c)) for c in modes.clusters],
        cache_hit=hit,
        mesh_digest=solid.digest(),
        n_elements=int(len(solid.tets)),
        options=options,
        min_quality=float(solid.info.get("min_scaled_jacobian", float("nan"))),
        geometry=geometry,
        assembly=assembly,
        disc=disc,
        constraints=cmap,
        modes_q=vq,
        modes_raw=v_raw,
        mass_matrix=m,
        plate=plate,
        system=(kq, mq) if keep_system else None,
    )
    return result

