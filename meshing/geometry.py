"""gmsh (OpenCASCADE) script: the bodies of one pose -> second-order tetrahedral mesh.

Each leg part is its own solid cylinder or tube (a uniform leg: one cylinder B_i -> A_i; a
stepped one: a housing and a rod, `meshing.bodies.leg_parts`), the (optional) elastic platform
its own plate; nothing is fused, so the bodies share no node and are joined only by the FEM's
joint constraints. Elements are 10-node tetrahedra with curved (geometry-following) mid-edge nodes.

Size control: a global size h everywhere (in a tube at most its wall thickness, so that a thin
wall is never spanned by one flat element), graded toward the rims of the joint faces (the
edges of rigidly coupled faces, where the stress is singular; a tube's end face has two, its
outer and its inner circle): at a distance r from the nearest rim the
size is h (r / rim_zone)^a, at least rim_factor h and at most h. With a = 1 the elements near a
rim are as large as a fixed fraction of their distance to it (geometric layers). Every length
of the field is h times a function of r that does not depend on h, so meshes at different h
form one family (the refinement study's observed order is that of the family). Every option that
gmsh would otherwise read from its defaults or the environment is pinned below, with one thread,
so the same input gives the same mesh, node for node.

gmsh is a process-wide singleton and neither thread-safe nor reentrant: calls are serialised by a
lock, and gmsh is always finalised, also on error.
"""
from __future__ import annotations

import contextlib
import signal
import threading
from dataclasses import dataclass

import numpy as np

from common.errors import ComputeError
from common.settings import (
    MAX_LENGTH,
    MIN_PART,
    as_dict,
    check_settings,
    named_setting,
    setting,
)

from .bodies import Assembly, Cylinder, Plate
from .mesh import SolidMesh

MIN_MESH_SIZE = MIN_PART / 100  # m: a hundredth of the smallest machine part (common.settings)
MIN_RIM_FACTOR = 0.005  # the deepest rim grading measured (fem_reference.harmonic's references)
MIN_RIM_GRADING = 0.1  # a flatter exponent grades nothing: (r / zone)^0.1 = 0.4 at r = 1e-4 zone


class GmshFailure(ComputeError):
    """gmsh could not build a valid mesh for these bodies and settings."""


@dataclass(frozen=True)
class MeshSettings:
    """How finely the bodies of one pose are meshed: the one declaration of every mesh knob.

    A new knob is a field here (with its `setting` declaration) and, if a scene should set it,
    a key in the scene file: the scene reader, the FEM options, the mesh cache key and the
    result cache key all take the whole object.
    """

    size: float = setting(doc="global element size h of the solid mesh (at least 0.01 mm, a "
                          "hundredth of the smallest machine part; the memory estimate refuses "
                          "far coarser meshes of real machines)", unit="mm",
                          minimum=MIN_MESH_SIZE, maximum=MAX_LENGTH, scene_name="mesh_size")
    rim_factor: float = setting(
        0.4, doc="smallest element size, at the rims of the joint faces (stress-singular edges "
        "of rigidly coupled faces), as a fraction of the global size, for tetrahedral legs and "
        "an elastic plate (harmonic legs grade their meridian's rim corners themselves, "
        "fem_reference/meridian.py); 1 = no refinement; at "
        "least 0.005, the deepest grading measured (the harmonic legs' reference meshes): the "
        "singular rim limits convergence whatever the grading, so deeper only adds elements",
        minimum=MIN_RIM_FACTOR, maximum=1.0)
    # no default here: a scene's is a fraction of its legs' diameter, the one rule
    # (scene.load.geometry_defaults); every other caller gives its own, by name
    rim_zone: float = named_setting(
        doc="distance from the joint-face rims at which the element size is back to the "
        "global size (0 = no refinement)", unit="mm", minimum=0.0, maximum=MAX_LENGTH)
    rim_grading: float = setting(
        1.0, doc="exponent a of the graded size h (distance / rim_zone)^a near the rims, "
        "bounded by rim_factor h below and h above; 1: geometric (elements as large as a "
        "fixed fraction of their distance to the rim); at least 0.1: below it the size reaches "
        "rim_factor h only in the last 1e-4 of the zone (no grading; rim_factor = 1 says so)",
        minimum=MIN_RIM_GRADING, maximum=1.0)

    def __post_init__(self):
        check_settings(self)

    def canonical(self) -> dict:
        return as_dict(self)


