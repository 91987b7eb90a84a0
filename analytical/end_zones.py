"""Solid end zones: the leg next to a coupled face, condensed from a small solid model.

With `joint_ends = "solid"` every face the models couple to a reference point (the joint faces
at B_i and A_i, and with a housing and rod the two faces of the junction) gets an end zone of
fixed length l_z = end_zone * D (D: the outer diameter of the part it belongs to) whose
stiffness and mass come from a small solid model of that zone, condensed to a 12 x 12
superelement on (face point, interface section node) (the `joint_ends` package: gmsh +
scikit-fem, cached on disk); frame elements carry the rest of the part. The zone captures what
a beam cannot: near a coupled face the section can neither warp nor contract freely (rigid
coupling), which stiffens a leg by about 0.6 % on its first bending modes. A hollow part gets a
hollow zone.

This module only handles plain arrays: the superelement arrives as a `joint_ends.EndZone` (its
matrices, and their mirror image for a zone whose face is at its far end), so the model itself
needs numpy alone; `solid_end_zone` imports the builder lazily and says in one line what is
missing when gmsh or scikit-fem are not installed. The chain of a leg's segments is
`leg_chain`.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from common.errors import InputError
from common.leg_profile import LegPart

from .params import Manipulator, ModelOptions

if TYPE_CHECKING:  # the zone's type lives with its builder, imported only for solid ends
    from joint_ends import EndZone

MIN_MIDDLE = 0.1  # the beam middle of a part must be at least this many of its diameters long


class JointEndsUnavailable(InputError):
    """Solid joint ends were asked for but cannot be built here."""


def solid_end_zone(manipulator: Manipulator, options: ModelOptions,
                   part: LegPart | None = None) -> EndZone:
    """The condensed end zone of a part (default: the part at the base joint) of this material
    and joint coupling (built once, then read from the cache of `joint_ends`, under
    `options.cache_dir`)."""
    mat = manipulator.material
    part = manipulator.end_part("base") if part is None else part
    try:
        from joint_ends import end_zone
        return end_zone(part.outer, options.end_zone * part.outer, mat.youngs_modulus,
                        mat.shear_modulus, mat.density, options.joint_coupling,
                        cache_dir=options.cache_dir, inner_diameter=part.inner)
    except ModuleNotFoundError as exc:  # gmsh, scikit-fem or the package itself
        raise JointEndsUnavailable(
            f"joint_ends = 'solid' needs the solid sub-model ({exc.name or exc} is not "
            "installed): install the [fem] extra or use joint_ends = 'beam'") from None


def zone_for(manipulator: Manipulator, options: ModelOptions) -> dict[str, EndZone] | None:
    """The end zone of every part of the leg, by part name, with solid joint ends (None with
    beam joint ends)."""
    if options.joint_ends != "solid":
        return None
    parts = {manipulator.end_part(end).name: manipulator.end_part(end)
             for end in ("base", "platform")}
    return {name: solid_end_zone(manipulator, options, part) for name, part in parts.items()}
