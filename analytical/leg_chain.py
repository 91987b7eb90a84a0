"""A leg as a chain of segments, built from its profile (`common.leg_profile`).

Joint to joint, a leg is one uniform part, or a housing and a rod. Every part is cut into
`options.elements` equal frame elements (Eq. 4; "elements per part chosen as today"), between
two solid end zones at its coupled faces when `joint_ends = "solid"` (`end_zones`). The chain
numbers the leg's nodes from B_i (node 0) to A_i; segment e joins nodes e and e + 1.

The drive spring (`common.stiffness`, `actuator_axial`) is a segment of zero length: a node
that repeats the one before it plus the drive's axial stretch delta along the leg,
u_split = u_before + delta e (the other five relative motions rigid). It sits at the junction
of a housing and a rod, or, for a uniform leg, at the base joint (node 1 repeats the joint's
node 0). With a rigid drive there is no such node: the housing and the rod share the junction
node (plane sections, as the FEM ties both faces to one point). The segment carries no matrix
of its own (zeros); the spring's energy 1/2 k_a delta^2 is added on delta by the synthesis
(`substructure`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .beam import Section, frame_element
from .end_zones import MIN_MIDDLE, JointEndsUnavailable
from .params import Manipulator, ModelOptions
from .part_reduction import reduced_segments

if TYPE_CHECKING:
    from joint_ends import EndZone


@dataclass(frozen=True)
class LegChain:
    """The pose-independent layout of every leg's chain: its segments, in order from B_i,
    each ("element", part index), ("zone", part index, "start" | "end"), ("drive",) or, with
    `legs = "solid"`, ("solid", part index): one station interval of a condensed part, whose
    matrices come whole from `solid_legs.part_blocks`."""

    kinds: tuple[tuple, ...]

    @property
    def segments(self) -> int:
        return len(self.kinds)

    @property
    def split(self) -> int | None:
        """The node that repeats the one before it plus the drive's stretch (None: rigid)."""
        for e, kind in enumerate(self.kinds):
            if kind[0] == "drive":
                return e + 1
        return None


def leg_chain(manipulator: Manipulator, options: ModelOptions, modes: int = 0) -> LegChain:
    """The segments of every leg of this machine with these options (the module doc); with
    solid legs and `modes`, each part's interior reduced to that many modal coordinates
    (`part_reduction`: the batched model's)."""
    solid = options.joint_ends == "solid" and options.legs == "beam"
    element = "solid" if options.legs == "solid" else "element"
    drive = manipulator.stiffness.actuator_axial > 0.0
    parts = 2 if manipulator.leg.stepped else 1
    kinds: list[tuple] = []
    if drive and parts == 1:
        kinds.append(("drive",))
    for p in range(parts):
        if p == 1 and drive:
            kinds.append(("drive",))
        if solid:
            kinds.append(("zone", p, "start"))
        count = options.elements
        if element == "solid":
            count = reduced_segments(count, modes)
        kinds.extend((element, p) for _ in range(count))
        if solid:
            kinds.append(("zone", p, "end"))
    return LegChain(tuple(kinds))


def segments(manipulator: Manipulator, options: ModelOptions) -> int:
    """Segments per leg: frame elements, end zones and the drive's."""
    return leg_chain(manipulator, options).segments


def part_bounds(manipulator: Manipulator, lengths: np.ndarray) -> list[tuple]:
    """(start, end, LegPart at the base-end unit scale) of every part, arrays over lengths."""
    leg = manipulator.leg
    if not leg.stepped:
        return [(np.zeros_like(lengths), lengths, manipulator.end_part("base"))]
    junction = np.full_like(lengths, leg.housing_length)
    if np.any(lengths <= junction):
        raise JointEndsUnavailable(
            f"leg length {float(np.min(lengths)) * 1e3:.6g} mm: not longer than its housing "
            f"(housing_length_mm = {leg.housing_length * 1e3:g})")
    return [(np.zeros_like(lengths), junction, manipulator.end_part("base")),
            (junction, lengths, manipulator.end_part("platform"))]