# Pinned gmsh options (name -> value). Algorithm 6 = Frontal-Delaunay (2D), 1 = Delaunay (3D).
PINNED_OPTIONS = {
    "General.Terminal": 0,
    "General.Verbosity": 0,
    "General.NumThreads": 1,
    "Geometry.OCCParallel": 0,
    "Geometry.Tolerance": 1e-8,
    "Mesh.MaxNumThreads1D": 1,
    "Mesh.MaxNumThreads2D": 1,
    "Mesh.MaxNumThreads3D": 1,
    "Mesh.RandomSeed": 1,
    "Mesh.RandomFactor": 1e-9,
    "Mesh.RandomFactor3D": 1e-12,
    "Mesh.Algorithm": 6,
    "Mesh.Algorithm3D": 1,
    "Mesh.Optimize": 1,
    "Mesh.OptimizeNetgen": 1,
    "Mesh.OptimizeThreshold": 0.3,
    "Mesh.Smoothing": 1,
    "Mesh.ElementOrder": 2,
    "Mesh.SecondOrderLinear": 0,
    "Mesh.HighOrderOptimize": 0,
    "Mesh.MeshSizeFromPoints": 0,
    "Mesh.MeshSizeFromCurvature": 0,
    "Mesh.MeshSizeExtendFromBoundary": 0,
    "Mesh.MeshSizeFactor": 1.0,
    "Mesh.MinimumCircleNodes": 7,
    "Mesh.MinimumCurveNodes": 3,
    "Mesh.RecombineAll": 0,
    "Mesh.SubdivisionAlgorithm": 0,
    "Mesh.Binary": 0,
}


def rim_size_expression(settings: MeshSettings, distance: str) -> str:
    """gmsh MathEval text of the element size at `distance` (a field) from the nearest rim:
    h (distance / rim_zone)^a, bounded by rim_factor h and h (see `element_size`)."""
    h, z = float(settings.size), float(settings.rim_zone)
    return (f"Max({h * settings.rim_factor!r}, Min({h!r}, "
            f"{h!r} * ({distance} / {z!r})^{float(settings.rim_grading)!r}))")


def element_size(settings: MeshSettings, distance):
    """The size that the mesh is asked for at `distance` (m, array) from the nearest rim."""
    h = float(settings.size)
    if settings.rim_factor >= 1.0 or settings.rim_zone <= 0.0:
        return np.full_like(np.asarray(distance, float), h)
    ratio = np.asarray(distance, float) / settings.rim_zone
    return np.clip(h * ratio ** settings.rim_grading, h * settings.rim_factor, h)


_GMSH_LOCK = threading.Lock()
GMSH_TETRA10_TO_MESHIO = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8]  # gmsh edge 8 is 23, 9 is 13


def gmsh_version() -> str:
    import gmsh
    return str(gmsh.__version__)


def _add_cylinder(cyl: Cylinder, occ) -> int:
    """The OCC volume of a cylinder, or of a tube (the outer cylinder less the bore)."""
    axis = np.subtract(cyl.end, cyl.start)
    outer = occ.addCylinder(*cyl.start, *axis, cyl.radius)
    if not cyl.hollow:
        return outer
    bore = occ.addCylinder(*cyl.start, *axis, cyl.inner_radius)
    out, _ = occ.cut([(3, outer)], [(3, bore)])
    volumes = [t for d, t in out if d == 3]
    if len(volumes) != 1:
        raise GmshFailure(f"{cyl.name}: the tube's cut gave {len(volumes)} volumes")
    return volumes[0]


