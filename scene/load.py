"""Scene files (TOML): a manipulator, its poses and the fidelity asked, validated at the edge.

Millimetres, degrees and GPa are converted to SI exactly once, here. Every field is checked for
type and range, unknown keys are rejected, and every problem raises SceneError with one line
naming the key and the offending value.
"""
from __future__ import annotations

import difflib
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from analytical import plausibility
from analytical.architecture import ARCHITECTURE_KEYS, ARCHITECTURE_REQUIRED
from analytical.params import (
    Manipulator,
    Material,
    ModelOptions,
    Pose,
    check_manipulator,
)
from common.errors import InputError
from common.frf import Damping, Tool
from common.leg_profile import LegProfile
from common.paths import UnsafeName, distinct_stems
from common.payload import Payload
from common.settings import (
    MAX_LENGTH,
    MISSING,
    Setting,
    declared,
    nested,
    setting,
)
from common.stiffness import Stiffness
from fem_reference.convergence import sequence_problem
from fem_reference.model import FemError, FemOptions, FemRuntime, legs_for
from meshing.geometry import MIN_MESH_SIZE

from .cases import CaseSettings, HeightCalibration, check_paper_rows
from .errors import SceneError
from .fidelity import FidelitySettings


@dataclass(frozen=True)
class FemStudy:
    """The scene's plan for the FEM reference beyond one solve: its refinement sequence and
    the mesh of the CI regression baselines."""

    refinement: tuple[float, ...] = setting(
        kind=tuple, unit="mm", minimum=MIN_MESH_SIZE, maximum=MAX_LENGTH, min_length=3,
        doc="global element sizes of the Richardson refinement study, coarse to fine "
        "(strictly decreasing, at least three)")
    ci_mesh_size: float = setting(unit="mm", minimum=MIN_MESH_SIZE, maximum=MAX_LENGTH,
                                  doc="mesh size of the CI regression baselines")


@dataclass(frozen=True)
class SceneSettings:
    """The scene file's top-level keys."""

    name: str = setting("unnamed scene", kind=str, doc="title of the scene in reports")
    ci_cases: tuple[str, ...] = setting(None, kind=tuple, item=str, min_length=1,
                                        doc="cases of the CI profile and of the regression "
                                        "baselines (default: every case)")


@dataclass(frozen=True)
class ManipulatorNotes:
    """Free text beside the [manipulator] values."""

    platform_shape_reason: str = setting("", kind=str, paragraphs=True,
                                         doc="why this platform shape (when it is an assumption)")


# Defaults that follow the geometry: element sizes as fractions of the leg diameter d (measured
# on the paper's 100 mm legs: 0.32 d gives <= 0.16 % estimated error on f1..f6, the sequence
# 0.40 .. 0.20 d a <= 0.08 % reference; the rim zone 0.15 d).
MESH_SIZE_PER_DIAMETER = 0.32
REFINEMENT_PER_DIAMETER = (0.40, 0.32, 0.25, 0.20)
CI_MESH_SIZE_PER_DIAMETER = 0.40
RIM_ZONE_PER_DIAMETER = 0.15


GEOMETRY_DEFAULTS_TEXT = {
    "size": f"{MESH_SIZE_PER_DIAMETER:g} d",
    "refinement": "[" + ", ".join(f"{f:g} d" for f in REFINEMENT_PER_DIAMETER) + "]",
    "ci_mesh_size": f"{CI_MESH_SIZE_PER_DIAMETER:g} d",
    "rim_zone": f"{RIM_ZONE_PER_DIAMETER:g} d",
}  # d: the leg diameter


def geometry_defaults(manipulator: Manipulator) -> dict[str, object]:
    """SI defaults of the [fem] keys a scene leaves out, scaled with the leg diameter."""
    d = manipulator.leg_diameter
    return {"size": MESH_SIZE_PER_DIAMETER * d,
            "refinement": tuple(f * d for f in REFINEMENT_PER_DIAMETER),
            "ci_mesh_size": CI_MESH_SIZE_PER_DIAMETER * d,
            "rim_zone": RIM_ZONE_PER_DIAMETER * d}


@dataclass(frozen=True)
class Case:
    name: str
    description: str
    pose: Pose
    height_origin: Literal["calibrated", "scene"]
    paper_fea_hz: tuple[float, ...] | None = None
    paper_theory_hz: tuple[float, ...] | None = None
    paper_error_percent: tuple[float, ...] | None = None  # as printed in the paper


