"""Scene files (TOML): a manipulator, its poses and the fidelity asked, validated at the edge.

Millimetres, degrees and GPa are converted to SI exactly once, here. Every field is checked for
type and range, unknown keys are rejected, and every problem raises SceneError with one line
naming the key and the offending value.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from analytical import plausibility
from analytical.architectures import ARCHITECTURES, NAMES
from analytical.params import (
    Manipulator,
    Material,
    ModelOptions,
    Pose,
    check_manipulator,
)
from chatter.cutting import Cutting
from common.errors import InputError
from common.frf import Damping, Tool
from common.leg_profile import LegProfile
from common.paths import UnsafeName, distinct_stems
from common.payload import Payload
from common.settings import (
    MAX_LENGTH,
    declared,
    setting,
)
from common.stiffness import Stiffness
from fem_reference.convergence import sequence_problem
from fem_reference.model import FemOptions, FemRuntime, legs_for
from meshing.geometry import MIN_MESH_SIZE

from .cases import CaseSettings, HeightCalibration, check_paper_rows
from .errors import SceneError
from .fidelity import FidelitySettings
from .toml_table import Table, found_instead, read_toml, scene_keys, short


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
    cutting: Cutting | None = None  # [cutting]: the milling cut whose stability lobes run

    def case(self, name: str) -> Case:
        if name not in self.cases:
            raise SceneError(f"case {name!r} is not in scene {self.path} "
                             f"(it has: {', '.join(self.cases)})")
        return self.cases[name]


MM = 1e-3
DEG = math.pi / 180.0


def _architecture_keys(man: Table, where: str) -> dict:
    """Check the keys of the scene's architecture; values decided here (SI) for the fields
    the other architecture's keys would set."""
    spec = next(s for n, s, _ in declared(Manipulator) if n == "architecture")
    name = man.value("architecture", spec) if "architecture" in man.data else NAMES[0]
    arch = ARCHITECTURES[name]
    for other in ARCHITECTURES.values():
        given = [k for k in other.keys if k in man.data]
        if other is not arch and given:
            raise SceneError(f"{where}.manipulator.{given[0]} = {short(man.data[given[0]])} "
                             f"with architecture = {name!r}: the key belongs to a {other.name}")
    for key in arch.required:
        if key not in man.data:
            field_name = key.rsplit("_", 1)[0]
            doc = next(s for n, s, _ in declared(Manipulator) if n == field_name).doc
            raise SceneError(f"{where}.manipulator.{key}: missing ({doc}, in mm; a {name} "
                             "needs it)" + found_instead(key, man.data,
                                                          scene_keys(Manipulator)))
    return dict(arch.fills)


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file; raise SceneError with one line on any problem."""
    return parse_scene(read_toml(path), str(path))


def parse_scene(raw: dict, where: str = "scene") -> Scene:
    """A scene's tables read in the order they depend on one another (the machine, then what
    acts on it, the fidelity, the FEM, the model, the cases), then the machine checked whole;
    SceneError with one line naming the first problem."""
    top = Table(raw, where)
    top_settings = top.settings(SceneSettings)
    name = top_settings.name
    if not name.strip():
        raise SceneError(f"{where}.name = {name!r}: empty; give the scene a title (or leave "
                         "the key out)")
    manipulator, shape_reason = _machine(top, where)
    damping = _read(top, "damping", Damping, _one_ratio_for_all)
    if "damping" in raw:  # a table that damps nothing is refused, never read as the default
        damping.check_table(raw["damping"], f"{where}.damping")
    tool = _read(top, "tool", Tool)
    cutting = _read(top, "cutting", Cutting) if "cutting" in raw else None
    uncertainty = None
    if "uncertainty" in raw:  # after the machine: its inputs are around the scene's values
        from .uncertainty import parse as parse_uncertainty
        uncertainty = parse_uncertainty(top.table("uncertainty"), manipulator,
                                        f"{where}.uncertainty")
    fidelity = _read(top, "fidelity", FidelitySettings)
    fem, study, runtime = _fem(top, manipulator, fidelity, where)
    ana = top.table("analytical", {})
    # solid joint ends model the FEM's joint faces unless the scene says otherwise
    analytical = ana.settings(ModelOptions, {"joint_coupling": fem.coupling},
                              modes=fidelity.modes)
    ana.done()
    calibrated, reason = _calibration(top, raw, where)
    cases = _cases(top, calibrated, fidelity, where)
    ci_cases = top_settings.ci_cases or tuple(cases)
    if any(c not in cases for c in ci_cases):
        raise SceneError(f"{where}.ci_cases = {short(list(ci_cases))}: every name must be a "
                         f"case of the scene (it has: {', '.join(cases)})")
    top.done()
    try:  # the machine as a whole, before any work (the rules of analytical.plausibility)
        warnings = plausibility.check(manipulator, [(n, c.pose) for n, c in cases.items()])
        if "tool" in raw:
            warnings += plausibility.check_tool(manipulator, tool.point,
                                                [(n, c.pose) for n, c in cases.items()])
    except InputError as exc:
        raise SceneError(f"{where}: {exc}") from None
    return Scene(name, where, manipulator, analytical, fem, study, runtime, cases, calibrated,
                 reason, shape_reason, raw, tuple(ci_cases), fidelity, "analytical" in raw,
                 "mesh_size_mm" in raw.get("fem", {}), warnings, damping, tool,
                 "damping" in raw or "tool" in raw, uncertainty, cutting)


def _read(top: Table, key: str, cls, prepare=None, required: bool = False):
    """A table of one declared dataclass, optional unless `required` (`prepare` may rewrite
    its raw data first)."""
    t = top.table(key) if required else top.table(key, {})
    if prepare is not None:
        prepare(t)
    value = t.settings(cls)
    t.done()
    return value


def _one_ratio_for_all(damp: Table) -> None:
    """[damping] modal_ratio = 0.03: one ratio for every mode (the declared list of one)."""
    if isinstance(damp.data, dict) and isinstance(damp.data.get("modal_ratio"), (int, float)):
        damp.data = {**damp.data, "modal_ratio": [damp.data["modal_ratio"]]}


def _machine(top: Table, where: str) -> tuple[Manipulator, str]:
    """[manipulator] with its [material], [payload], [leg] and [stiffness], checked as one
    machine; and the reason given for the platform's shape."""
    man = top.table("manipulator")
    parts: dict[str, Any] = {
        "material": _read(top, "material", Material, required=True),
        "payload": _read(top, "payload", Payload), "leg": _read(top, "leg", LegProfile),
        "stiffness": _read(top, "stiffness", Stiffness)}
    leg = parts["leg"]
    if leg.stepped:  # the leg's diameter is its parts' (common.leg_profile)
        if "leg_diameter_mm" in man.data:
            raise SceneError(f"{where}.manipulator.leg_diameter_mm = "
                             f"{short(man.data['leg_diameter_mm'])} with a [leg] housing and "
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
    return manipulator, shape_reason


def _fem(top: Table, manipulator: Manipulator, fidelity: FidelitySettings,
         where: str) -> tuple[FemOptions, FemStudy, FemRuntime]:
    """[fem]: the solve's options at the scene's size, its refinement study, its runtime."""
    fem_t = top.table("fem", {})
    defaults = geometry_defaults(manipulator)
    given: dict[str, Any] = {"modes": fidelity.modes}
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
    return fem, study, runtime


def _calibration(top: Table, raw: dict, where: str) -> tuple[float | None, str]:
    """[calibration.height]: a fitted height and its reason, or (None, "")."""
    if "calibration" not in raw:
        return None, ""
    cal = top.table("calibration")
    h = cal.table("height")
    cal_settings = h.settings(HeightCalibration)
    calibrated, reason = cal_settings.value, cal_settings.reason.strip()
    if not reason:
        raise SceneError(f"{where}.calibration.height.reason: a calibrated value needs its "
                         "reason")
    h.done()
    cal.done()
    return calibrated, reason


def _cases(top: Table, calibrated: float | None, fidelity: FidelitySettings,
           where: str) -> dict[str, Case]:
    """[cases]: each named pose with its paper rows; case names become file names, so they
    are checked by the one rule before any case is read."""
    cases_t = top.table("cases")
    try:
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
            name=case_name, description=(spec.description or case_name).strip(),
            pose=Pose(height=spec.height, azimuth=spec.azimuth, tilt=spec.tilt),
            height_origin=origin, paper_fea_hz=spec.paper_fea_hz,
            paper_theory_hz=spec.paper_theory_hz, paper_error_percent=spec.paper_error_percent)
        c.done()
    cases_t.done()
    if not cases:
        raise SceneError(f"{where}.cases: the scene defines no case")
    return cases