def _face_tags(occ_dim_tags, cylinder: Cylinder, model) -> tuple[int, int]:
    """The planar end faces of an OCC cylinder or tube: (face at start, face at end) (an
    annulus's centre of mass is its centre too)."""
    faces = [t for d, t in model.getBoundary(occ_dim_tags, oriented=False) if d == 2]
    start, end = np.asarray(cylinder.start), np.asarray(cylinder.end)
    found = {}
    for tag in faces:
        c = np.asarray(model.occ.getCenterOfMass(2, tag))
        for label, p in (("start", start), ("end", end)):
            if np.linalg.norm(c - p) < 1e-6 * max(1.0, cylinder.length):
                found[label] = tag
    if set(found) != {"start", "end"}:
        raise GmshFailure(f"{cylinder.name}: end faces not found among OCC faces {faces}")
    return found["start"], found["end"]


def _wall_fields(model, assembly: Assembly, volumes, h: float) -> list[int]:
    """Per tube thinner than h: a size field of its wall thickness restricted to the tube (its
    volume, surfaces and curves), so that at least one element spans the wall and none is a
    flat sliver across it. None for solid parts (their meshes stay as they were)."""
    fields = []
    for cyl, (_, vtag) in zip(assembly.cylinders, volumes):
        if not cyl.hollow or cyl.wall >= h:
            continue
        const = model.mesh.field.add("MathEval")
        model.mesh.field.setString(const, "F", repr(float(cyl.wall)))
        surfaces = [t for d, t in model.getBoundary([(3, vtag)], oriented=False) if d == 2]
        curves = sorted({t for s in surfaces
                         for d, t in model.getBoundary([(2, s)], oriented=False) if d == 1})
        restrict = model.mesh.field.add("Restrict")
        model.mesh.field.setNumber(restrict, "InField", const)
        model.mesh.field.setNumbers(restrict, "VolumesList", [vtag])
        model.mesh.field.setNumbers(restrict, "SurfacesList", surfaces)
        model.mesh.field.setNumbers(restrict, "CurvesList", curves)
        fields.append(restrict)
    return fields


def _add_plate(plate: Plate, occ) -> int:
    n = np.asarray(plate.normal, float)
    bottom = np.asarray(plate.centre) - 0.5 * plate.thickness * n
    if plate.shape == "disk":
        return occ.addCylinder(*bottom, *(plate.thickness * n), plate.radius)
    pts = [occ.addPoint(*(np.asarray(c) - 0.5 * plate.thickness * n)) for c in plate.corners]
    lines = [occ.addLine(pts[k], pts[(k + 1) % 3]) for k in range(3)]
    surface = occ.addPlaneSurface([occ.addCurveLoop(lines)])
    out = occ.extrude([(2, surface)], *(plate.thickness * n))
    return next(t for d, t in out if d == 3)


# Element quality: the minimum scaled Jacobian (gmsh "minSJ", 1 for an undistorted element,
# <= 0 folded) of every curved tetrahedron. Without Netgen's optimiser most meshes of the
# paper's poses had nearly degenerate curved elements (minSJ 0.000-0.02 at 25-50 mm, measured
# on six poses, some folded); with it (pinned above, +0.1-0.2 s at 40 mm) 0.15-0.88. Below
# MIN_QUALITY the mesh is rebuilt once with gmsh's high-order optimiser on top (REPAIR_OPTIONS,
# 0.68-0.85 on the same poses, twice the meshing time); in a child process, because that
# optimiser can abort the whole process (std::runtime_error, measured without Netgen). A mesh
# still below the threshold is refused (GmshFailure naming the value).
MIN_QUALITY = 0.1
REPAIR_OPTIONS = {"Mesh.HighOrderOptimize": 2}