@dataclass(frozen=True)
class Scene:
    name: str
    path: str
    manipulator: Manipulator
    analytical: ModelOptions
    fem: FemOptions  # at the scene's default mesh size, for the compared modes
    fem_study: FemStudy
    fem_runtime: FemRuntime
    cases: dict[str, Case]
    calibrated_height: float | None = None  # m
    calibration_reason: str = ""
    platform_shape_reason: str = ""
    raw: dict = field(default_factory=dict, repr=False)
    ci_cases: tuple[str, ...] = ()  # the cases of the CI profile and its regression baselines
    fidelity: FidelitySettings = FidelitySettings()
    analytical_given: bool = False  # [analytical] in the file: an explicit override
    fem_size_given: bool = False  # [fem] mesh_size_mm in the file: an explicit override
    warnings: tuple[str, ...] = ()  # a machine that strains a shared idealisation
                                    # (analytical.plausibility): the output and report say so
    damping: Damping = Damping()  # [damping]: the tool's receptance (common.frf)
    tool: Tool = Tool()  # [tool]: where the force acts and the response is read
    dynamics_given: bool = False  # [damping] or [tool] in the file: the scene asks for the
                                  # dynamic compliance at the tool (its studies run)
    uncertainty: Any = None  # [uncertainty] (scene.uncertainty.Uncertainty): its studies run

    def case(self, name: str) -> Case:
        if name not in self.cases:
            raise SceneError(f"case {name!r} is not in scene {self.path} "
                             f"(it has: {', '.join(self.cases)})")
        return self.cases[name]


class _Table:
    """Typed access to one TOML table that remembers which keys were read."""

    def __init__(self, data: Any, where: str):
        if not isinstance(data, dict):
            raise SceneError(f"{where} = {_short(data)}: expected a table")
        self.data, self.where = data, where
        self.used: set[str] = set()

    def _get(self, key: str, default: Any) -> Any:
        self.used.add(key)
        if key not in self.data:
            if default is _REQUIRED:
                raise SceneError(f"{self.where}.{key}: missing")
            return default
        return self.data[key]

    def table(self, key: str, default: Any = None) -> "_Table":
        value = self._get(key, _REQUIRED if default is None else default)
        return _Table(value, f"{self.where}.{key}")

    def settings(self, cls, defaults: dict | None = None, **given):
        """Read every declared field of the dataclass `cls` (and of its nested settings) from
        this table, in the field's edge unit, converted to SI once. `defaults` replace the
        declared defaults (SI); `given` are values decided elsewhere (passed through)."""
        defaults = defaults or {}
        values = dict(given)
        for name, sub in nested(cls):
            if name not in values:
                values[name] = self.settings(sub, defaults)
        for name, spec, default in declared(cls):
            if name in values or not spec.scene:
                continue
            default = defaults.get(name, default)
            key = spec.scene_key(name)
            if key not in self.data:
                self.used.add(key)
                if default is MISSING or spec.scene_required:
                    raise SceneError(f"{self.where}.{key}: missing ({spec.doc}"
                                     f"{', in ' + spec.unit if spec.unit else ''})"
                                     + _found_instead(key, self.data, _scene_keys(cls)))
                values[name] = default
                continue
            values[name] = self.value(key, spec)
        try:
            return cls(**values)
        except (ValueError, FemError) as exc:
            raise SceneError(f"{self.where}: {exc}") from None

    def value(self, key: str, spec: Setting):
        """One declared value, checked in the edge unit and returned in SI."""
        raw = typed = self._get(key, _REQUIRED)
        if spec.kind is tuple:
            if not isinstance(raw, list) or not raw:
                raise SceneError(f"{self.where}.{key} = {_short(raw)}: expected a non-empty list")
            raw = tuple(raw)
        if spec.kind is float and isinstance(raw, int) and not isinstance(raw, bool):
            raw = float(raw)
        si: Any
        if spec.kind is tuple and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                      for v in raw):
            si = tuple(float(v) * spec.scale for v in raw)
        elif spec.kind is float and isinstance(raw, float):
            si = raw * spec.scale
        else:
            si = raw
        why = spec.problem(si, edge=True)
        if why is not None:
            raise SceneError(f"{self.where}.{key} = {_short(typed)}: {why}")
        return si

    def done(self) -> None:
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise SceneError(f"{self.where}: unknown key {_short(unknown[0])}"
                             + _did_you_mean(unknown[0], self.used)
                             + (f" (and {len(unknown) - 1} more)" if len(unknown) > 1 else ""))


def _did_you_mean(key: str, known) -> str:
    """'; did you mean youngs_modulus_gpa?' for the closest known key (case ignored), or ''."""
    by_lower = {k.lower(): k for k in sorted(known)}
    close = difflib.get_close_matches(str(key).lower(), list(by_lower), n=1, cutoff=0.6)
    return f"; did you mean {by_lower[close[0]]}?" if close else ""


