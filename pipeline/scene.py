"""Scene files (TOML): a manipulator, its poses and the fidelity asked, validated at the edge.

Millimetres, degrees and GPa are converted to SI exactly once, here. Every field is checked for
type and range, unknown keys are rejected, and every problem raises SceneError with one line
naming the key and the offending value.
"""
from __future__ import annotations

from dataclasses import dataclass, field
import math
from pathlib import Path
import tomllib
from typing import Any

from analytical.params import (BEAM_THEORIES, PLATFORM_INERTIAS, PLATFORM_SHAPES, Manipulator,
                               Material, ModelOptions, Pose, check_manipulator)

FEM_PLATFORMS = ("rigid", "elastic")
FEM_COUPLINGS = ("rigid", "distributing")


class SceneError(ValueError):
    """The scene file is unreadable or holds an invalid value."""


@dataclass(frozen=True)
class FemSettings:
    mesh_size: float  # m
    refinement: tuple[float, ...]  # m, coarse to fine
    ci_mesh_size: float  # m, the mesh of the CI regression baselines
    platform: str = "rigid"
    coupling: str = "rigid"
    max_dofs: int = 600_000
    rim_factor: float = 0.5  # element size near joint-face rims, as a fraction of mesh_size
    rim_zone: float = 0.015  # m, distance over which the size grows back to mesh_size


@dataclass(frozen=True)
class Case:
    name: str
    description: str
    pose: Pose
    height_origin: str  # "calibrated" or "scene"
    paper_fea_hz: tuple[float, ...] | None = None
    paper_theory_hz: tuple[float, ...] | None = None
    paper_error_percent: tuple[float, ...] | None = None  # as printed in the paper


@dataclass(frozen=True)
class Scene:
    name: str
    path: str
    manipulator: Manipulator
    analytical: ModelOptions
    fem: FemSettings
    cases: dict[str, Case]
    calibrated_height: float | None = None  # m
    calibration_reason: str = ""
    platform_shape_reason: str = ""
    raw: dict = field(default_factory=dict, repr=False)

    def case(self, name: str) -> Case:
        if name not in self.cases:
            raise SceneError(f"case {name!r} is not in scene {self.path} "
                             f"(it has: {', '.join(self.cases)})")
        return self.cases[name]


class _Table:
    """Typed access to one TOML table that remembers which keys were read."""

    def __init__(self, data: Any, where: str):
        if not isinstance(data, dict):
            raise SceneError(f"{where}: expected a table, got {data!r}")
        self.data, self.where, self.used = data, where, set()

    def _get(self, key: str, default: Any) -> Any:
        self.used.add(key)
        if key not in self.data:
            if default is _REQUIRED:
                raise SceneError(f"{self.where}.{key}: missing")
            return default
        return self.data[key]

    def number(self, key: str, default: Any = None, *, positive: bool = True,
               minimum: float | None = None, maximum: float | None = None) -> float:
        default = _REQUIRED if default is None else default
        value = self._get(key, default)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise SceneError(f"{self.where}.{key} = {value!r}: expected a finite number")
        if positive and value <= 0:
            raise SceneError(f"{self.where}.{key} = {value!r}: must be positive")
        if minimum is not None and value < minimum:
            raise SceneError(f"{self.where}.{key} = {value!r}: must be >= {minimum}")
        if maximum is not None and value > maximum:
            raise SceneError(f"{self.where}.{key} = {value!r}: must be <= {maximum}")
        return float(value)

    def integer(self, key: str, default: Any = None, *, minimum: int = 1) -> int:
        value = self._get(key, _REQUIRED if default is None else default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise SceneError(f"{self.where}.{key} = {value!r}: expected an integer")
        if value < minimum:
            raise SceneError(f"{self.where}.{key} = {value!r}: must be >= {minimum}")
        return value

    def choice(self, key: str, options: tuple[str, ...], default: Any = None) -> str:
        value = self._get(key, _REQUIRED if default is None else default)
        if value not in options:
            raise SceneError(f"{self.where}.{key} = {value!r}: expected one of "
                             f"{', '.join(options)}")
        return value

    def text(self, key: str, default: str | None = None) -> str:
        value = self._get(key, _REQUIRED if default is None else default)
        if not isinstance(value, str):
            raise SceneError(f"{self.where}.{key} = {value!r}: expected a string")
        return value.strip()

    def numbers(self, key: str, default: Any = None, *, length: int | None = None,
                positive: bool = True) -> tuple[float, ...] | None:
        value = self._get(key, _REQUIRED if default is None else default)
        if value is _ABSENT:
            return None
        if not isinstance(value, list) or not value or any(
                isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v)
                for v in value):
            raise SceneError(f"{self.where}.{key} = {value!r}: expected a list of numbers")
        if length is not None and len(value) != length:
            raise SceneError(f"{self.where}.{key} = {value!r}: expected {length} numbers")
        if positive and any(v <= 0 for v in value):
            raise SceneError(f"{self.where}.{key} = {value!r}: every value must be positive")
        return tuple(float(v) for v in value)

    def table(self, key: str, default: Any = None) -> "_Table":
        value = self._get(key, _REQUIRED if default is None else default)
        return _Table(value, f"{self.where}.{key}")

    def done(self) -> None:
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise SceneError(f"{self.where}: unknown key {unknown[0]!r}"
                             + (f" (and {len(unknown) - 1} more)" if len(unknown) > 1 else ""))


