"""docs/scenes.md, generated from the declarations that validate scene files.

Every key, its type, unit, default, admitted values and meaning come from the `setting(...)`
declarations of the dataclasses the scene reader fills (`scene.parse_scene`), so the
page cannot disagree with the reader; `tests/test_scene_docs.py` fails when the committed page
is stale (`python -m rps scene-docs` rewrites it).
"""
from __future__ import annotations

from dataclasses import MISSING
from pathlib import Path

from analytical.architectures import ARCHITECTURES
from analytical.params import Manipulator, Material, ModelOptions
from analytical.plausibility import RULES
from chatter.cutting import Cutting
from common.frf import Damping, Tool
from common.leg_profile import LegProfile
from common.paths import MAX_LENGTH
from common.payload import Payload
from common.settings import Setting, declared
from common.stiffness import Stiffness
from fem_reference.model import FemOptions, FemRuntime
from meshing.geometry import MeshSettings

from .cases import PAPER_ROWS_RULE, CaseSettings, HeightCalibration
from .fidelity import FidelitySettings
from .load import GEOMETRY_DEFAULTS_TEXT, FemStudy, ManipulatorNotes, SceneSettings
from .uncertainty import InputSpec, UncertaintySettings

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "scenes.md"

TABLES = (
    ("top level", "The scene's own keys.", (SceneSettings,)),
    ("[manipulator]", "Geometry, joints and limits of the machine (paper Section 2, Eq. 25). "
     'With architecture = "3-PRS" a slider on a rail from each B_i carries the revolute joint '
     "and the legs have one length (analytical/architecture.py): its keys are rail_angle_deg, "
     "leg_length_mm, slider_min_mm and slider_max_mm in place of actuator_min_mm and "
     "actuator_max_mm, the R-joint angle is measured from the rail, and the slider is locked, "
     "rigid and of no mass. A key of the other architecture is refused.",
     (Manipulator, ManipulatorNotes)),
    ("[material]", "One isotropic material for legs and platform.", (Material,)),
    ("[payload]", "A rigid body fixed to the platform (a tool, a spindle, a workpiece), carried "
     "identically by both models (common/payload.py). Leave the table out for none.",
     (Payload,)),
    ("[leg]", "Every leg as a linear actuator: a housing tube of fixed length from the base joint "
     "and a rod taking the rest of the pose's length, each solid or hollow (common/"
     "leg_profile.py). Both models build their legs from this one profile. Leave the table out "
     "for the paper's uniform solid leg of leg_diameter_mm; with it, leave leg_diameter_mm out. "
     "A 3-RPS only (a 3-PRS's legs are links).",
     (LegProfile,)),
    ("[stiffness]", "Joint bearings and the drive as linear springs, carried identically by both "
     "models (common/stiffness.py): a joint spring joins the body to the leg end's reference "
     "point, the drive spring joins the housing's end face to the rod's (a 3-PRS: the slider to "
     "its rail, along the rail). 0 (the default) is rigid.", (Stiffness,)),
    ("[damping]", "How the modes are damped, for the dynamic compliance at the tool (`rps frf`, "
     "the run's tool-point studies; common/frf.py): proportional viscous damping, a ratio per "
     "mode or Rayleigh's C = alpha M + beta K. modal_ratio may be one number (every mode) or a "
     "list. With [damping] or [tool] in the scene, a validation also maps the least dynamic "
     "stiffness at the tool over the workspace and checks both models' receptance against the "
     "solid's direct frequency response at every case.", (Damping,)),
    ("[tool]", "Where the force acts and the response is read: a point fixed to the rigid "
     "platform.", (Tool,)),
    ("[cutting]", "A milling cut, for its stability lobes (`rps lobes`, chatter/): the tool "
     "axis is the platform normal, x the feed in the platform's plane, y = z x x; the cutter "
     "turns clockwise seen from +z, a tooth's angle measured from +y (Altintas' convention). "
     "The diagram's speeds: spindle_rpm = [low, high] at `speeds` points, or exactly "
     "spindle_rpm_list. The lobes take the tool point's modes ([tool], [damping]) in the "
     "cut's plane; the residual flexibility of the modes left out is not in them. Without "
     "[cutting] nothing of it runs.", (Cutting,)),
    ("[uncertainty]", "The scene's inputs known within a tolerance, for the propagation of input "
     "uncertainty through the fast model (`rps uncertainty`; with the table, a validation adds "
     "the uncertainty of every case's frequencies, the V&V 20 table and the 95 % band along "
     "the workspace map's worst path; scene/uncertainty.py). Its own keys are below; every "
     "other key is a scene number, quoted, as \"table.key\" (one of [manipulator], "
     "[material], [leg], [stiffness], [payload]; the same addresses as `rps design` and "
     "`rps identify`), set to an inline table of the keys in [uncertainty.\"table.key\"].",
     (UncertaintySettings,)),
    ("[uncertainty.\"table.key\"]", "One uncertain input, e.g. `\"material.youngs_modulus_gpa\" "
     "= { distribution = \"normal\", cv_percent = 2.0, source = \"EN 10025: ...\" }`. A normal "
     "or lognormal input has the scene's value as its mean; a uniform one spans the scene's "
     "value plus_minus a tolerance (which follows the scene's value when a design or an "
     "identification moves it), or low..high around it. Every distribution is cut at its "
     "1e-6 and 1 - 1e-6 quantiles, and each "
     "input at those two ends (the others at the scene's values) is checked as a scene is: in "
     "the key's range, a machine that can exist. An input that `follows` another moves by the "
     "same factor (E and G under a fixed Poisson's ratio): not an input of its own, its share "
     "counted in its leader's Sobol' indices. The inputs are independent otherwise.",
     (InputSpec,)),
    ("[fidelity]", "What accuracy the scene needs, on which modes. Where the scene leaves "
     "[analytical] out, and mesh_size_mm out of [fem], the run chooses the cheapest models that "
     "meet it, by measurement (studies/choice.py).", (FidelitySettings,)),
    ("[analytical]", "Fidelity of the beam model (substructure synthesis, Eqs. 4-24); an "
     "explicit choice that overrides the automatic one.", (ModelOptions,)),
    ("[fem]", "Fidelity of the 3D solid reference, its refinement study and its guard; "
     "mesh_size_mm overrides the automatic choice.",
     (MeshSettings, FemOptions, FemStudy, FemRuntime)),
    ("[calibration.height]", "A value the paper prints wrongly, recovered and labelled.",
     (HeightCalibration,)),
    ("[cases.NAME]", ("One table per pose; NAME is the case's name, and names its files "
                      "(tables/NAME.csv, modes/NAME_fem.vtu): a name with a path separator, a "
                      f"control character, a leading dot, more than {MAX_LENGTH} characters "
                      "or a device name Windows reserves (CON, NUL, COM1, ...) is refused; "
                      "any character other than A-Z, a-z, 0-9, '.', '_' and '-' is written "
                      "as '_' in the file names (common/paths.py), and two names that give "
                      "one file name (case ignored) are refused."), (CaseSettings,)),
)

