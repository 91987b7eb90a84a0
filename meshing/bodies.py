"""The solid bodies of one pose, as plain geometry: three leg cylinders and the platform plate.

Pure numpy, no gmsh: what `meshing.geometry` turns into OpenCASCADE solids, and what the mesh
cache hashes. Every leg is a solid circular cylinder of diameter d from its R-joint centre B_i
(base face) to its S-joint centre A_i (top face); the platform is a plate of thickness h centred
on o with normal R[:, 2] (a disk of radius r2, or the triangle A1A2A3). The bodies touch only at
the joints: they are meshed separately (no boolean fusion) and joined by the FEM's multipoint
constraints. SI units throughout.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from common.errors import InputError


class GeometryError(InputError):
    """The bodies cannot be built: degenerate, touching or intersecting legs, bad numbers."""


@dataclass(frozen=True)
class Cylinder:
    name: str  # body name, e.g. "leg1"
    start: tuple[float, float, float]  # centre of the first end face (B_i), m
    end: tuple[float, float, float]  # centre of the second end face (A_i), m
    radius: float  # m

    @property
    def start_face(self) -> str:
        """Name of the planar end face at `start` (the base joint's face)."""
        return f"{self.name}_base"

    @property
    def end_face(self) -> str:
        """Name of the planar end face at `end` (the platform joint's face)."""
        return f"{self.name}_top"

    @property
    def length(self) -> float:
        return float(np.linalg.norm(np.subtract(self.end, self.start)))

    @property
    def volume(self) -> float:
        return math.pi * self.radius**2 * self.length

    @property
    def area(self) -> float:
        return 2 * math.pi * self.radius * (self.radius + self.length)


@dataclass(frozen=True)
class Plate:
    name: str  # "platform"
    centre: tuple[float, float, float]  # o, mid-surface centre, m
    normal: tuple[float, float, float]  # unit normal R[:, 2]
    thickness: float  # h, m
    shape: str  # "disk" or "triangle"
    radius: float  # r2: disk radius or triangle circumradius, m
    corners: tuple[tuple[float, float, float], ...] = ()  # triangle vertices A_i (mid-surface)

    @property
    def volume(self) -> float:
        if self.shape == "disk":
            return math.pi * self.radius**2 * self.thickness
        side = math.sqrt(3.0) * self.radius
        return math.sqrt(3.0) / 4.0 * side**2 * self.thickness

    @property
    def area(self) -> float:
        if self.shape == "disk":
            face, rim = math.pi * self.radius**2, 2 * math.pi * self.radius
        else:
            side = math.sqrt(3.0) * self.radius
            face, rim = math.sqrt(3.0) / 4.0 * side**2, 3 * side
        return 2 * face + rim * self.thickness


@dataclass(frozen=True)
class Assembly:
    """The bodies of one pose, in base coordinates. `cylinders[i]` is leg i + 1."""

    cylinders: tuple[Cylinder, ...]
    plate: Plate | None = None

    @property
    def volume(self) -> float:
        return sum(c.volume for c in self.cylinders) + (self.plate.volume if self.plate else 0.0)

    @property
    def area(self) -> float:
        return sum(c.area for c in self.cylinders) + (self.plate.area if self.plate else 0.0)

    def canonical(self) -> dict:
        """A JSON-ready description, rounded to 1e-12 m so that hashing is stable."""
        def r(x):
            return [round(float(v), 12) for v in np.ravel(x)]
        out = {"cylinders": [{"name": c.name, "start": r(c.start), "end": r(c.end),
                              "radius": r([c.radius])[0]} for c in self.cylinders]}
        if self.plate is not None:
            p = self.plate
            out["plate"] = {"name": p.name, "centre": r(p.centre), "normal": r(p.normal),
                            "thickness": r([p.thickness])[0], "shape": p.shape,
                            "radius": r([p.radius])[0], "corners": r(p.corners)}
        return out


def _finite_point(name: str, x) -> tuple[float, float, float]:
    arr = np.asarray(x, float).reshape(-1)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise GeometryError(f"{name} = {np.asarray(x).tolist()!r}: not a finite 3D point")
    return tuple(float(v) for v in arr)


def segment_distance(p0, p1, q0, q1) -> float:
    """Shortest distance between the segments p0-p1 and q0-q1 (sampled + closed form clamp)."""
    p0, p1, q0, q1 = (np.asarray(v, float) for v in (p0, p1, q0, q1))
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    a, e, f = d1 @ d1, d2 @ d2, d2 @ r
    c, b = d1 @ r, d1 @ d2
    denom = a * e - b * b
    s = np.clip((b * f - c * e) / denom, 0.0, 1.0) if denom > 1e-14 * a * e else 0.0
    t = (b * s + f) / e
    if t < 0.0:
        t, s = 0.0, np.clip(-c / a, 0.0, 1.0)
    elif t > 1.0:
        t, s = 1.0, np.clip((b - c) / a, 0.0, 1.0)
    return float(np.linalg.norm((p0 + s * d1) - (q0 + t * d2)))


def leg_name(index: int) -> str:
    """Body name of leg `index` (0-based): "leg1", "leg2", ..."""
    return f"leg{index + 1}"


def leg_cylinders(base_points, platform_points, diameter: float) -> tuple[Cylinder, ...]:
    """Three leg cylinders B_i -> A_i, checked for zero length and for touching each other."""
    if not (isinstance(diameter, (int, float)) and math.isfinite(diameter) and diameter > 0):
        raise GeometryError(f"leg diameter = {diameter!r} m: must be a finite positive number")
    legs = []
    for i, (b, a) in enumerate(zip(base_points, platform_points)):
        b = _finite_point(f"B{i + 1}", b)
        a = _finite_point(f"A{i + 1}", a)
        length = float(np.linalg.norm(np.subtract(a, b)))
        if length < diameter / 2:
            raise GeometryError(f"leg {i + 1} length = {length:.6g} m: zero or shorter than the "
                                f"leg radius {diameter / 2:g} m (degenerate leg)")
        legs.append(Cylinder(leg_name(i), b, a, diameter / 2))
    for i in range(len(legs)):
        for j in range(i + 1, len(legs)):
            gap = segment_distance(legs[i].start, legs[i].end, legs[j].start, legs[j].end)
            if gap <= diameter:
                raise GeometryError(
                    f"legs {i + 1} and {j + 1}: axis distance {gap:.6g} m <= leg diameter "
                    f"{diameter:g} m (touching or intersecting legs)")
    return tuple(legs)


def platform_plate(manipulator, geometry) -> Plate:
    """The platform of a pose as a plate: thickness h centred on o with normal R[:, 2]."""
    normal = np.asarray(geometry.rotation, float)[:, 2]
    plate = Plate(
        name="platform",
        centre=_finite_point("platform centre o", geometry.platform_centre),
        normal=tuple(float(v) for v in normal / np.linalg.norm(normal)),
        thickness=float(manipulator.platform_thickness),
        shape=manipulator.platform_shape,
        radius=float(manipulator.platform_radius),
        corners=tuple(_finite_point(f"A{i + 1}", a)
                      for i, a in enumerate(geometry.platform_points)),
    )
    if plate.shape not in ("disk", "triangle"):
        raise GeometryError(f"platform_shape = {plate.shape!r}: expected disk or triangle")
    return plate


def pose_assembly(manipulator, geometry, elastic_platform: bool = False) -> Assembly:
    """The bodies of a manipulator (`analytical.params.Manipulator`) in one pose
    (`analytical.kinematics.PoseGeometry`); the plate only for the elastic-platform option."""
    legs = leg_cylinders(geometry.base_points, geometry.platform_points,
                         manipulator.leg_diameter)
    plate = platform_plate(manipulator, geometry) if elastic_platform else None
    return Assembly(legs, plate)