def build_mesh(assembly: Assembly, settings: MeshSettings) -> SolidMesh:
    """Mesh the bodies with 10-node tetrahedra; physical groups per body and joint face.

    A mesh whose worst curved element has a scaled Jacobian below MIN_QUALITY is rebuilt once
    with REPAIR_OPTIONS (the same input always takes the same path, so meshes stay
    deterministic); `info["min_scaled_jacobian"]` records the quality of the mesh returned.
    Raises GmshFailure when gmsh fails or the repaired mesh is still below the threshold.
    """
    from common.worker import WorkerDied, stoppable

    mesh = _build_with(assembly, settings, {})
    if _quality(mesh) >= MIN_QUALITY:
        return mesh
    first = _quality(mesh)
    try:
        mesh = stoppable(_build_with, assembly, settings, REPAIR_OPTIONS)
    except WorkerDied:
        raise GmshFailure(f"min scaled Jacobian {first:.3g} below {MIN_QUALITY:g}, and gmsh's "
                          "high-order optimiser aborted on the repair") from None
    if _quality(mesh) < MIN_QUALITY:
        raise GmshFailure(f"min scaled Jacobian {_quality(mesh):.3g} below {MIN_QUALITY:g} "
                          f"after repair ({first:.3g} before; inverted if <= 0)")
    return mesh


def _quality(mesh: SolidMesh) -> float:
    return float(mesh.info["min_scaled_jacobian"])


@contextlib.contextmanager
def gmsh_session(options: dict):
    """gmsh initialised with PINNED_OPTIONS and `options` for the block, finalised after; its
    errors (plain Exception with its last message) become one-line GmshFailure. One session
    at a time per process (gmsh is not reentrant)."""
    import gmsh

    with _GMSH_LOCK:
        if gmsh.isInitialized():
            raise GmshFailure("gmsh is already initialised in this process (not reentrant)")
        # gmsh's library installs its own SIGTERM handler (measured: a `kill` after a mesh
        # ended the process without Python's cleanup); put the caller's handler back after.
        on_main_thread = threading.current_thread() is threading.main_thread()
        previous = signal.getsignal(signal.SIGTERM) if on_main_thread else None
        gmsh.initialize(readConfigFiles=False, interruptible=False)
        try:
            for name, value in {**PINNED_OPTIONS, **options}.items():
                gmsh.option.setNumber(name, value)
            yield gmsh
        except GmshFailure:
            raise
        except Exception as exc:
            raise GmshFailure(str(exc).splitlines()[0] if str(exc) else type(exc).__name__) \
                from None
        finally:
            gmsh.finalize()
            if on_main_thread and previous is not None:
                signal.signal(signal.SIGTERM, previous)


def _build_with(assembly: Assembly, settings: MeshSettings, extra: dict) -> SolidMesh:
    with gmsh_session(extra) as gmsh:
        return _build(gmsh, assembly, settings)


