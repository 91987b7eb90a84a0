"""The analytical settings compared throughout a run: the paper's and ours, and the candidates of
the speed-vs-error plot and the fidelity choice. One constructor, so every study that names a
setting ("Timoshenko (Hutchinson), s=5") means the same options."""
from __future__ import annotations

from dataclasses import replace

from analytical.params import ModelOptions
from scene import Scene

Settings = dict[str, ModelOptions]  # label ("Timoshenko (Cowper), s=3") -> the options


def _setting(base: ModelOptions, beam: str, elements: int, shear: str = "cowper",
             joint_ends: str = "beam", platform_inertia: str = "plate",
             legs: str = "beam") -> ModelOptions:
    """The scene's analytical options with one compared setting in place."""
    return replace(base, beam=beam, elements=elements, shear=shear, joint_ends=joint_ends,
                   platform_inertia=platform_inertia, legs=legs)


SOLID_LEG_ELEMENTS = 8  # stations per part of the solid-legs setting (joint_ends/README.md)
SOLID_LEGS = f"Solid legs, s={SOLID_LEG_ELEMENTS}"


def _solid_legs(scene: Scene) -> Settings:
    """The solid-legs setting where a scene needs it: legs of a housing and a rod, short thick
    tubes no beam represents to 0.1 % (docs/legs.md); a uniform solid leg's beam models are
    within 0.05 % already, and the solid legs would only cost time there."""
    if not scene.manipulator.leg.stepped:
        return {}
    return {SOLID_LEGS: _setting(scene.analytical, "timoshenko", SOLID_LEG_ELEMENTS,
                                 legs="solid")}


def model_variants(scene: Scene) -> Settings:
    """The analytical settings compared throughout: the paper's and ours. Every Timoshenko
    label names its shear coefficient (analytical.beam: Cowper's or Hutchinson's); "solid
    ends" are the condensed solid end zones at the joints (analytical.end_zones); "solid
    legs", on a housing and a rod, every part condensed whole (analytical.solid_legs)."""
    base = scene.analytical
    eb, timo = "euler-bernoulli", "timoshenko"
    return {
        "paper (EB, s=3, Eq. 8 inertia)": _setting(base, eb, 3, platform_inertia="paper-eq8"),
        "EB, s=3, plate inertia": _setting(base, eb, 3),
        "Timoshenko (Cowper), s=3, plate inertia": _setting(base, timo, 3),
        "Timoshenko (Hutchinson), s=3, plate inertia": _setting(base, timo, 3, "hutchinson"),
        "Timoshenko (Cowper), s=10, plate inertia": _setting(base, timo, 10),
        "Timoshenko (Hutchinson), s=5, solid ends, plate inertia": _setting(
            base, timo, 5, "hutchinson", joint_ends="solid"),
    } | _solid_legs(scene)


SOLID_END_ELEMENTS = (1, 2, 3, 4, 5)  # s of the beam middle between two solid end zones


def speed_settings(scene: Scene) -> Settings:
    """Every analytical setting whose time and error the speed-vs-error plot shows: beam
    theories (with their shear coefficient) at s = 1..10, Timoshenko (Hutchinson) middles
    between solid end zones, and on a housing and a rod the solid legs."""
    base, out = scene.analytical, Settings()
    for beam, shear, tag in (("euler-bernoulli", "cowper", "EB"),
                             ("timoshenko", "cowper", "Timoshenko (Cowper)"),
                             ("timoshenko", "hutchinson", "Timoshenko (Hutchinson)")):
        for s in (1, 2, 3, 5, 10):
            out[f"{tag}, s={s}"] = _setting(base, beam, s, shear)
    for s in SOLID_END_ELEMENTS:
        out[f"Timoshenko (Hutchinson) + solid ends, s={s}"] = _setting(
            base, "timoshenko", s, "hutchinson", joint_ends="solid")
    return out | _solid_legs(scene)