HEADER = """# Scene files

A scene (`scenes/*.toml`) is a manipulator, its poses and the fidelity asked. Lengths in
millimetres, angles in degrees, moduli in GPa, density in kg/m3 at this edge; the code converts
once to SI. Run one with `make SCENE=path/to/scene.toml`. Unknown keys are refused (with the
closest known key named), and every value outside its range gives a one-line error naming the
key and the value. Defaults written with `d` scale with the leg diameter d.

Generated from the declarations by `python -m rps scene-docs`; do not edit by hand.
"""


def _type(spec: Setting) -> str:
    if spec.kind is tuple:
        return "list of names" if spec.item is str else (
            f"{spec.length} numbers" if spec.length else "list of numbers")
    return {float: "number", int: "integer", str: "text", bool: "true/false"}[spec.kind]


def _edge(spec: Setting, value) -> str:
    if isinstance(value, tuple):
        return "[" + ", ".join(_edge(spec, v) for v in value) + "]"
    if isinstance(value, float):
        return f"{spec.edge(value):.6g}"
    return repr(value) if isinstance(value, str) else str(value)


def _default(name: str, spec: Setting, default) -> str:
    if name in GEOMETRY_DEFAULTS_TEXT:
        return GEOMETRY_DEFAULTS_TEXT[name]
    for architecture in ARCHITECTURES.values():
        if spec.scene_key(name) in architecture.required:
            return f"required ({architecture.name})"
    if default is MISSING or spec.scene_required:
        return "required"
    if default is None:
        return "—"
    return _edge(spec, default)


def _cell(text: str) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def section(title: str, intro: str, classes) -> list[str]:
    """One table's section: its title, its introduction and a row per declared key."""
    lines = [f"## {title}", "", intro, "",
             "| key | type | unit | default | allowed | meaning |",
             "|---|---|---|---|---|---|"]
    for cls in classes:
        for name, spec, default in declared(cls):
            if not spec.scene:
                continue
            lines.append("| " + " | ".join(_cell(x) for x in (
                f"`{spec.scene_key(name)}`", _type(spec), spec.unit or "",
                _default(name, spec, default), spec.range_text(), spec.doc)) + " |")
    return lines + [""]


def render() -> str:
    lines = [HEADER]
    for title, intro, classes in TABLES:
        lines += section(title, intro, classes)
    lines += ["## Physical consistency", "",
              "Rules that tie values together, checked when a scene is read, before any work "
              "(analytical/plausibility.py): a machine that breaks one cannot exist and is "
              "refused in one line naming the keys and the rule; a rule that says warning lets "
              "the scene run and states the warning in the command's output and the report.",
              ""]
    lines += [f"- **{name}**: {_cell(text)}." for name, text in
              RULES + (("paper's rows", PAPER_ROWS_RULE),)]
    lines.append("")
    return "\n".join(lines)


def write(path: Path = DOC) -> Path:
    from common.atomic import write_text_atomic
    return write_text_atomic(path, render())