def _scene_keys(cls) -> set[str]:
    """The scene keys of every declared field of `cls` and of its nested settings."""
    keys = {spec.scene_key(name) for name, spec, _ in declared(cls)}
    for _, sub in nested(cls):
        keys |= _scene_keys(sub)
    return keys


def _found_instead(key: str, data: dict, known=()) -> str:
    """'; found Youngs_Modulus_GPa: did you mean youngs_modulus_gpa?' for a misspelt key (a
    key of its own, `known`, is not one: slider_min_mm is no typo of slider_max_mm)."""
    typo = next((k for k in sorted(data, key=str)
                 if k not in known and _did_you_mean(k, [key])), None)
    return f"; found {_short(typo)}: did you mean {key}?" if typo is not None else ""


_REQUIRED = object()


def _short(value: Any, limit: int = 80) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."
MM = 1e-3
DEG = math.pi / 180.0


def _architecture_keys(man: _Table, where: str) -> dict:
    """Check the keys of the scene's architecture; values decided here (SI) for the fields
    the other architecture's keys would set."""
    spec = next(s for n, s, _ in declared(Manipulator) if n == "architecture")
    arch = man.value("architecture", spec) if "architecture" in man.data else "3-RPS"
    for other, keys in ARCHITECTURE_KEYS.items():
        given = [k for k in keys if k in man.data]
        if other != arch and given:
            raise SceneError(f"{where}.manipulator.{given[0]} = {_short(man.data[given[0]])} "
                             f"with architecture = {arch!r}: the key belongs to a {other}")
    for key in ARCHITECTURE_REQUIRED[arch]:
        if key not in man.data:
            name = key.rsplit("_", 1)[0]
            doc = next(s for n, s, _ in declared(Manipulator) if n == name).doc
            raise SceneError(f"{where}.manipulator.{key}: missing ({doc}, in mm; a {arch} "
                             "needs it)" + _found_instead(key, man.data,
                                                          _scene_keys(Manipulator)))
    if arch == "3-PRS":  # no actuator range of its own: its legs' one length (Manipulator)
        man.used.update(ARCHITECTURE_KEYS["3-RPS"])
        return {"actuator_min": 0.0, "actuator_max": 0.0}
    return {}


