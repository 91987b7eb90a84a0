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
- payload weight: the weight of the payload and the platform, held by the legs in the
  platform's static equilibrium (`leg_forces`) at every pose of that grid and every case, is
  below each leg's Euler buckling load (pinned ends, its length there, the least bending
  stiffness of its parts); above PRELOAD_WARNING of it the scene runs with a warning, since
  both models neglect the legs' gravity preload, which lowers a leg's bending frequencies by
  about half that fraction. A platform without payload is checked too (on the coarser
  PLATE_GRID), unless it weighs under NEGLIGIBLE_LOAD of a leg's buckling load (so a scene
  without payload and with legs of sense costs nothing here).
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from common.errors import InputError
from common.leg_profile import MIN_PART_DIAMETERS, MIN_ROD_GAP
from common.settings import MIN_PART
from common.stiffness import MIN_SPRING

from .architectures import height_reach, leg_length_range, of
from .params import Manipulator
from .platform import platform_mass
from .pose_batch import pose_batch
from .reach import WorkspaceError, level_band, max_tilts

PAYLOAD_REACH = 4.0  # platform radii: the envelope of a payload's centre and of its mass
BAND_HEIGHTS = 24  # heights of the level band at which the payload's centre is checked ...
BAND_AZIMUTHS = 72  # ... level and at the largest tilt in each of these directions
TILT_TOLERANCE = 1e-4  # rad: the largest tilts, by bisection
BAND_GRID = (BAND_HEIGHTS, BAND_AZIMUTHS, TILT_TOLERANCE)
PLATE_GRID = (8, 24, 1e-3)  # a plate alone: its weight at o, the load varies smoothly
GRAVITY = 9.80665  # m/s2
PRELOAD_WARNING = 0.02  # of the buckling load: a leg's bending frequencies about 1 % low
# A plate (no payload) weighing under this fraction of one leg's Euler load at its longest is
# not checked further: its weight shared by three legs would have to be amplified some 60
# times (legs within a degree of horizontal, a near-singular pose) to reach the warning.
NEGLIGIBLE_LOAD = 1e-3

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
    ("tool envelope", "the [tool]'s point_mm within the machine's size of the platform "
     "centre (the greatest height its platform joints reach, or its longest leg, plus the "
     "platform's radius), above the base plane (z > 0) at "
     "every case, and above it at some pose of the level band; where it passes below the base "
     "plane at some poses of the band the scene runs with a warning (a ring-shaped base may "
     "clear it)"),
    ("springs", "each [stiffness] key is 0 (rigid) or at least "
     f"{MIN_SPRING / 1e6:g} N/um (N m/urad for a rotation): a softer bearing or drive carries "
     "no machine; at most its declared maximum, rigid to every digit of a double"),
    ("legs apart", "the three legs 120 degrees apart in leg_angles_deg (the parasitic-motion "
     "closure, Eq. 2), and no two legs overlapping at their joints on either circle"),
    ("payload weight", "the weight of the payload (at its centre) and the platform, held by "
     "the legs in the platform's static equilibrium (each leg's force through its spherical "
     "joint, in the plane of its axis and its revolute joint's axis; gravity along -z of the "
     "base frame) at every pose of the payload rule's grid and every case, below each leg's "
     "Euler buckling load (pinned ends, its length there, the least bending stiffness of its "
     "parts all along: a lower bound); the legs' own weight is left out: refused at or above "
     f"it; above {PRELOAD_WARNING:.0%} of it the scene runs with a warning in the command's "
     "output and the report (both models neglect the legs' gravity preload, which lowers "
     "their bending frequencies by about half that fraction)"),
)


def check(m: Manipulator, poses=()) -> tuple[str, ...]:
    """Refuse (InputError, one line naming the keys and the rule) a machine that cannot be;
    return the warnings of one that strains a shared idealisation. `poses`: (name, Pose) of
    the scene's cases, checked too where reachable (an unreachable one is named by the run's
    workspace check, never blamed on the payload). The same machine and cases are checked
    once per process (a scene read again costs nothing)."""
    return _checked(m, tuple((str(name), pose) for name, pose in poses))


@lru_cache(maxsize=64)
def _checked(m: Manipulator, poses: tuple) -> tuple[str, ...]:
    if m.leg.stepped:  # also checked first of the leg's proportions (params.check_manipulator)
        m.leg.check_rod_fits()
    loaded = m.payload.mass > 0.0
    if loaded:
        _check_envelope(m)
    elif _weight(m) < NEGLIGIBLE_LOAD * _buckling(m, leg_length_range(m)[1]):
        return ()  # the plate alone, far below what its legs carry: nothing to check
    found = _poses(m, poses, BAND_GRID if loaded else PLATE_GRID)
    if found is None:
        return ()
    if loaded:
        _check_above_base(m, *found)
    return _check_weight(m, *found)


