"""Solid pieces of the legs, condensed to superelements for the analytical model.

    from joint_ends import end_zone, leg_part
    zone = end_zone(diameter, length, E, G, rho, coupling)   # joint_ends.EndZone
    part = leg_part(D, d, L, s, E, G, rho, (coupling, coupling))   # joint_ends.PartModel

An end zone (`joint_ends = "solid"`) is the leg next to a coupled face, 12 x 12; a part
(`legs = "solid"`) is a whole housing, rod or uniform leg on its s + 1 section nodes, from the
harmonic meridian of the FEM's legs: a part of one length (`leg_part`), or a part whose length
follows the pose as pieces of its stroke (`part_piece`: K and M interpolated in the length,
built once per piece and cached on disk like the zones).

The zone is built by `joint_ends.zone` (gmsh + scikit-fem, the FEM reference's machinery), once
per content: the matrices are cached on disk (`joint_ends.cache`, in `joint_ends/` under the
cache directory given, the run's `--cache`) and in this process. The package builds on common,
meshing and fem_reference and imports nothing of the analytical model, which takes the zone as
plain arrays (`EndZone`, `joint_ends.superelement`: numpy only).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from .leg_part import PartMesh, PartModel, PartPiece
from .superelement import EndZone
from .zone import COUPLINGS, ZoneMesh

__all__ = ["COUPLINGS", "EndZone", "PartMesh", "PartModel", "PartPiece", "ZoneMesh", "end_zone",
           "leg_part", "missing_pieces", "part_piece"]


def end_zone(diameter: float, length: float, youngs_modulus: float, shear_modulus: float,
             density: float, coupling: str, mesh: ZoneMesh = ZoneMesh(),
             cache_dir=None, inner_diameter: float = 0.0) -> EndZone:
    """The condensed end zone (`EndZone`) of a leg of this diameter and material, `length`
    long, its joint face coupled as `coupling`; SI units; a tube with a bore of
    `inner_diameter` (0: solid). `cache_dir`: the cache directory (the zones go to its
    `joint_ends/`); None: the default one."""
    return _memo(float(diameter), float(length), float(youngs_modulus), float(shear_modulus),
                 float(density), str(coupling), mesh, None if cache_dir is None
                 else str(cache_dir), float(inner_diameter))


@lru_cache(maxsize=16)
def _memo(diameter, length, youngs_modulus, shear_modulus, density, coupling, mesh, cache_dir,
          inner_diameter):
    from .cache import cached_zone, default_dir

    model = cached_zone(diameter, length, youngs_modulus, shear_modulus, density, coupling,
                        mesh, default_dir(cache_dir), inner_diameter)
    model.stiffness.setflags(write=False)
    model.mass.setflags(write=False)
    return EndZone(model.length, model.stiffness, model.mass)


def leg_part(outer: float, inner: float, length: float, stations: int, youngs_modulus: float,
             shear_modulus: float, density: float, couplings: tuple[str, str],
             mesh: PartMesh = PartMesh(), cache_dir=None) -> PartModel:
    """A whole leg part of one length condensed onto `stations` + 1 section nodes
    (`leg_part.build_part`; a housing, the same in every pose), cached on disk and remembered
    in this process. SI units; `inner` 0 for a solid part."""
    return _remembered("part", float(outer), float(inner), round(float(length), 12),
                       int(stations), float(youngs_modulus), float(shear_modulus),
                       float(density), tuple(couplings), mesh,
                       None if cache_dir is None else str(cache_dir))


def part_piece(outer: float, inner: float, piece: int, stations: int, youngs_modulus: float,
               shear_modulus: float, density: float, couplings: tuple[str, str],
               mesh: PartMesh = PartMesh(), cache_dir=None) -> PartPiece:
    """A leg part over grid piece `piece` of the lengths it takes (`leg_part.build_piece`:
    its condensed K and M interpolated in the length), cached on disk and remembered in this
    process."""
    return _remembered("piece", float(outer), float(inner), int(piece), int(stations),
                       float(youngs_modulus), float(shear_modulus), float(density),
                       tuple(couplings), mesh, None if cache_dir is None else str(cache_dir))


@lru_cache(maxsize=256)  # a housing and a rod's pieces per machine, a few machines a process
def _remembered(kind, outer, inner, where, stations, youngs_modulus, shear_modulus, density,
                couplings, mesh, cache_dir):
    """A part of one length (`kind` "part", `where` its length) or a piece of its stroke
    ("piece", `where` the piece), from the disk cache or built, its arrays read-only."""
    from .cache import cached_part, cached_piece, default_dir

    made = (cached_part if kind == "part" else cached_piece)(
        outer, inner, where, stations, youngs_modulus, shear_modulus, density, couplings, mesh,
        default_dir(cache_dir))
    made.stiffness.setflags(write=False)
    made.mass.setflags(write=False)
    return made


def missing_pieces(outer: float, inner: float, pieces, stations: int, youngs_modulus: float,
                   shear_modulus: float, density: float, couplings: tuple[str, str],
                   mesh: PartMesh = PartMesh(), cache_dir=None) -> tuple[list[int], float]:
    """(the grid pieces of `pieces` not on disk under the cache, about how many seconds
    building them takes: `leg_part.piece_seconds`)."""
    from .cache import default_dir, part_entry_exists, part_inputs
    from .leg_part import piece_seconds

    directory = default_dir(cache_dir)
    missing = [int(k) for k in np.unique(np.asarray(pieces, int))
               if not part_entry_exists(part_inputs(outer, inner, stations, youngs_modulus,
                                                    shear_modulus, density, couplings, mesh,
                                                    piece=int(k)), directory)]
    return missing, sum(piece_seconds(outer, inner, k, mesh) for k in missing)