_REQUIRED = object()
_ABSENT = object()
MM = 1e-3
DEG = math.pi / 180.0


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file; raise SceneError with one line on any problem."""
    path = Path(path)
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SceneError(f"scene file {str(path)!r} does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"scene file {str(path)!r} cannot be read: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"scene file {str(path)!r} is not valid TOML: {exc}") from None
    return parse_scene(raw, str(path))


def parse_scene(raw: dict, where: str = "scene") -> Scene:
    top = _Table(raw, where)
    name = top.text("name", "unnamed scene")

    man = top.table("manipulator")
    mat = top.table("material")
    material = Material(
        youngs_modulus=mat.number("youngs_modulus_gpa") * 1e9,
        shear_modulus=mat.number("shear_modulus_gpa") * 1e9,
        density=mat.number("density_kg_m3"),
    )
    mat.done()
    angles = man.numbers("leg_angles_deg", [0.0, 120.0, 240.0], length=3, positive=False)
    manipulator = Manipulator(
        base_radius=man.number("base_radius_mm") * MM,
        platform_radius=man.number("platform_radius_mm") * MM,
        leg_diameter=man.number("leg_diameter_mm") * MM,
        platform_thickness=man.number("platform_thickness_mm") * MM,
        material=material,
        leg_angles=tuple(a * DEG for a in angles),
        platform_shape=man.choice("platform_shape", PLATFORM_SHAPES, "disk"),
        actuator_min=man.number("actuator_min_mm") * MM,
        actuator_max=man.number("actuator_max_mm") * MM,
        s_joint_max=man.number("s_joint_max_deg", maximum=90.0) * DEG,
        r_joint_max=man.number("r_joint_max_deg", maximum=90.0) * DEG,
    )
    shape_reason = man.text("platform_shape_reason", "")
    man.done()
    try:
        check_manipulator(manipulator)
    except ValueError as exc:
        raise SceneError(f"{where}: {exc}") from None
    if manipulator.leg_diameter >= manipulator.platform_radius * math.sqrt(3.0):
        raise SceneError(f"{where}: manipulator.leg_diameter_mm = "
                         f"{manipulator.leg_diameter / MM:g}: legs would touch at the platform")

    ana = top.table("analytical", {})
    try:
        analytical = ModelOptions(
            elements=ana.integer("elements", 3),
            beam=ana.choice("beam", BEAM_THEORIES, "euler-bernoulli"),
            platform_inertia=ana.choice("platform_inertia", PLATFORM_INERTIAS, "plate"),
            modes=ana.integer("modes", 6),
        )
    except ValueError as exc:
        raise SceneError(f"{where}: analytical: {exc}") from None
    ana.done()

    fem_t = top.table("fem", {})
    size = fem_t.number("mesh_size_mm", 32.0) * MM
    refinement = fem_t.numbers("refinement_mm", [40.0, 32.0, 25.0, 20.0])
    if len(refinement) < 3:
        raise SceneError(f"{where}.fem.refinement_mm = {list(refinement)!r}: "
                         "Richardson extrapolation needs at least three sizes")
    if list(refinement) != sorted(refinement, reverse=True) or len(set(refinement)) != len(refinement):
        raise SceneError(f"{where}.fem.refinement_mm = {list(refinement)!r}: "
                         "sizes must strictly decrease")
    fem = FemSettings(
        mesh_size=size,
        refinement=tuple(r * MM for r in refinement),
        ci_mesh_size=fem_t.number("ci_mesh_size_mm", 40.0) * MM,
        platform=fem_t.choice("platform", FEM_PLATFORMS, "rigid"),
        coupling=fem_t.choice("coupling", FEM_COUPLINGS, "rigid"),
        max_dofs=fem_t.integer("max_dofs", 600_000, minimum=100),
        rim_factor=fem_t.number("rim_factor", 0.5, maximum=1.0),
        rim_zone=fem_t.number("rim_zone_mm", 15.0, positive=False, minimum=0.0) * MM,
    )
    fem_t.done()

    calibrated, reason = None, ""
    if "calibration" in raw:
        cal = top.table("calibration")
        h = cal.table("height")
        calibrated = h.number("value_mm") * MM
        reason = h.text("reason")
        if not reason:
            raise SceneError(f"{where}.calibration.height.reason: a calibrated value needs "
                             "its reason")
        h.done()
        cal.done()

    cases_t = top.table("cases")
    cases = {}
    for case_name in cases_t.data:
        c = cases_t.table(case_name)
        height_value = c._get("height_mm", _REQUIRED)
        if height_value == "calibrated":
            if calibrated is None:
                raise SceneError(f"{where}.cases.{case_name}.height_mm = 'calibrated' but the "
                                 "scene has no [calibration.height]")
            height, origin = calibrated, "calibrated"
        else:
            c.used.discard("height_mm")
            height, origin = c.number("height_mm") * MM, "scene"
        pose = Pose(height=height,
                    azimuth=c.number("azimuth_deg", 0.0, positive=False) * DEG,
                    tilt=c.number("tilt_deg", 0.0, positive=False,
                                  minimum=-90.0, maximum=90.0) * DEG)
        cases[case_name] = Case(
            name=case_name,
            description=c.text("description", case_name),
            pose=pose,
            height_origin=origin,
            paper_fea_hz=c.numbers("paper_fea_hz", _ABSENT),
            paper_theory_hz=c.numbers("paper_theory_hz", _ABSENT),
            paper_error_percent=c.numbers("paper_error_percent", _ABSENT),
        )
        c.done()
    cases_t.done()
    if not cases:
        raise SceneError(f"{where}.cases: the scene defines no case")
    top.done()
    return Scene(name, where, manipulator, analytical, fem, cases, calibrated, reason,
                 shape_reason, raw)