def check_tool(m: Manipulator, point, poses=()) -> tuple[str, ...]:
    """The rule 'tool envelope' for a tool point (platform frame, m): refused (InputError,
    one line naming the key and the rule) beyond the machine's reach, below the base plane at
    a case (`poses`: (name, Pose)), or below it at every pose of the level band (it would pass
    through the base wherever the machine goes); a warning where it passes below the base
    plane at some poses of the band only (a ring-shaped base may clear it: the scene says
    nothing of the base's shape)."""
    return _tool_checked(m, tuple(float(v) for v in point),
                         tuple((str(name), pose) for name, pose in poses))


def tool_reach(m: Manipulator) -> float:
    """How far a tool point may lie from the platform centre (m): the machine's own size, the
    greatest height its platform joints reach (a 3-RPS: its longest leg; a 3-PRS: the top of
    its rails plus a link) and the platform's radius."""
    return max(height_reach(m), leg_length_range(m)[1]) + m.platform_radius


@lru_cache(maxsize=64)
def _tool_checked(m: Manipulator, point: tuple[float, float, float],
                  poses: tuple) -> tuple[str, ...]:
    shown = [float(f"{c * 1e3:.6g}") for c in point]
    reach = tool_reach(m)
    distance = math.dist(point, (0.0, 0.0, 0.0))
    if distance > reach:
        raise InputError(
            f"tool.point_mm = {shown}: {distance * 1e3:.6g} mm from the platform centre, "
            f"beyond the machine's reach (the highest its platform joints go, plus the "
            f"platform's radius: at most {reach * 1e3:.6g} mm, rule 'tool envelope')")
    try:
        low = level_band(m).low
    except WorkspaceError:  # no level pose: the run's own workspace check names the limit
        low = 0.0
    if distance < low and not poses:  # the platform centre is at least that high
        return ()
    found = _poses(m, poses, BAND_GRID if distance >= low else (0, 0, 1.0))
    if found is None:
        return ()
    batch, names = found
    heights = batch.platform_centre[:, 2] + batch.rotation[:, 2, :] @ np.asarray(point)
    below = heights <= 0.0
    at_case = [k for k in np.flatnonzero(below) if names[k] is not None]
    if at_case:
        k = int(at_case[0])
        raise InputError(
            f"tool.point_mm = {shown}: the tool point is {-heights[k] * 1e3:.1f} mm below "
            f"the base plane at {_where(batch, names, k)} (rule 'tool envelope')")
    band = [k for k, name in enumerate(names) if name is None]
    if band and all(below[k] for k in band):
        k = int(band[int(np.argmax(heights[band]))])
        raise InputError(
            f"tool.point_mm = {shown}: the tool point stays below the base plane at every "
            f"pose of the level band (at best {heights[k] * 1e3:.1f} mm, at "
            f"{_where(batch, names, k)}; rule 'tool envelope': it would pass through the "
            "base wherever the machine goes)")
    if any(below[k] for k in band):
        k = int(band[int(np.argmin(heights[band]))])
        return (f"tool.point_mm = {shown}: the tool point passes {-heights[k] * 1e3:.1f} mm "
                f"below the base plane at {_where(batch, names, k)} (rule 'tool envelope'): "
                "the base must leave it room there (a ring), or those poses are not "
                "usable",)
    return ()


def _weight(m: Manipulator) -> float:
    return (m.payload.mass + platform_mass(m)) * GRAVITY


def _buckling(m: Manipulator, lengths):
    """Euler load of a pinned leg of these lengths, its least bending stiffness all along
    (a lower bound for a stepped leg)."""
    parts = m.leg_parts(float(np.max(lengths)))
    stiffness = m.material.youngs_modulus * min(
        math.pi / 64 * (p.outer**4 - p.inner**4) for p in parts)
    return math.pi**2 * stiffness / np.asarray(lengths, float) ** 2


def _poses(m: Manipulator, poses, grid: tuple[int, int, float]):
    """The reachable poses the rules are checked at: the level band's grid (heights,
    azimuths, tilt tolerance) and the cases."""
    count, directions, tolerance = grid
    z: list[float] = []
    phi: list[float] = []
    theta: list[float] = []
    names: list[str | None] = []
    try:
        band = level_band(m) if count > 0 else None  # count 0: the cases alone
    except WorkspaceError:  # no level pose: the run's own workspace check names the limit
        band = None
    if band is not None:
        heights = np.linspace(band.low, band.high, count)
        azimuths = np.linspace(0.0, 2 * math.pi, directions, endpoint=False)
        tilts = max_tilts(m, heights, azimuths, tolerance)
        zz, pp = np.meshgrid(heights, azimuths, indexing="ij")
        z += [*heights, *zz.ravel()]
        phi += [0.0] * count + list(pp.ravel())
        theta += [0.0] * count + list(tilts.ravel())
        names += [None] * (count + zz.size)
    for name, pose in poses:
        z.append(pose.height)
        phi.append(pose.azimuth)
        theta.append(pose.tilt)
        names.append(f"case {name}")
    if not z:
        return None
    batch = pose_batch(m, z, phi, theta)
    keep = np.flatnonzero(batch.feasible)
    if not len(keep):
        return None
    return batch.take(keep), [names[k] for k in keep]


