"""The segments of a leg: Timoshenko/Euler-Bernoulli elements, and solid end zones at the joints.

With `joint_ends = "beam"` a leg of length L is s equal frame elements (Eq. 4). With
`joint_ends = "solid"` each joint end gets an end zone of fixed length l_z = end_zone * d whose
stiffness and mass come from a small solid model of that zone, condensed to a 12 x 12
superelement on (joint point, interface section node) (the `joint_ends` package: gmsh +
scikit-fem, cached on disk); the s frame elements carry the rest, L - 2 l_z. The zone captures
what a beam cannot: near a joint face the section can neither warp nor contract freely (rigid
coupling), which stiffens a leg by about 0.6 % on its first bending modes.

A leg then has s + 2 segments; segment e joins leg nodes e and e + 1, from B_i (node 0) to A_i.
This module only handles plain arrays: the superelement arrives as a `joint_ends.EndZone` (its
matrices, and their mirror image for the platform end), so the model itself needs numpy alone;
`solid_end_zone` imports the builder lazily and says in one line what is missing when gmsh or
scikit-fem are not installed.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from common.errors import InputError

from .beam import Section, frame_element
from .params import Manipulator, ModelOptions

if TYPE_CHECKING:  # the zone's type lives with its builder, imported only for solid ends
    from joint_ends import EndZone

MIN_MIDDLE = 0.1  # the beam middle must be at least this many leg diameters long


class JointEndsUnavailable(InputError):
    """Solid joint ends were asked for but cannot be built here."""


def segments(options: ModelOptions) -> int:
    """Segments per leg: the s frame elements, plus the two end zones."""
    return options.elements + (2 if options.joint_ends == "solid" else 0)


def solid_end_zone(manipulator: Manipulator, options: ModelOptions) -> EndZone:
    """The condensed end zone of this leg diameter, material and joint coupling (built once,
    then read from the cache of `joint_ends`, under `options.cache_dir`)."""
    mat = manipulator.material
    try:
        from joint_ends import end_zone
        return end_zone(manipulator.leg_diameter, options.end_zone * manipulator.leg_diameter,
                        mat.youngs_modulus, mat.shear_modulus, mat.density,
                        options.joint_coupling, cache_dir=options.cache_dir)
    except ModuleNotFoundError as exc:  # gmsh, scikit-fem or the package itself
        raise JointEndsUnavailable(
            f"joint_ends = 'solid' needs the solid sub-model ({exc.name or exc} is not "
            "installed): install the [fem] extra or use joint_ends = 'beam'") from None


def leg_stations(options: ModelOptions, zone: EndZone | None, lengths) -> np.ndarray:
    """(..., segments + 1): positions of the leg nodes as fractions of each leg's length."""
    lengths = np.asarray(lengths, float)
    s = options.elements
    if zone is None:
        return np.broadcast_to(np.linspace(0.0, 1.0, s + 1), lengths.shape + (s + 1,))
    lz = zone.length / lengths[..., None]
    inner = lz + np.linspace(0.0, 1.0, s + 1) * (1.0 - 2.0 * lz)
    return np.concatenate([np.zeros(lengths.shape + (1,)), inner,
                           np.ones(lengths.shape + (1,))], axis=-1)


def leg_segments(manipulator: Manipulator, options: ModelOptions, zone: EndZone | None,
                 lengths) -> np.ndarray:
    """Stiffness and mass of every segment of legs of the given lengths, limb frame:
    (segments, 2, *lengths.shape, 12, 12), [K, M] per segment (Eq. 4 for the frame elements,
    the condensed zones at both ends with solid joint ends)."""
    lengths = np.asarray(lengths, float)
    mat = manipulator.material
    section = Section.solid_circle(manipulator.leg_diameter, mat.poisson_ratio, options.shear)
    s = options.elements
    middle = lengths if zone is None else lengths - 2.0 * zone.length
    if zone is not None and np.any(middle < MIN_MIDDLE * manipulator.leg_diameter):
        short = float(np.min(lengths))
        raise JointEndsUnavailable(
            f"leg length {short * 1e3:.6g} mm: too short for two solid end zones of "
            f"end_zone = {options.end_zone:g} leg diameters ({zone.length * 1e3:.6g} mm each) "
            f"and a beam middle of at least {MIN_MIDDLE:g} d; shorten end_zone")
    k, m = frame_element(mat.youngs_modulus, mat.shear_modulus, mat.density, section,
                         middle / s, options.beam)
    element = np.stack([k, m])  # (2, ..., 12, 12)
    if zone is None:
        return np.broadcast_to(element, (s,) + element.shape)
    shape = element.shape
    bottom = np.stack([np.broadcast_to(zone.stiffness, shape[1:]),
                       np.broadcast_to(zone.mass, shape[1:])])
    top = np.stack([np.broadcast_to(a, shape[1:]) for a in zone.at_platform_end()])
    return np.stack([bottom] + [element] * s + [top])


def zone_for(manipulator: Manipulator, options: ModelOptions) -> EndZone | None:
    """The end zone the options ask for (None with beam joint ends)."""
    return solid_end_zone(manipulator, options) if options.joint_ends == "solid" else None
