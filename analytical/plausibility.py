"""Physical consistency of a machine: what a scene can write that no machine can be.

Every value of a scene is checked against its own range where it is read (`scene.load`); the
rules here tie values together, so a machine that cannot exist is refused before any work, with
one line naming the keys and the rule, and a machine that exists but strains an idealisation
the models share is run with a warning that the command's output and the report state. Each
rule is declared once in `RULES` (docs/scenes.md is generated from it) and checked by `check`:

- rod in bore: the rod of an actuator leg slides in the housing's bore, with room for a guide
  bush or wear ring between them (MIN_ROD_GAP radially); a solid housing has no bore;
- payload envelope: the payload's centre lies within PAYLOAD_REACH platform radii of the
  platform centre o, and so does its mass (each radius of gyration sqrt(J_i / m));
- payload above the base: the payload's centre stays above the base plane (z > 0, base frame)
  at every pose of the level band: each of BAND_HEIGHTS heights, level and at its largest tilt
  in each of BAND_AZIMUTHS directions;
- payload weight: the weight of the payload and the platform, shared by the three legs of a
  level pose (two-force members) at either end of the level band, is below a leg's Euler
  buckling load (pinned ends, the leg's length there, the least bending stiffness of its
  parts); above PRELOAD_WARNING of it the scene runs with a warning, since both models
  neglect the legs' gravity preload, which lowers a leg's bending frequencies by about half
  that fraction.
"""
from __future__ import annotations

import math

import numpy as np

from common.errors import InputError
from common.leg_profile import MIN_PART_DIAMETERS, MIN_ROD_GAP
from common.settings import MIN_PART
from common.stiffness import MIN_SPRING

from .architecture import is_prs
from .params import Manipulator
from .platform import platform_mass
from .pose_batch import pose_batch
from .reach import WorkspaceError, level_band, max_tilts

PAYLOAD_REACH = 4.0  # platform radii: the envelope of a payload's centre and of its mass
BAND_HEIGHTS = 24  # heights of the level band at which the payload's centre is checked ...
BAND_AZIMUTHS = 72  # ... level and at the largest tilt in each of these directions
TILT_TOLERANCE = 1e-4  # rad: the largest tilts, by bisection
GRAVITY = 9.80665  # m/s2
PRELOAD_WARNING = 0.02  # of the buckling load: a leg's bending frequencies about 1 % low

RULES = (
    ("rod out of the housing", f"a [leg]'s housing is at least {MIN_PART_DIAMETERS:g} of its "
     "outer diameters long, and at the shortest leg (actuator_min_mm) the rod reaches at least "
     f"{MIN_PART_DIAMETERS:g} rod diameters out of it: a tube, not a ring, with room for the "
     "solid end zones (actuator_min_mm >= housing_length_mm + "
     f"{MIN_PART_DIAMETERS:g} rod_outer_diameter_mm)"),
    ("walls", f"a bore leaves a wall of at least {MIN_PART * 1e3:g} mm (inner diameter at most "
     f"the outer less {2 * MIN_PART * 1e3:g} mm)"),
    ("rod in bore", f"a [leg]'s rod slides in the housing's bore: housing_inner_diameter_mm at "
     f"least rod_outer_diameter_mm + {2 * MIN_ROD_GAP * 1e3:g} mm ({MIN_ROD_GAP * 1e3:g} mm "
     "radially for a guide bush or wear ring); a solid housing (bore 0) takes no rod"),
    ("payload envelope", f"the [payload]'s centre_mm within {PAYLOAD_REACH:g} platform radii "
     f"of the platform centre, and each radius of gyration sqrt(inertia / mass) within "
     f"{PAYLOAD_REACH:g} platform radii"),
    ("payload above the base", "the payload's centre above the base plane (z > 0) at every "
     f"pose of the level band ({BAND_HEIGHTS} heights, each level and at its largest tilt in "
     f"{BAND_AZIMUTHS} directions)"),
    ("springs", "each [stiffness] key is 0 (rigid) or at least "
     f"{MIN_SPRING / 1e6:g} N/um (N m/urad for a rotation): a softer bearing or drive carries "
     "no machine; at most its declared maximum, rigid to every digit of a double"),
    ("legs apart", "the three legs 120 degrees apart in leg_angles_deg (the parasitic-motion "
     "closure, Eq. 2), and no two legs overlapping at their joints on either circle"),
    ("payload weight", "the weight of the payload and the platform, shared by the three legs "
     "of a level pose at either end of the level band, below a leg's Euler buckling load "
     "(pinned ends, the leg's length there, its least bending stiffness): refused at or above "
     f"it; above {PRELOAD_WARNING:.0%} of it the scene runs with a warning in the command's "
     "output and the report (both models neglect the legs' gravity preload, which lowers "
     "their bending frequencies by about half that fraction)"),
)


def check(m: Manipulator, poses=()) -> tuple[str, ...]:
    """Refuse (InputError, one line naming the keys and the rule) a machine that cannot be;
    return the warnings of one that strains a shared idealisation. `poses`: (name, Pose) of
    the scene's cases, where the payload's centre is checked too."""
    if m.leg.stepped:  # also checked first of the leg's proportions (params.check_manipulator)
        m.leg.check_rod_fits()
    if m.payload.mass == 0.0:
        return ()
    _check_envelope(m)
    try:
        band = level_band(m)
    except WorkspaceError:  # no level pose: the run's own workspace check names the limit
        return ()
    _check_above_base(m, band, poses)
    return _check_weight(m, band)


