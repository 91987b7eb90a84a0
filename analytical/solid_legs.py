"""Solid legs (`legs = "solid"`): every part of a leg condensed from its solid of revolution.

With `legs = "solid"` a part (a uniform leg, or a housing and a rod) is not cut into frame
elements: its s + 1 chain nodes (the stations of `leg_chain`, k L_p / s along the part) are the
masters of a superelement condensed from the part's solid (`joint_ends.leg_part`: the FEM's own
harmonic meridian, both end faces coupled as `joint_coupling` says, the interior stations the
L2 projections of their sections, Guyan). The blocks join the leg's nodal matrices exactly
where the part's frame elements would have; the joints, the drive's node and the springs act
on the same nodes as with beam legs.

Built once per machine, never per pose: a part of one length in every pose (a housing, a
3-PRS's leg) is condensed once; a part whose length follows the pose (a rod, a uniform 3-RPS
leg) is the same solid stretched along its axis, so its K and M are read from pieces of its
stroke (`joint_ends.part_piece`: a mesh per piece stretched exactly, the condensed matrices
interpolated in the length to ~1e-10). Both are cached on disk under the run's cache; the
pieces a run lacks are announced with their estimated build time before they are built.

Only plain arrays cross here: `joint_ends` is imported lazily, as for the end zones
(`end_zones.solid_end_zone`), and a missing gmsh or scikit-fem is one line.
"""
from __future__ import annotations

import functools
import math
import sys

import numpy as np

from .architectures import leg_length_range
from .end_zones import JointEndsUnavailable
from .leg_chain import leg_chain, part_bounds
from .params import Manipulator, ModelOptions
from .part_reduction import (
    SUB_PIECES,
    interior_modes,
    reduce_part,
    stretched_modes,
    sub_piece,
)

ANNOUNCE_SECONDS = 1.0  # a build estimated longer than this is said on stderr before it starts


def part_blocks(manipulator: Manipulator, options: ModelOptions, lengths, modes: int = 0
                ) -> list[tuple[int, np.ndarray]]:
    """[(first node, (2, *lengths.shape, d, d))]: K and M of every part of legs of the given
    lengths in the limb frame, with `legs = "solid"` ([] otherwise): on its s + 1 stations
    (d = 6 (s + 1)), or with `modes` its interior reduced to that many modal coordinates
    (d = 12 + modes, `part_reduction`: the batched model's)."""
    if options.legs != "solid":
        return []
    joint_ends = _joint_ends()
    lengths = np.asarray(lengths, float)
    kinds = leg_chain(manipulator, options, modes).kinds
    bounds = part_bounds(manipulator, lengths)
    spans = [np.broadcast_to(end - start, lengths.shape) for start, end, _ in bounds]
    _announce(manipulator, options, bounds, spans, joint_ends)
    d = 12 + modes if modes else 6 * (options.elements + 1)
    out = []
    for p, ((_, _, part), span) in enumerate(zip(bounds, spans)):
        args = _part_args(manipulator, options, part)
        block = np.empty((2, *lengths.shape, d, d))
        fixed = _fixed_length(manipulator, p)
        if fixed is not None:  # one length in every pose: one condensation
            model = joint_ends.leg_part(part.outer, part.inner, fixed, *args)
            k, m = model.stiffness, model.mass
            if modes:
                k, m = reduce_part(k, m, interior_modes(k, m, modes))
            block[0], block[1] = k, m
        else:
            pieces = _pieces(span)
            for piece in np.unique(pieces):
                made = joint_ends.part_piece(part.outer, part.inner, int(piece), *args)
                where = pieces == piece
                if not modes:
                    block[0][where], block[1][where] = made.at(span[where])
                    continue
                subs = sub_piece(span, made.lo, made.hi)[0]
                for sub in np.unique(subs[where]):
                    there = where & (subs == sub)
                    reduced = _reduced_piece(part.outer, part.inner, int(piece), int(sub), args,
                                             modes)
                    block[0][there], block[1][there] = reduced.at(span[there])
        block[0] *= manipulator.material.youngs_modulus
        block[1] *= manipulator.material.density
        out.append((kinds.index(("solid", p)), block))
    return out


