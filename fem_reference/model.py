"""One pose of the 3-RPS manipulator as a 3D solid: mesh, assemble, constrain, solve.

solve_pose(manipulator, geometry, options) -> FemResult. Steps (timed):
  mesh      bodies of the pose -> gmsh 10-node tetrahedra (or the mesh cache)
  assemble  scikit-fem P2 stiffness and consistent mass, joint constraint map T (u = T q),
            reduced K_q = T^T K T, M_q = T^T M T (+ the rigid platform's 6x6 mass at o, Eqs. 7-9,
            integrated over its own meshed plate: rigid_platform.py)
  solve     shift-invert Lanczos for the lowest modes
Every failure on bad input is a FemError with one line naming the offending value; nothing is
written (cache entries and VTU files are atomic).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
import math
import os
import time

import numpy as np
import scipy.sparse as sp

from common.rigid_body import rigid_fit
from common.settings import MAX_SOLVED_MODES, check_settings, nested_setting, setting
from meshing.bodies import Assembly, GeometryError, Plate, platform_plate, pose_assembly
from meshing.cache import cached_mesh
from meshing.geometry import GmshFailure, MeshSettings, element_size

from .assembly import stiffness_and_mass
from .constraints import COUPLINGS, ConstraintMap, build_constraints
from .discretisation import Discretisation, discretise
from .eigen import BACKENDS, EigenError, Modes, lowest_modes
from .export import write_mode_collection, write_modes_vtu
from .resources import MemoryLimitError, check_memory
from .rigid_platform import meshed_plate_mass
from common.worker import WorkerDied, stoppable
from . import probes

PLATFORMS = ("rigid", "elastic")
LEG_MODELS = ("harmonic", "tetrahedra")
# P2 nodes ~ NODES_PER_VOLUME V / h^3 + NODES_PER_AREA A / h^2 + NODES_PER_RIM_AREA times the
# rims' surface term (estimate_raw_dofs). Fitted (relative least squares) to 82 meshes of the
# pinned gmsh options with Netgen's optimiser: the paper's legs, three poses, 16-50 mm, uniform
# and six graded families; then raised by 1.2 so that no mesh has more nodes than estimated:
# estimate / actual 1.01-1.36 there, 1.15-1.38 on stocky (d = 150 mm) and slender (d = 30 mm)
# legs. The fit leaves no separate volume term at the rims: the surface meshes carry the
# grading, and the interior follows them.
NODES_PER_VOLUME = 4.4
NODES_PER_AREA = 7.4
NODES_PER_RIM_AREA = 14.0
MAX_ESTIMATE = 10**15  # dofs: the estimate of absurdly small sizes, far above any guard


def legs_for(platform: str | None, legs: str | None) -> str | None:
    """The leg discretisation asked for: `legs` when given; else tetrahedra for an elastic
    plate (meshed in 3D, so are the legs joined to it); else None (FemOptions' default)."""
    if legs is None and platform == "elastic":
        return "tetrahedra"
    return legs


class FemError(ValueError):
    """Bad input or a failed FEM step; the message is one line naming the offending value."""


@dataclass(frozen=True)
class FemOptions:
    """What the solid model is: the mesh, the platform, the joint-face coupling, the modes.

    Everything that changes the answer is here (the result cache keys on the whole object);
    how the answer is obtained (cache directory, DOF guard, linear solver) is `FemRuntime`.
    """

    mesh: MeshSettings = nested_setting(MeshSettings)
    platform: str = setting("rigid", kind=str, choices=PLATFORMS,
                            doc="rigid: 6 coordinates at o with the plate's inertia (as the "
                            "paper); elastic: the plate meshed as a solid")
    legs: str = setting("harmonic", kind=str, choices=LEG_MODELS,
                        doc="how the solid legs are discretised: harmonic (the exact Fourier "
                        "split of each cylinder's 3D elasticity on a 2D meridian mesh of P2 "
                        "triangles, harmonic.py; rigid platform only) or tetrahedra (a 3D "
                        "mesh of 10-node tetrahedra, graded toward the rims; what an elastic "
                        "platform takes when legs is not given)")
    coupling: str = setting("rigid", kind=str, choices=COUPLINGS,
                            doc="how a joint face follows its joint centre: rigid (RBE2-like) or "
                            "distributing (RBE3-like, the face may warp)")
    modes: int = setting(6, kind=int, minimum=1, maximum=MAX_SOLVED_MODES, scene=False,
                         doc="number of modes solved for")
    platform_mesh: float = setting(
        0.2, minimum=0.0, exclusive_minimum=True, maximum=2.0, scene=False,
        doc="element size of the rigid platform's own mesh, over which its mass and inertia "
        "are integrated, as a fraction of the platform radius (0.2: 1e-6 of the disk's "
        "closed form, fem_reference/rigid_platform.py)")

    def __post_init__(self):
        if not isinstance(self.mesh, MeshSettings):
            raise FemError(f"mesh = {self.mesh!r}: expected MeshSettings")
        try:
            check_settings(self)
        except ValueError as exc:
            raise FemError(str(exc)) from None
        if self.legs == "harmonic" and self.platform != "rigid":
            raise FemError(f"legs = 'harmonic' with platform = {self.platform!r}: harmonic legs "
                           "need the rigid platform (use legs = 'tetrahedra')")

    @property
    def mesh_size(self) -> float:
        return self.mesh.size

    def with_size(self, size: float) -> "FemOptions":
        """The same options at another global element size (m)."""
        try:
            return replace(self, mesh=replace(self.mesh, size=float(size)))
        except ValueError as exc:
            raise FemError(str(exc)) from None


@dataclass(frozen=True)
class FemRuntime:
    """How a solve is run; nothing here changes the frequencies."""

    cache_dir: str | os.PathLike | None = None  # mesh cache; None: meshing.cache.DEFAULT_DIR
    use_cache: bool = True
    max_dofs: int = setting(600_000, kind=int, minimum=100, maximum=100_000_000,
                            doc="refuse meshes with more raw degrees of freedom than this "
                            "(estimated before meshing); whatever it says, a solve whose "
                            "estimated memory exceeds half of what the machine has available "
                            "is refused too (fem_reference/resources.py)")
    backend: str = setting("splu", kind=str, choices=BACKENDS, scene=False,
                           doc="sparse factorisation of the shift-invert eigen solve")

    def __post_init__(self):
        try:
            check_settings(self)
        except ValueError as exc:
            raise FemError(str(exc)) from None


@dataclass
class FemResult:
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
    geometry: object = field(repr=False)  # analytical.kinematics.PoseGeometry
    assembly: Assembly = field(repr=False)  # the meshed bodies (names of legs and faces)
    disc: Discretisation = field(repr=False)
    constraints: ConstraintMap = field(repr=False)
    modes_q: np.ndarray = field(repr=False)  # (n_free, modes), M-orthonormal
    modes_raw: np.ndarray = field(repr=False)  # (raw_dofs, modes) = T modes_q
    mass_matrix: object = field(default=None, repr=False)  # raw consistent mass (CSR)
    plate: Plate | None = field(default=None, repr=False)  # the platform (meshed or rigid)

    def leg_axis_displacements(self, fractions) -> np.ndarray:
        """Translation of the leg axis points B_i + t (A_i - B_i), t in `fractions`, per mode:
        (3 legs, len(fractions), 3, n_modes), base coordinates. Inside the leg the P2 field is
        interpolated; at t = 0 and t = 1 (the joint centres) the reference points' motion is
        used (B_i fixed; A_i moving with the platform)."""
        t = station_fractions(fractions)
        legs = self.assembly.cylinders
        out = np.zeros((len(legs), len(t), 3, self.modes_raw.shape[1]))
        for i, leg in enumerate(legs):
            b, a = np.asarray(leg.start), np.asarray(leg.end)
            inner = (t > 1e-9) & (t < 1 - 1e-9)
            if inner.any():
                pts = b + t[inner, None] * (a - b)
                out[i, inner] = probes.evaluate(self.disc, leg.name, pts, self.modes_raw)
            for end, face in ((0.0, leg.start_face), (1.0, leg.end_face)):
                sel = np.abs(t - end) <= 1e-9
                if sel.any():
                    out[i, sel] = self.constraints.reference_motion(face, self.modes_raw)[:3]
        return out

    def leg_axis_twists(self, fractions) -> np.ndarray:
        """Rotation of each leg's sections about its axis (rad) at fractions t, per mode:
        (3 legs, len(fractions), n_modes). Inside the leg, the mean of (e x u) . a / r over
        `section_arms` (six points) at half the radius (exact for a rigid twist of the
        section); at the joint centres the face's projected rigid rotation."""
        t = station_fractions(fractions)
        legs = self.assembly.cylinders
        out = np.zeros((len(legs), len(t), self.modes_raw.shape[1]))
        for i, leg in enumerate(legs):
            b, a = np.asarray(leg.start), np.asarray(leg.end)
            axis = (a - b) / np.linalg.norm(a - b)
            inner = (t > 1e-9) & (t < 1 - 1e-9)
            if inner.any():
                centres = b + t[inner, None] * (a - b)
                arms = section_arms(axis, 0.5 * leg.radius)  # (k, 3)
                pts = (centres[:, None, :] + arms[None]).reshape(-1, 3)
                u = probes.evaluate(self.disc, leg.name, pts, self.modes_raw)
                u = u.reshape(len(centres), len(arms), 3, -1)
                out[i, inner] = twist_from_section(axis, arms, u)
            for end, face in ((0.0, leg.start_face), (1.0, leg.end_face)):
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


def solve_record(result, **extra) -> dict:
    """The plain record of a solve (FemResult or harmonic.HarmonicResult) and its extras."""
    return {
        "frequencies_hz": [float(f) for f in result.frequencies_hz],
        "dofs": result.dofs,
        "raw_dofs": result.raw_dofs,
        "mesh_size_m": result.mesh_size,
        "elements": result.n_elements,
        "min_scaled_jacobian": result.min_quality,
        "timings": dict(result.timings),
        "clusters": result.clusters,
        "cache_hit": result.cache_hit,
        "mesh_digest": result.mesh_digest,
        "platform": result.options.platform,
        "coupling": result.options.coupling,
        "legs": result.options.legs,
        **extra,
    }


def section_arms(axis: np.ndarray, radius: float, count: int = 6) -> np.ndarray:
    """(count, 3): points at `radius` from a section's centre, evenly around `axis`. The mean
    tangential displacement over `count` such points sees harmonics 0 (the twist) and
    multiples of `count` only: six keeps section distortions up to n = 5 out of the twist."""
    axis = np.asarray(axis, float)
    e1 = np.cross(axis, np.eye(3)[np.argmin(np.abs(axis))])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    angles = 2 * np.pi * np.arange(count) / count
    return radius * (np.cos(angles)[:, None] * e1 + np.sin(angles)[:, None] * e2)


def twist_from_section(axis: np.ndarray, arms: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Section rotation about `axis` from displacements u (..., k, 3, m) at `arms` (k, 3):
    mean over the points of axis . (arm x u) / |arm|^2 (translations and bending cancel in
    the mean over points evenly around the axis)."""
    cross = np.cross(arms[:, :, None], u, axis=-2)  # (..., k, 3, m)
    return np.einsum("c,...kcm->...m", np.asarray(axis, float), cross) / (
        len(arms) * float(np.sum(arms[0] ** 2)))


def estimate_raw_dofs(assembly: Assembly, settings: MeshSettings) -> int:
    """Raw dof count of the P2 mesh, estimated from volume and surface before meshing.

    Uniform part: NODES_PER_VOLUME V / h^3 + NODES_PER_AREA A / h^2. Graded part, at every
    joint-face rim (a circle of the leg radius R): the surface nodes that the finer size s(r) of
    `meshing.geometry.element_size` adds at a distance r from the rim, on the two surfaces that
    meet there (the face and the wall), NODES_PER_RIM_AREA int (1/s^2 - 1/h^2) 2 (2 pi R) dr.
    """
    h = settings.size
    try:
        nodes = NODES_PER_VOLUME * assembly.volume / h**3 + NODES_PER_AREA * assembly.area / h**2
        if settings.rim_factor < 1 and settings.rim_zone > 0:
            for c in assembly.cylinders:
                reach = min(settings.rim_zone, c.radius, 0.5 * c.length)
                r = reach * np.concatenate([np.linspace(0.0, 1e-3, 50)[:-1],
                                            np.geomspace(1e-3, 1.0, 400)])
                finer = 1 / element_size(settings, r) ** 2 - 1 / h**2
                nodes += (NODES_PER_RIM_AREA * 2 * (2 * math.pi * c.radius)
                          * float(np.trapezoid(2 * finer, r)))
    except (ZeroDivisionError, OverflowError, FloatingPointError):  # h^3 underflows
        nodes = math.inf
    if not math.isfinite(nodes):
        return MAX_ESTIMATE
    return int(3 * nodes) if 3 * nodes < MAX_ESTIMATE else MAX_ESTIMATE


def check_mesh_size(assembly: Assembly, options: FemOptions, runtime: FemRuntime) -> None:
    """Refuse, before meshing, a size coarser than a leg or whose estimated dofs exceed the
    DOF guard, or (tetrahedra) whose solve would not fit in memory: FemError naming the size."""
    settings = options.mesh
    diameter = 2 * assembly.cylinders[0].radius
    shown = f"mesh_size_mm = {settings.size * 1e3:g}"
    if settings.size > diameter:
        raise FemError(f"{shown}: coarser than the leg diameter {diameter * 1e3:g} mm (needs "
                       "at least one element across a leg)")
    harmonic = options.legs == "harmonic"
    if harmonic:  # 2D meridians: a fraction of the memory of 3D meshes
        from .harmonic import estimate_raw_dofs as estimate_harmonic
        estimate = estimate_harmonic(assembly, settings.size)
    else:
        estimate = estimate_raw_dofs(assembly, settings)
    if estimate > runtime.max_dofs:
        raise FemError(f"{shown}: about {estimate}{' harmonic' if harmonic else ''} dofs "
                       f"expected, above max_dofs = {runtime.max_dofs}")
    try:  # before meshing: peak against the memory the machine has, whatever max_dofs says
        check_memory(estimate, diameter, settings.size, harmonic=harmonic)
    except MemoryLimitError as exc:
        raise FemError(str(exc)) from None


def solve_pose(manipulator, geometry, options: FemOptions,
               runtime: FemRuntime = FemRuntime()) -> FemResult:
    """Natural frequencies and modes of the 3D solid model of one pose."""
    if not isinstance(options, FemOptions):
        raise FemError(f"options = {options!r}: expected FemOptions")
    if not isinstance(runtime, FemRuntime):
        raise FemError(f"runtime = {runtime!r}: expected FemRuntime")
    t0 = time.perf_counter()
    elastic = options.platform == "elastic"
    try:
        assembly = pose_assembly(manipulator, geometry, elastic_platform=elastic)
    except GeometryError as exc:
        raise FemError(str(exc)) from None
    settings = options.mesh
    check_mesh_size(assembly, options, runtime)
    if options.legs == "harmonic":
        from .harmonic import HarmonicError, solve_pose_harmonic
        try:  # sub-second: in this process, so its per-leg caches serve the next pose
            return solve_pose_harmonic(manipulator, geometry, options, runtime.max_dofs)
        except HarmonicError as exc:
            raise FemError(str(exc)) from None
    try:
        solid, hit = cached_mesh(assembly, settings, runtime.cache_dir, runtime.use_cache)
    except GmshFailure as exc:
        raise FemError(f"mesh_size_mm = {settings.size * 1e3:g}: gmsh failed ({exc})") from None
    t_mesh = time.perf_counter()

    disc = discretise(solid)
    if disc.n_dofs > runtime.max_dofs:
        raise FemError(f"mesh_size_mm = {settings.size * 1e3:g}: {disc.n_dofs} dofs, above max_dofs = "
                       f"{runtime.max_dofs}")
    k, m = stiffness_and_mass(disc, manipulator.material)
    try:
        cmap = build_constraints(disc, geometry, assembly, options.coupling, options.platform)
    except ValueError as exc:
        raise FemError(str(exc)) from None
    t_ = cmap.T
    plate = assembly.plate or platform_plate(manipulator, geometry)
    kq, mq = reduced_matrices(k, m, t_, None if elastic else cmap.columns["platform"], plate,
                              manipulator, geometry, options)
    t_asm = time.perf_counter()

    try:
        # in a child process, so Ctrl-C and SIGTERM stop a long factorisation at once
        modes = stoppable(lowest_modes, kq, mq, options.modes, backend=runtime.backend)
    except (EigenError, WorkerDied) as exc:
        raise FemError(f"mesh_size_mm = {settings.size * 1e3:g}: eigensolver failed ({exc})") from None
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
    )
    return result


def reduced_matrices(k, m, t, platform_cols, plate, manipulator, geometry,
                     options: FemOptions) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """K_q = T^T K T and M_q = T^T M T (paper Eqs. 20-22), plus the rigid platform's 6x6 mass
    at o on its coordinates `platform_cols` (Eqs. 7-9, integrated over its own meshed plate,
    rigid_platform.py; None: an elastic plate, already in K and M), symmetric to round-off.
    T^T (K T) with T^T in CSR: both products row-major, half the time of (T^T K) T (which
    converts T^T from CSC on the way; measured 0.016 s against 0.035 s at 17k dofs)."""
    t_rows = t.T.tocsr()
    kq = (t_rows @ (k @ t)).tocsr()
    mq = (t_rows @ (m @ t)).tocsr()
    if platform_cols is not None:
        try:
            mp = sp.coo_matrix(meshed_plate_mass(
                plate, np.asarray(geometry.rotation), manipulator.material.density,
                options.platform_mesh * plate.radius))
        except GmshFailure as exc:
            raise FemError(f"platform_mesh = {options.platform_mesh:g}: gmsh failed on the "
                           f"platform plate ({exc})") from None
        mq = mq + sp.csr_matrix((mp.data, (platform_cols[mp.row], platform_cols[mp.col])),
                                shape=mq.shape)
    return 0.5 * (kq + kq.T), 0.5 * (mq + mq.T)


def station_fractions(fractions) -> np.ndarray:
    """The fractions t of a leg (B_i -> A_i) where shapes are sampled, checked to lie in
    [0, 1] (FemError naming them)."""
    t = np.atleast_1d(np.asarray(fractions, float))
    if t.ndim != 1 or np.any(~np.isfinite(t)) or np.any(t < 0) or np.any(t > 1):
        raise FemError(f"fractions = {np.asarray(fractions).tolist()!r}: need values in [0, 1]")
    return t


def normalise_signs(v: np.ndarray) -> np.ndarray:
    """Deterministic sign: the largest-magnitude entry of every mode is positive."""
    idx = np.argmax(np.abs(v), axis=0)
    s = np.sign(v[idx, np.arange(v.shape[1])])
    s[s == 0] = 1
    return v * s


def with_size(options: FemOptions, size: float) -> FemOptions:
    return options.with_size(size)

