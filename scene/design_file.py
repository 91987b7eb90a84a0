"""Design files (TOML): which values of a scene a design study may vary, within which bounds,
under which constraints, towards which objective (`rps design`, `studies.design`).

```toml
name = "Lightest legs and plate with f1 >= 20 Hz everywhere"
scene = "../scenes/3prs-head.toml"      # relative to this file

[variables]                              # scene keys ("table.key"), [low, high] in their units
"manipulator.leg_diameter_mm" = [40.0, 100.0]
"manipulator.platform_thickness_mm" = [20.0, 60.0]

[constraints]
min_frequency_hz = 20.0                  # the least f_mode over the reachable workspace
mode = 1
min_level_band_mm = 300.0                # heights of the reachable level platform (optional)

[objective]
minimise = "moving_mass"                 # or "lowest_frequency" (maximises the least f_mode)

[search]
designs = 60                             # designs solved at most
seed = 1
```
Every variable is a number the scene declares (`[manipulator]`, `[leg]`, `[stiffness]`,
`[payload] mass_kg`), its bounds inside the declared range; a design is the scene with those
values, parsed and checked like any scene (a refused one is an infeasible design, its reason
kept). Units at this edge as in scenes; SI inside.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from analytical.params import ModelOptions
from analytical.substructure import model_coordinates
from common.errors import InputError
from common.settings import MAX_MODES, Setting, setting, text_problem

from .address import resolve
from .load import Scene, SceneError, parse_scene
from .toml_table import Table, read_toml, short

OBJECTIVES = ("moving_mass", "lowest_frequency", "dynamic_stiffness", "critical_depth")
DIRECTIONS = ("x", "y", "z")
MAX_DESIGNS = 2000  # a study's designs at most (each one workspace minimum, about a second)


@dataclass(frozen=True)
class Constraints:
    """[constraints] of a design file."""

    min_frequency_hz: float = setting(0.0, minimum=0.0, maximum=1e6,
                                      doc="the least f_mode over the reachable workspace must "
                                      "reach this (0: no constraint)")
    mode: int = setting(1, kind=int, minimum=1, maximum=MAX_MODES,
                        doc="which natural frequency, f_1 the lowest")
    min_level_band: float = setting(0.0, unit="mm", minimum=0.0, maximum=100.0,
                                    doc="the heights at which the level platform is reachable "
                                    "must span at least this")
    min_dynamic_stiffness: float = setting(
        0.0, unit="N/um", minimum=0.0, maximum=1e6,
        doc="the least dynamic stiffness at the scene's [tool] (1 / max |H_dd| with its "
        "[damping]) over the regular workspace, in the weakest of `directions`, must reach "
        "this (0: no constraint)")
    directions: tuple[str, ...] = setting(
        DIRECTIONS, kind=tuple, item=str, min_length=1,
        doc="the tool directions (base frame x, y, z) the dynamic stiffness is taken along")
    min_critical_depth: float = setting(
        0.0, unit="mm", minimum=0.0, maximum=1.0,
        doc="the least critical depth of the scene's [cutting] (its stability lobes: every "
        "speed of its range) over a coarse map of the regular workspace must reach this "
        "(0: no constraint)")

    def __post_init__(self) -> None:
        bad = [d for d in self.directions if d not in DIRECTIONS]
        if bad or len(set(self.directions)) != len(self.directions):
            raise InputError(f"constraints.directions = {list(self.directions)}: expected "
                             "distinct names among x, y, z")


@dataclass(frozen=True)
class Objective:
    """[objective] of a design file."""

    minimise: str = setting("moving_mass", kind=str, choices=OBJECTIVES,
                            doc="moving_mass (legs, plate and payload), lowest_frequency "
                            "(the least f_mode, maximised), dynamic_stiffness (the least "
                            "dynamic stiffness at the tool, maximised) or critical_depth (the "
                            "least critical depth of the scene's cut, maximised)")


@dataclass(frozen=True)
class Search:
    """[search] of a design file."""

    designs: int = setting(60, kind=int, minimum=4, maximum=MAX_DESIGNS,
                           doc="designs solved at most by the optimiser")
    seed: int = setting(1, kind=int, minimum=0, maximum=2**31 - 1,
                        doc="seed of the optimiser's random start")


@dataclass(frozen=True)
class Variable:
    table: str
    key: str  # the scene key, in its edge unit
    low: float  # edge unit
    high: float
    spec: Setting

    @property
    def name(self) -> str:
        return f"{self.table}.{self.key}"


@dataclass(frozen=True)
class DesignSpec:
    name: str
    path: str
    scene_path: str
    raw_scene: dict
    variables: tuple[Variable, ...]
    constraints: Constraints
    objective: Objective
    search: Search
    model: ModelOptions


def _variable(name: Any, bounds: Any, where: str) -> Variable:
    address = resolve(name, f"{where}.variables:")
    table, key, spec = address.table, address.key, address.spec
    if (not isinstance(bounds, list) or len(bounds) != 2
            or not all(isinstance(b, (int, float)) and not isinstance(b, bool)
                       and math.isfinite(b) for b in bounds) or not bounds[0] < bounds[1]):
        raise SceneError(f"{where}.variables.{name} = {bounds!r}: expected [low, high], two "
                         "finite numbers, low below high")
    for b in bounds:
        why = spec.problem(float(b) * spec.scale, edge=True)
        if why is not None:
            raise SceneError(f"{where}.variables.{name} = {bounds!r}: {b!r} {why}")
    return Variable(table, key, float(bounds[0]), float(bounds[1]), spec)


def load_design(path: str | Path) -> DesignSpec:
    """Read and check a design file and its scene; SceneError with one line on any problem."""
    path = Path(path)
    raw = read_toml(path, "design file")
    where = str(path)
    top = Table(raw, where)
    name = top.get("name", "design study")
    why = "expected a string" if not isinstance(name, str) else text_problem(name)
    if why is not None:
        raise SceneError(f"{where}.name = {short(name)}: {why}")
    scene_ref = top.get("scene", None)
    if not isinstance(scene_ref, str) or not scene_ref:
        raise SceneError(f"{where}.scene: missing (the scene file the design varies, relative "
                         "to the design file)")
    scene_path = (path.parent / scene_ref).resolve()
    raw_scene = read_toml(scene_path, f"{where}.scene = {scene_ref!r}: scene file")
    parse_scene(raw_scene, str(scene_path))  # the scene itself must be valid
    variables_t = top.table("variables")
    variables = tuple(_variable(k, v, where) for k, v in variables_t.data.items())
    variables_t.used.update(variables_t.data)
    if not variables:
        raise SceneError(f"{where}.variables: the design varies nothing")
    parts = {}
    for key, cls in (("constraints", Constraints), ("objective", Objective),
                     ("search", Search)):
        t = top.table(key, {})
        parts[key] = t.settings(cls)
        t.done()
    model_t = top.table("model", {})
    model = model_t.settings(ModelOptions, {"beam": "timoshenko", "shear": "hutchinson"},
                             modes=parts["constraints"].mode)
    model_t.done()
    top.done()
    c, minimise = parts["constraints"], parts["objective"].minimise
    if minimise == "moving_mass" and not (c.min_frequency_hz or c.min_dynamic_stiffness
                                          or c.min_critical_depth):
        raise SceneError(f"{where}.constraints.min_frequency_hz: missing (or "
                         "min_dynamic_stiffness_n_per_um or min_critical_depth_mm): the "
                         "lightest machine without a target is the smallest one the bounds "
                         "allow")
    if (c.min_critical_depth or minimise == "critical_depth") and "cutting" not in raw_scene:
        asked = ("constraints.min_critical_depth_mm" if c.min_critical_depth
                 else "objective.minimise = 'critical_depth'")
        raise SceneError(f"{where}.{asked}: the scene {scene_ref!r} has no [cutting] table "
                         "(the cut whose critical depth the design would take)")
    if ("directions" in raw.get("constraints", {}) and not c.min_dynamic_stiffness
            and minimise != "dynamic_stiffness"):
        raise SceneError(f"{where}.constraints.directions = {short(list(c.directions))}: "
                         "the directions of the dynamic stiffness, but the design asks for "
                         "none (no min_dynamic_stiffness_n_per_um, objective minimise = "
                         f"{minimise!r}); give min_dynamic_stiffness_n_per_um or leave "
                         "directions out")
    spec = DesignSpec(str(name), where, str(scene_path), raw_scene, variables,
                      parts["constraints"], parts["objective"], parts["search"], model)
    middle = [0.5 * (v.low + v.high) for v in variables]
    try:  # a key this scene can never take refuses every design: say so before any is solved
        scene = design_scene(spec, middle)
    except SceneError as exc:
        raise SceneError(f"{where}: the design at the middle of its bounds is refused: "
                         f"{exc}") from None
    if parts["constraints"].mode > model_coordinates(scene.manipulator, model):
        raise SceneError(f"{where}.constraints.mode = {parts['constraints'].mode}: the search "
                         f"model has only {model_coordinates(scene.manipulator, model)} modes")
    return spec


def design_scene(spec: DesignSpec, values) -> Scene:
    """The scene with the variables at `values` (edge units, in the spec's order), parsed and
    checked like any scene (SceneError if this design is not a plausible machine)."""
    raw = {k: (dict(v) if isinstance(v, dict) else v) for k, v in spec.raw_scene.items()}
    for var, value in zip(spec.variables, values):
        raw.setdefault(var.table, {})[var.key] = float(value)
    return parse_scene(raw, spec.scene_path)