def read_toml(path: str | Path, what: str = "scene file") -> dict:
    """The tables of a TOML file; SceneError naming `what` and the path on any problem."""
    path = Path(path)
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SceneError(f"{what} {str(path)!r} does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"{what} {str(path)!r} cannot be read: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{what} {str(path)!r} is not valid TOML: {exc}") from None


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file; raise SceneError with one line on any problem."""
    return parse_scene(read_toml(path), str(path))


def parse_scene(raw: dict, where: str = "scene") -> Scene:
    top = _Table(raw, where)
    top_settings = top.settings(SceneSettings)
    name = top_settings.name
    if not name.strip():
        raise SceneError(f"{where}.name = {name!r}: empty; give the scene a title (or leave "
                         "the key out)")

    man = top.table("manipulator")
    mat = top.table("material")
    material = mat.settings(Material)
    mat.done()
    pay = top.table("payload", {})
    payload = pay.settings(Payload)
    pay.done()
    leg_t = top.table("leg", {})
    leg = leg_t.settings(LegProfile)
    leg_t.done()
    stiff_t = top.table("stiffness", {})
    stiffness = stiff_t.settings(Stiffness)
    stiff_t.done()
    parts = dict(material=material, payload=payload, leg=leg, stiffness=stiffness)
    if leg.stepped:  # the leg's diameter is its parts' (common.leg_profile)
        if "leg_diameter_mm" in man.data:
            raise SceneError(f"{where}.manipulator.leg_diameter_mm = "
                             f"{_short(man.data['leg_diameter_mm'])} with a [leg] housing and "
                             "rod: their diameters are the leg's; leave leg_diameter_mm out")
        parts["leg_diameter"] = leg.largest_diameter
    parts.update(_architecture_keys(man, where))
    manipulator = man.settings(Manipulator, **parts)
    shape_reason = man.settings(ManipulatorNotes).platform_shape_reason.strip()
    man.done()
    try:
        check_manipulator(manipulator)
    except ValueError as exc:
        raise SceneError(f"{where}: {exc}") from None

    damp = top.table("damping", {})
    if isinstance(damp.data, dict) and isinstance(damp.data.get("modal_ratio"), (int, float)):
        damp.data = {**damp.data, "modal_ratio": [damp.data["modal_ratio"]]}  # one for all
    damping = damp.settings(Damping)
    damp.done()
    if "damping" in raw:  # a table that damps nothing is refused, never read as the default
        damping.check_table(damp.data, f"{where}.damping")
    tool_t = top.table("tool", {})
    tool = tool_t.settings(Tool)
    tool_t.done()

    uncertainty = None
    if "uncertainty" in raw:  # after the machine: its inputs are around the scene's values
        from .uncertainty import parse as parse_uncertainty
        uncertainty = parse_uncertainty(top.table("uncertainty"), manipulator,
                                        f"{where}.uncertainty")

    fid = top.table("fidelity", {})
    fidelity = fid.settings(FidelitySettings)
    fid.done()

    fem_t = top.table("fem", {})
    fem_size_given = "mesh_size_mm" in fem_t.data
    defaults = geometry_defaults(manipulator)
    given = {"modes": fidelity.modes}
    legs = legs_for(fem_t.data.get("platform"), fem_t.data.get("legs"))
    if legs is not None and "legs" not in fem_t.data:
        given["legs"] = legs
    fem = fem_t.settings(FemOptions, defaults, **given)
    if fem.platform == "elastic" and manipulator.payload.mass > 0.0:
        raise SceneError(f"{where}.fem.platform = 'elastic' with [payload] mass_kg = "
                         f"{manipulator.payload.mass:g}: how the payload's mass spreads over an "
                         "elastic plate is not modelled (use a rigid platform)")
    study = fem_t.settings(FemStudy, defaults)
    why = sequence_problem(study.refinement)
    if why is not None:
        raise SceneError(f"{where}.fem.refinement_mm = {[r / MM for r in study.refinement]!r}: "
                         f"{why}")
    runtime = fem_t.settings(FemRuntime, defaults)
    fem_t.done()

    analytical_given = "analytical" in raw
    ana = top.table("analytical", {})
    # solid joint ends model the FEM's joint faces unless the scene says otherwise
    analytical = ana.settings(ModelOptions, {"joint_coupling": fem.coupling},
                              modes=fidelity.modes)
    ana.done()

    calibrated, reason = None, ""
    if "calibration" in raw:
        cal = top.table("calibration")
        h = cal.table("height")
        cal_settings = h.settings(HeightCalibration)
        calibrated, reason = cal_settings.value, cal_settings.reason.strip()
        if not reason:
            raise SceneError(f"{where}.calibration.height.reason: a calibrated value needs "
                             "its reason")
        h.done()
        cal.done()

    cases_t = top.table("cases")
    try:  # case names become file names: checked by the one rule before any case is read
        distinct_stems(cases_t.data, "case name")
    except UnsafeName as exc:
        raise SceneError(f"{where}: {exc}") from None
    cases = {}
    for case_name in cases_t.data:
        c = cases_t.table(case_name)
        if c.data.get("height_mm") == "calibrated":
            if calibrated is None:
                raise SceneError(f"{where}.cases.{case_name}.height_mm = 'calibrated' but the "
                                 "scene has no [calibration.height]")
            c.used.add("height_mm")
            spec = c.settings(CaseSettings, height=calibrated)
            origin: Literal["calibrated", "scene"] = "calibrated"
        else:
            spec = c.settings(CaseSettings)
            origin = "scene"
        try:
            check_paper_rows(spec, f"{where}.cases.{case_name}", fidelity.modes)
        except InputError as exc:
            raise SceneError(str(exc)) from None
        cases[case_name] = Case(
            name=case_name,
            description=(spec.description or case_name).strip(),
            pose=Pose(height=spec.height, azimuth=spec.azimuth, tilt=spec.tilt),
            height_origin=origin,
            paper_fea_hz=spec.paper_fea_hz,
            paper_theory_hz=spec.paper_theory_hz,
            paper_error_percent=spec.paper_error_percent,
        )
        c.done()
    cases_t.done()
    if not cases:
        raise SceneError(f"{where}.cases: the scene defines no case")
    ci_cases = top_settings.ci_cases or tuple(cases)
    if any(c not in cases for c in ci_cases):
        raise SceneError(f"{where}.ci_cases = {_short(list(ci_cases))}: every name must be a "
                         f"case of the scene (it has: {', '.join(cases)})")
    top.done()
    try:  # the machine as a whole, before any work (the rules of analytical.plausibility)
        warnings = plausibility.check(manipulator, [(n, c.pose) for n, c in cases.items()])
        if "tool" in raw:
            plausibility.check_tool(manipulator, tool.point)
    except InputError as exc:
        raise SceneError(f"{where}: {exc}") from None
    return Scene(name, where, manipulator, analytical, fem, study, runtime, cases, calibrated,
                 reason, shape_reason, raw, tuple(ci_cases), fidelity, analytical_given,
                 fem_size_given, warnings, damping, tool, "damping" in raw or "tool" in raw,
                 uncertainty)