@functools.lru_cache(maxsize=512)
def _reduced_piece(outer, inner, piece, sub, args, modes):
    """Sub-piece `sub` of a piece of a part's stroke reduced (`part_reduction`: the modes of
    its middle length carried to its others, the static modes of each length), interpolated
    on its own Chebyshev points from the piece's interpolant."""
    from dataclasses import replace

    import joint_ends

    made = joint_ends.part_piece(outer, inner, piece, *args)
    ratio = made.hi / made.lo
    lo = made.lo * ratio ** (sub / SUB_PIECES)
    hi = made.lo * ratio ** ((sub + 1) / SUB_PIECES)
    middle = math.sqrt(lo * hi)
    phi = interior_modes(*made.at(middle), modes)
    nodes = len(made.stiffness)
    x = np.polynomial.chebyshev.chebpts1(nodes)
    lengths = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x
    k, m = reduce_part(*made.at(lengths), stretched_modes(phi, middle / lengths))
    fitted = [np.polynomial.chebyshev.chebfit(x, v.reshape(nodes, -1), nodes - 1).reshape(
        v.shape) for v in (k, m)]
    for c in fitted:
        c.setflags(write=False)
    return replace(made, lo=lo, hi=hi, stiffness=fitted[0], mass=fitted[1])


def _fixed_length(manipulator: Manipulator, part: int) -> float | None:
    """The length of part `part` if the machine gives it one length in every pose (a housing;
    a 3-PRS's leg), None if it follows the pose (a rod, a 3-RPS's uniform leg): decided by the
    machine, never by the poses a call happens to hold (three equal legs at a level pose are
    still read from the pieces, as the other poses of a map are)."""
    shortest, longest = leg_length_range(manipulator)
    start, end, _ = part_bounds(manipulator, np.array([shortest, longest]))[part]
    span = end - start
    return float(span[0]) if span[0] == span[1] else None


def clear_caches() -> None:
    """Forget the parts, pieces and reduced pieces remembered in this process (benchmarks time
    a machine's build; the disk cache is the caller's directory)."""
    joint_ends = _joint_ends()
    for memo in (joint_ends._remembered, _reduced_piece):
        memo.cache_clear()


def _joint_ends():
    try:
        import joint_ends
        from joint_ends import leg_part  # noqa: F401  (gmsh and scikit-fem behind it)
    except ModuleNotFoundError as exc:  # gmsh, scikit-fem or the package itself
        raise JointEndsUnavailable(
            f"legs = 'solid' needs the solid sub-model ({exc.name or exc} is not installed): "
            "install the [fem] extra or use legs = 'beam'") from None
    return joint_ends


def _part_args(manipulator: Manipulator, options: ModelOptions, part) -> tuple:
    """The part's builder's arguments after its diameters, for a unit material: E = 1 Pa,
    rho = 1 kg/m3 and the material's G / E (its Poisson ratio). A part's K is E times that of
    its Poisson ratio and its M rho times (the condensation and the reduction are linear in
    both), so machines of other moduli and densities (another steel, a design's variants)
    share one build; `part_blocks` scales the blocks back."""
    mat = manipulator.material
    coupling = options.joint_coupling
    return (options.elements, 1.0, mat.shear_modulus / mat.youngs_modulus, 1.0,
            (coupling, coupling), _mesh(), options.cache_dir)


def _mesh():
    from joint_ends import PartMesh

    return PartMesh()


def _pieces(span: np.ndarray) -> np.ndarray:
    from joint_ends.leg_part import piece_index

    return piece_index(span)


def _announce(manipulator, options, bounds, spans, joint_ends) -> None:
    """One stderr line before a build of pieces estimated longer than ANNOUNCE_SECONDS."""
    count, seconds = 0, 0.0
    for p, ((_, _, part), span) in enumerate(zip(bounds, spans)):
        if not span.size or _fixed_length(manipulator, p) is not None:
            continue
        missing, estimate = joint_ends.missing_pieces(
            part.outer, part.inner, _pieces(span), *_part_args(manipulator, options, part))
        count, seconds = count + len(missing), seconds + estimate
    if count and seconds > ANNOUNCE_SECONDS:
        print(f"note: solid legs: building {count} piece(s) of the legs' strokes once, about "
              f"{seconds:.0f} s (then cached)", file=sys.stderr, flush=True)