def _mm(value: float) -> str:
    return f"{value * 1e3:g}"


def _check_envelope(m: Manipulator) -> None:
    p = m.payload
    reach = PAYLOAD_REACH * m.platform_radius
    distance = float(np.linalg.norm(p.centre))
    if distance > reach:
        raise InputError(
            f"payload.centre_mm = {[float(f'{c * 1e3:.6g}') for c in p.centre]}: "
            f"{distance * 1e3:.6g} mm from the platform centre, beyond {PAYLOAD_REACH:g} "
            f"platform radii (platform_radius_mm = {_mm(m.platform_radius)}: at most "
            f"{reach * 1e3:.6g} mm, rule 'payload envelope')")
    gyration = max(p.inertia)
    if gyration > p.mass * reach**2:
        raise InputError(
            f"payload.inertia_kg_m2 = {list(p.inertia)} with mass_kg = {p.mass:g}: a radius "
            f"of gyration of {math.sqrt(gyration / p.mass) * 1e3:.6g} mm, beyond "
            f"{PAYLOAD_REACH:g} platform radii ({reach * 1e3:.6g} mm, rule 'payload "
            f"envelope'); expected each moment at most {p.mass * reach**2:.6g} kg m2")


def _centre_heights(m: Manipulator, batch) -> np.ndarray:
    centre = np.asarray(m.payload.centre, float)
    return batch.platform_centre[:, 2] + batch.rotation[:, 2, :] @ centre


def _check_above_base(m: Manipulator, band, poses) -> None:
    found = []
    for name, pose in poses:
        case = pose_batch(m, pose.height, pose.azimuth, pose.tilt)
        found.append((float(_centre_heights(m, case)[0]), f"case {name}"))
    if band.low > np.linalg.norm(m.payload.centre):  # no pose of the band takes it that low
        return _refuse_below(m, found)
    heights = np.linspace(band.low, band.high, BAND_HEIGHTS)
    azimuths = np.linspace(0.0, 2 * math.pi, BAND_AZIMUTHS, endpoint=False)
    tilts = max_tilts(m, heights, azimuths, TILT_TOLERANCE)
    z, phi = np.meshgrid(heights, azimuths, indexing="ij")
    batch = pose_batch(m, np.concatenate([heights, z.ravel()]),
                       np.concatenate([np.zeros(BAND_HEIGHTS), phi.ravel()]),
                       np.concatenate([np.zeros(BAND_HEIGHTS), tilts.ravel()]))
    found += [(float(zc), f"z = {h * 1e3:.1f} mm, azimuth {math.degrees(a):.0f} deg, tilt "
               f"{math.degrees(t):.1f} deg") for zc, h, a, t in zip(
        _centre_heights(m, batch), batch.heights, batch.azimuths, batch.tilts)]
    _refuse_below(m, found)


def _refuse_below(m: Manipulator, found) -> None:
    if not found:
        return
    lowest, where = min(found)
    if lowest <= 0.0:
        raise InputError(
            f"payload.centre_mm = {[float(f'{c * 1e3:.6g}') for c in m.payload.centre]}: the "
            f"payload's centre reaches {lowest * 1e3:.1f} mm, below the base plane, at {where} "
            "(rule 'payload above the base': it would pass through the base)")


def _check_weight(m: Manipulator, band) -> tuple[str, ...]:
    weight = (m.payload.mass + platform_mass(m)) * GRAVITY
    ends = pose_batch(m, [band.low, band.high], 0.0, 0.0)
    lengths = ends.leg_lengths.max(axis=1)
    directions = ends.platform_points - ends.base_points
    vertical = np.abs(directions[:, :, 2]).min(axis=1) / lengths
    force = weight / (3 * np.maximum(vertical, 1e-12))
    parts = m.leg_parts(float(lengths.max()))
    stiffness = m.material.youngs_modulus * min(
        math.pi / 64 * (p.outer**4 - p.inner**4) for p in parts)
    buckling = math.pi**2 * stiffness / lengths**2
    ratio = force / buckling
    k = int(np.argmax(ratio))
    where = f"at z = {ends.heights[k] * 1e3:.1f} mm, legs {lengths[k] * 1e3:.1f} mm long"
    if ratio[k] >= 1.0:
        most = buckling[k] * 3 * vertical[k] / GRAVITY - platform_mass(m)
        if most <= 0.0:
            raise InputError(
                f"payload.mass_kg = {m.payload.mass:g}: the platform's own weight "
                f"({platform_mass(m):.4g} kg) already loads each leg beyond its Euler buckling "
                f"load {buckling[k] / 1e3:.4g} kN {where} (rule 'payload weight'): legs this "
                "slender cannot carry it; thicker legs or a lighter platform")
        raise InputError(
            f"payload.mass_kg = {m.payload.mass:g}: with the platform's, its weight loads each "
            f"leg to {ratio[k]:.3g} times its Euler buckling load {buckling[k] / 1e3:.4g} kN "
            f"{where} (rule 'payload weight'): the machine cannot carry it; expected at most "
            f"{max(most, 0.0):.4g} kg")
    if ratio[k] > PRELOAD_WARNING:
        kind = "slider links" if is_prs(m) else "legs"
        return (f"payload.mass_kg = {m.payload.mass:g}: its weight loads the {kind} to "
                f"{ratio[k]:.1%} of their Euler buckling load {where}; both models neglect "
                f"this preload, which lowers the {kind}' bending frequencies by about "
                f"{ratio[k] / 2:.1%} (rule 'payload weight')",)
    return ()