def _build(gmsh, assembly: Assembly, settings: MeshSettings) -> SolidMesh:
    model, occ = gmsh.model, gmsh.model.occ
    model.add("pose")
    h = float(settings.size)
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    walls = [c.wall for c in assembly.cylinders if c.hollow and c.wall < h]
    gmsh.option.setNumber("Mesh.MeshSizeMin", min([h] + walls) * min(1.0, settings.rim_factor))

    volumes = []  # (name, tag)
    for cyl in assembly.cylinders:
        volumes.append((cyl.name, _add_cylinder(cyl, occ)))
    if assembly.plate is not None:
        volumes.append((assembly.plate.name, _add_plate(assembly.plate, occ)))
    occ.synchronize()

    faces = {}  # name -> surface tag
    for cyl, (_, vtag) in zip(assembly.cylinders, volumes):
        base, top = _face_tags([(3, vtag)], cyl, model)
        faces[cyl.start_face], faces[cyl.end_face] = base, top
    for k, (name, vtag) in enumerate(volumes):
        model.setPhysicalName(3, model.addPhysicalGroup(3, [vtag], k + 1), name)
    face_names = sorted(faces)
    for k, name in enumerate(face_names):
        model.setPhysicalName(2, model.addPhysicalGroup(2, [faces[name]], len(volumes) + 1 + k),
                              name)

    size_fields = []
    if settings.rim_factor < 1.0 and settings.rim_zone > 0.0:
        rims = sorted({t for f in faces.values()
                       for d, t in model.getBoundary([(2, f)], oriented=False) if d == 1})
        dist = model.mesh.field.add("Distance")
        model.mesh.field.setNumbers(dist, "CurvesList", rims)
        model.mesh.field.setNumber(dist, "Sampling", 200)
        graded = model.mesh.field.add("MathEval")
        model.mesh.field.setString(graded, "F", rim_size_expression(settings, f"F{dist}"))
        size_fields.append(graded)
    size_fields += _wall_fields(model, assembly, volumes, h)
    if len(size_fields) == 1:
        model.mesh.field.setAsBackgroundMesh(size_fields[0])
    elif size_fields:
        smallest = model.mesh.field.add("Min")
        model.mesh.field.setNumbers(smallest, "FieldsList", size_fields)
        model.mesh.field.setAsBackgroundMesh(smallest)

    model.mesh.generate(3)

    node_tags, coords, _ = model.mesh.getNodes()
    if len(node_tags) == 0:
        raise GmshFailure("gmsh produced no nodes")
    order = np.argsort(node_tags)
    node_tags = np.asarray(node_tags, np.int64)[order]
    points = np.asarray(coords, float).reshape(-1, 3)[order]
    index = np.full(int(node_tags.max()) + 1, -1, np.int64)
    index[node_tags] = np.arange(len(node_tags))

    blocks_of: list[np.ndarray] = []
    tet_body, elem_tags = [], []
    for k, (name, vtag) in enumerate(volumes):
        types, etags, enodes = model.mesh.getElements(3, vtag)
        blocks = [(np.asarray(t_, np.int64), np.asarray(n_, np.int64))
                  for ty, t_, n_ in zip(types, etags, enodes) if ty == 11]
        if not blocks or sum(len(b[0]) for b in blocks) == 0:
            raise GmshFailure(f"gmsh produced no 10-node tetrahedra in {name}")
        for t_, n_ in blocks:
            conn = index[n_.reshape(-1, 10)][:, GMSH_TETRA10_TO_MESHIO]
            blocks_of.append(conn)
            tet_body.append(np.full(len(conn), k, np.int32))
            elem_tags.append(t_)
    tets = np.concatenate(blocks_of)
    all_tags = np.concatenate(elem_tags)
    quality = np.asarray(model.mesh.getElementQualities(all_tags.tolist(), "minSJ"))

    face_conn = {}
    for name in face_names:
        types, _, enodes = model.mesh.getElements(2, faces[name])
        tri = [np.asarray(n_, np.int64).reshape(-1, 6) for ty, n_ in zip(types, enodes) if ty == 9]
        if not tri:
            raise GmshFailure(f"gmsh produced no triangle6 on {name}")
        face_conn[name] = index[np.concatenate(tri)]
    if (tets < 0).any() or any((f < 0).any() for f in face_conn.values()):
        raise GmshFailure("element refers to an unknown node")

    # keep only used nodes (OCC may leave geometry points unattached)
    used = np.unique(np.concatenate([tets.ravel()] + [f.ravel() for f in face_conn.values()]))
    remap = np.full(len(points), -1, np.int64)
    remap[used] = np.arange(len(used))
    info = {"gmsh": gmsh_version(), "settings": settings.canonical(),
            "min_scaled_jacobian": float(quality.min())}
    return SolidMesh(points[used], remap[tets], np.concatenate(tet_body),
                     tuple(n for n, _ in volumes),
                     {n: remap[f] for n, f in face_conn.items()}, info)