def _zone_length(options: ModelOptions, zones, part) -> float:
    return 0.0 if zones is None else zones[part.name].length


def leg_stations(manipulator: Manipulator, options: ModelOptions, zones, lengths
                 ) -> np.ndarray:
    """(..., segments + 1): positions of the leg nodes as fractions of each leg's length (the
    drive's node repeats the position of the node before it)."""
    lengths = np.asarray(lengths, float)
    chain = leg_chain(manipulator, options)
    s = options.elements
    paper = not manipulator.leg.stepped and chain.split is None
    if paper and zones is None:  # the paper's leg: s equal elements (as before, to the bit)
        return np.broadcast_to(np.linspace(0.0, 1.0, s + 1), lengths.shape + (s + 1,))
    if paper:  # the paper's leg between two zones
        lz = zones["leg"].length / lengths[..., None]
        inner = lz + np.linspace(0.0, 1.0, s + 1) * (1.0 - 2.0 * lz)
        return np.concatenate([np.zeros(lengths.shape + (1,)), inner,
                               np.ones(lengths.shape + (1,))], axis=-1)
    bounds = part_bounds(manipulator, lengths)
    positions = [np.zeros_like(lengths)]
    counters = [0] * len(bounds)
    for kind in chain.kinds:
        here = positions[-1]
        if kind[0] == "drive":
            positions.append(here)
            continue
        start, end, part = bounds[kind[1]]
        lz = _zone_length(options, zones, part)
        if kind[0] == "zone":
            positions.append(here + lz)
        else:
            counters[kind[1]] += 1
            k = counters[kind[1]]
            positions.append(start + lz + (end - start - 2 * lz) * k / s)
    return np.stack(positions, axis=-1) / lengths[..., None]


def leg_segments(manipulator: Manipulator, options: ModelOptions,
                 zones: dict[str, EndZone] | None, lengths, modes: int = 0) -> np.ndarray:
    """Stiffness and mass of every segment of legs of the given lengths, limb frame:
    (segments, 2, *lengths.shape, 12, 12), [K, M] per segment (Eq. 4 for the frame elements of
    each part's section, the condensed zones at its coupled faces, zeros for the drive)."""
    lengths = np.asarray(lengths, float)
    mat = manipulator.material
    chain = leg_chain(manipulator, options, modes)
    s = options.elements
    elements, zone_blocks = [], []
    for start, end, part in part_bounds(manipulator, lengths):
        lz = _zone_length(options, zones, part)
        middle = end - start - 2.0 * lz
        if zones is not None and np.any(middle < MIN_MIDDLE * part.outer):
            short = float(np.min(end - start))
            raise JointEndsUnavailable(
                f"{part.name} length {short * 1e3:.6g} mm: too short for two solid end zones "
                f"of end_zone = {options.end_zone:g} diameters ({lz * 1e3:.6g} mm each) and a "
                f"beam middle of at least {MIN_MIDDLE:g} diameters; shorten end_zone")
        section = Section.circle(part.outer, part.inner, mat.poisson_ratio, options.shear)
        k, m = frame_element(mat.youngs_modulus, mat.shear_modulus, mat.density, section,
                             middle / s, options.beam)
        elements.append(np.stack([k, m]))  # (2, ..., 12, 12)
        if zones is not None:
            zone = zones[part.name]
            zone_blocks.append({"start": (zone.stiffness, zone.mass),
                                "end": zone.at_platform_end()})
    shape = elements[0].shape
    out = []
    for kind in chain.kinds:
        if kind[0] == "element":
            out.append(elements[kind[1]])
        elif kind[0] == "solid":  # the part's block carries it (solid_legs.part_blocks)
            out.append(np.zeros(shape))
        elif kind[0] == "zone":
            out.append(np.stack([np.broadcast_to(a, shape[1:])
                                 for a in zone_blocks[kind[1]][kind[2]]]))
        else:
            out.append(np.zeros(shape))
    return np.stack(out)
