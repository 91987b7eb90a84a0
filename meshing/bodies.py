"""The solid bodies of one pose, as plain geometry: the legs' parts and the platform plate.

Pure numpy, no gmsh: what `meshing.geometry` turns into OpenCASCADE solids, and what the mesh
cache hashes. A leg is the sequence of its profile's parts (`common.leg_profile`, base joint
first): the paper's uniform leg is one solid circular cylinder of diameter d from its base joint
centre B_i (base face) to its platform joint centre A_i (top face), named "leg<i>" as always; a
stepped leg is a housing and a rod ("leg<i>_housing", "leg<i>_rod"), each a solid cylinder or a
tube (`Cylinder.inner_radius` > 0), each with its own two end faces. The platform is a plate of
thickness h centred on o with normal R[:, 2] (a disk of radius r2, or the triangle A1A2A3). The
bodies touch only at the joints and at a leg's junction: they are meshed separately (no boolean
fusion) and joined by the FEM's multipoint constraints. SI units throughout.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import cast

import numpy as np

from common.errors import InputError

Point3 = tuple[float, float, float]  # a point or a direction in base coordinates, m


class GeometryError(InputError):
    """The bodies cannot be built: degenerate, touching or intersecting legs, bad numbers."""


@dataclass(frozen=True)
class Cylinder:
    """A solid circular cylinder, or a tube when `inner_radius` > 0 (its end faces are then
    annuli: both their circles are rims)."""

    name: str  # body name, e.g. "leg1", "leg1_housing"
    start: tuple[float, float, float]  # centre of the first end face (B_i side), m
    end: tuple[float, float, float]  # centre of the second end face (A_i side), m
    radius: float  # outer radius, m
    inner_radius: float = 0.0  # bore radius, m (0: solid)

    def __post_init__(self):
        r, ri = self.radius, self.inner_radius
        if ri != 0.0 and not (math.isfinite(ri) and 0.0 < ri < r):
            raise GeometryError(f"{self.name}: inner radius {ri!r} m, expected 0 <= inner < "
                                f"outer radius {r!r} m")

    @property
    def hollow(self) -> bool:
        return self.inner_radius > 0.0

    @property
    def wall(self) -> float:
        """Radial thickness of the material: the radius of a solid cylinder, R - r of a tube."""
        return self.radius - self.inner_radius

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
        return math.pi * (self.radius**2 - self.inner_radius**2) * self.length

    @property
    def area(self) -> float:
        if not self.hollow:
            return 2 * math.pi * self.radius * (self.radius + self.length)
        r, ri = self.radius, self.inner_radius
        return 2 * math.pi * ((r**2 - ri**2) + (r + ri) * self.length)

    def canonical(self, rounded) -> dict:
        """The JSON-ready description the mesh cache hashes (a solid one's as before tubes
        existed, so cached meshes of uniform legs stay valid)."""
        out = {"name": self.name, "start": rounded(self.start), "end": rounded(self.end),
               "radius": rounded([self.radius])[0]}
        if self.hollow:
            out["inner_radius"] = rounded([self.inner_radius])[0]
        return out


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
    """The bodies of one pose, in base coordinates. `cylinders` are the legs' parts, leg by leg
    and base joint first; `parts[i]` the indices of leg i's parts in `cylinders` (default: one
    part per leg, `cylinders[i]` is leg i + 1)."""

    cylinders: tuple[Cylinder, ...]
    plate: Plate | None = None
    parts: tuple[tuple[int, ...], ...] | None = None

    @property
    def legs(self) -> tuple[tuple[Cylinder, ...], ...]:
        """Per leg, its parts (solids), base joint first."""
        if self.parts is None:
            return tuple((c,) for c in self.cylinders)
        return tuple(tuple(self.cylinders[k] for k in leg) for leg in self.parts)

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
        out: dict[str, object] = {"cylinders": [c.canonical(r) for c in self.cylinders]}
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
    return cast(Point3, tuple(float(v) for v in arr))  # three values: shape checked above


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


def part_name(index: int, part: str) -> str:
    """Body name of a part of leg `index` (0-based): "leg1" for a uniform leg's only part,
    "leg1_housing", "leg1_rod" for a stepped one's."""
    return leg_name(index) if part == "leg" else f"{leg_name(index)}_{part}"


def leg_parts(legs: tuple[Cylinder, ...], profile) -> Assembly:
    """The legs (checked cylinders B_i -> A_i of the largest diameter, `leg_cylinders`) cut
    into their profile's parts: `profile(length)` -> `common.leg_profile.LegPart`s, base joint
    first (the manipulator's `leg_parts`). A leg of one part named "leg" stays the cylinder it
    was (a solid of the leg's diameter), so uniform legs mesh as before."""
    cylinders: list[Cylinder] = []
    parts: list[tuple[int, ...]] = []
    for i, leg in enumerate(legs):
        b, a = np.asarray(leg.start, float), np.asarray(leg.end, float)
        length = float(np.linalg.norm(a - b))
        pieces = profile(length)
        if len(pieces) == 1 and pieces[0].name == "leg" and not pieces[0].inner:
            parts.append((len(cylinders),))
            cylinders.append(leg if 2 * leg.radius == float(pieces[0].outer)
                             else replace(leg, radius=0.5 * float(pieces[0].outer)))
            continue
        e = (a - b) / length
        own = []
        for k, p in enumerate(pieces):
            start = b if k == 0 else b + float(p.start) * e
            end = a if k == len(pieces) - 1 else b + float(p.end) * e
            own.append(len(cylinders))
            cylinders.append(Cylinder(part_name(i, p.name), cast(Point3, tuple(map(float, start))),
                                      cast(Point3, tuple(map(float, end))), 0.5 * float(p.outer),
                                      0.5 * float(p.inner)))
        parts.append(tuple(own))
    return Assembly(tuple(cylinders), None, tuple(parts))


def platform_plate(manipulator, geometry) -> Plate:
    """The platform of a pose as a plate: thickness h centred on o with normal R[:, 2]."""
    normal = np.asarray(geometry.rotation, float)[:, 2]
    plate = Plate(
        name="platform",
        centre=_finite_point("platform centre o", geometry.platform_centre),
        normal=cast(Point3, tuple(float(v) for v in normal / np.linalg.norm(normal))),
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
    (`analytical.kinematics.PoseGeometry`); the plate only for the elastic-platform option.
    The legs are checked for touching with the largest outer diameter of their profile (the
    manipulator's `leg_diameter`), then cut into their parts (`leg_parts`)."""
    legs = leg_cylinders(geometry.base_points, geometry.platform_points,
                         manipulator.leg_diameter)
    plate = platform_plate(manipulator, geometry) if elastic_platform else None
    profile = getattr(manipulator, "leg_parts", None)
    if profile is None:  # a manipulator without a leg profile: uniform solid legs
        return Assembly(legs, plate)
    cut = leg_parts(legs, profile)
    if cut.parts == tuple((i,) for i in range(len(legs))):
        return Assembly(cut.cylinders, plate)  # uniform legs: as before profiles existed
    return Assembly(cut.cylinders, plate, cut.parts)