def _where(batch, names, k: int) -> str:
    name = names[k]
    return name if name is not None else (
        f"z = {batch.heights[k] * 1e3:.1f} mm, azimuth {math.degrees(batch.azimuths[k]):.0f} "
        f"deg, tilt {math.degrees(batch.tilts[k]):.1f} deg")


def _mm(value: float) -> str:
    return f"{value * 1e3:g}"


def _centre(m: Manipulator) -> list[float]:
    """The payload's centre as the scene gives it (mm)."""
    return [float(f"{c * 1e3:.6g}") for c in m.payload.centre]


def _check_envelope(m: Manipulator) -> None:
    p = m.payload
    reach = PAYLOAD_REACH * m.platform_radius
    distance = float(np.linalg.norm(p.centre))
    if distance > reach:
        raise InputError(
            f"payload.centre_mm = {_centre(m)}: "
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


def _check_above_base(m: Manipulator, batch, names) -> None:
    heights = _centre_heights(m, batch)
    k = int(np.argmin(heights))
    if heights[k] <= 0.0:
        raise InputError(
            f"payload.centre_mm = {_centre(m)}: the "
            f"payload's centre reaches {heights[k] * 1e3:.1f} mm, below the base plane, at "
            f"{_where(batch, names, k)} (rule 'payload above the base': it would pass through the "
            "base)")


def leg_forces(m: Manipulator, batch, mass: float, centre) -> np.ndarray:
    """(N, 3): the axial force of each leg (compression positive, N) holding up a mass `mass`
    at `centre` (platform frame, from o) under gravity along -z, at every pose of `batch`.

    Each leg passes to the platform a force through its spherical joint in the plane of its
    axis e_i and its revolute joint's axis a_i (the revolute joint takes no moment about a_i,
    so the force has no component along a_i x e_i): f_i e_i + g_i a_i. The six unknowns
    solve the platform's equilibrium of forces and of moments about o; f_i > 0 pushes the
    platform away from the base, a compressed leg. Poses near a singularity (condition above
    1e10) give NaN."""
    spherical = batch.platform_points if m.platform_joint == "S" else batch.base_points
    arm = spherical - batch.platform_centre[:, None, :]  # (N, 3, 3)
    axes = np.concatenate([batch.leg_frames[:, :, :, 0], batch.joint_axes], axis=1)  # (N,6,3)
    arms = np.concatenate([arm, arm], axis=1)
    wrench = np.concatenate([axes, np.cross(arms, axes)], axis=2).transpose(0, 2, 1)
    load = np.array([0.0, 0.0, -mass * GRAVITY])
    lever = batch.rotation @ np.asarray(centre, float)  # (N, 3)
    rhs = -np.concatenate([np.broadcast_to(load, lever.shape), np.cross(lever, load)], axis=1)
    cond = np.linalg.cond(wrench)
    good = np.isfinite(cond) & (cond < 1e10)
    out = np.full((len(rhs), 3), np.nan)
    if good.any():
        out[good] = np.linalg.solve(wrench[good], rhs[good][..., None])[:, :3, 0]
    return out


def _check_weight(m: Manipulator, batch, names) -> tuple[str, ...]:
    buckling = _buckling(m, batch.leg_lengths)  # (N, 3)
    plate = leg_forces(m, batch, platform_mass(m), (0.0, 0.0, 0.0)) / buckling
    per_kg = leg_forces(m, batch, 1.0, m.payload.centre) / buckling
    ratio = plate + m.payload.mass * per_kg
    if not np.isfinite(ratio).any():
        return ()
    k, leg = (int(i) for i in np.unravel_index(int(np.nanargmax(ratio)), ratio.shape))
    worst = float(ratio[k, leg])
    kind = of(m).leg_word
    where = (f"{kind} {leg + 1} at {_where(batch, names, k)}, "
             f"{batch.leg_lengths[k, leg] * 1e3:.1f} mm long")
    if m.payload.mass > 0.0:
        what = f"payload.mass_kg = {m.payload.mass:g} (centre_mm = " \
               f"{_centre(m)})"
    else:
        what = (f"platform_thickness_mm = {m.platform_thickness * 1e3:g} with leg_diameter_mm = "
                f"{m.leg_diameter * 1e3:g}")
    if worst >= 1.0:
        if m.payload.mass > 0.0 and np.nanmax(plate) < 1.0:
            room = np.where(per_kg > 0, (1.0 - plate) / np.where(per_kg > 0, per_kg, 1.0),
                            np.inf)
            advice = f"expected at most {float(np.nanmin(room)):.4g} kg there"
        else:
            advice = ("the platform's own weight already buckles it: thicker legs or a "
                      "lighter plate")
        raise InputError(
            f"{what}: the weight on the platform loads {where}, to {worst:.3g} times its "
            f"Euler buckling load (rule 'payload weight'): the machine cannot carry it; "
            f"{advice}")
    if worst > PRELOAD_WARNING:
        return (f"{what}: the weight on the platform loads {where}, to {worst:.1%} of its "
                f"Euler buckling load; both models neglect this preload, which lowers the "
                f"{kind}s' bending frequencies by about {worst / 2:.1%} (rule 'payload weight')",)
    return ()
