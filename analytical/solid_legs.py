"""Solid legs (`legs = "solid"`): every part of a leg condensed from its solid of revolution.

With `legs = "solid"` a part (a uniform leg, or a housing and a rod) is not cut into frame
elements: its s + 1 chain nodes (the stations of `leg_chain`, k L_p / s along the part) are the
masters of a superelement condensed from the part's solid (`joint_ends.leg_part`: the FEM's own
harmonic meridian, both end faces coupled as `joint_coupling` says, the interior stations the
L2 projections of their sections, Guyan). The blocks join the leg's nodal matrices exactly
where the part's frame elements would have; the joints, the drive's node and the springs act
on the same nodes as with beam legs. A part of fixed length (a housing) is the same block in
every pose; a part whose length follows the pose (a uniform leg, a rod) is condensed for each
length it takes (~0.05-0.5 s a part, remembered in the process).

Only plain arrays cross here: `joint_ends` is imported lazily, as for the end zones
(`end_zones.solid_end_zone`), and a missing gmsh or scikit-fem is one line.
"""
from __future__ import annotations

import numpy as np

from .end_zones import JointEndsUnavailable
from .leg_chain import leg_chain, part_bounds
from .params import Manipulator, ModelOptions


def part_blocks(manipulator: Manipulator, options: ModelOptions, lengths
                ) -> list[tuple[int, np.ndarray]]:
    """[(first node, (2, *lengths.shape, 6 (s + 1), 6 (s + 1)))]: K and M of every part of
    legs of the given lengths in the limb frame, with `legs = "solid"` ([] otherwise)."""
    if options.legs != "solid":
        return []
    lengths = np.asarray(lengths, float)
    kinds = leg_chain(manipulator, options).kinds
    s = options.elements
    mat = manipulator.material
    out = []
    for p, (start, end, part) in enumerate(part_bounds(manipulator, lengths)):
        span = np.broadcast_to(end - start, lengths.shape)
        block = np.empty((2, *lengths.shape, 6 * (s + 1), 6 * (s + 1)))
        for index in np.ndindex(lengths.shape):  # equal lengths: one build (joint_ends' memo)
            block[(0, *index)], block[(1, *index)] = _part(
                part, float(span[index]), s, mat, options.joint_coupling)
        out.append((kinds.index(("solid", p)), block))
    return out


def _part(part, length: float, stations: int, mat, coupling: str):
    try:
        from joint_ends import leg_part
    except ModuleNotFoundError as exc:  # gmsh, scikit-fem or the package itself
        raise JointEndsUnavailable(
            f"legs = 'solid' needs the solid sub-model ({exc.name or exc} is not installed): "
            "install the [fem] extra or use legs = 'beam'") from None
    model = leg_part(part.outer, part.inner, length, stations, mat.youngs_modulus,
                     mat.shear_modulus, mat.density, (coupling, coupling))
    return model.stiffness, model.mass
