"""On-disk cache of condensed end zones and leg parts, keyed by content.

Key: SHA-256 of the canonical JSON of everything the superelement depends on: an end zone's
diameter, length, E, G, rho, joint coupling and mesh settings (`common.settings.as_dict`); a
leg part's diameters, its length or its piece of the stroke (`leg_part.piece_bounds`, with the
piece grid and Chebyshev nodes), its stations, material, couplings and mesh settings; and for
both the pinned gmsh options, the gmsh and scikit-fem versions and this format's version. Not
the machine: every machine with that part shares the entry. An entry is `<key>.npz` (the
matrices) and `<key>.json` (the inputs, the build facts and the SHA-256 of both files,
`common.checksum`), each written atomically, the JSON last; an entry failing its checks is
dropped with one line on stderr and rebuilt.
"""
from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import numpy as np

from common.atomic import atomic_write, write_text_atomic
from common.checksum import ChecksumError, report_dropped, seal, verify
from common.locations import cache_root
from common.settings import as_dict

from .leg_part import (
    PIECE_ANCHOR,
    PIECE_NODES,
    PIECE_RATIO,
    PartMesh,
    PartModel,
    PartPiece,
    build_part,
    build_piece,
)
from .zone import ZoneMesh, ZoneModel, build_zone

FORMAT_VERSION = 1
KIND = "joint_ends"  # the entries' folder under a cache directory, beside the other kinds


def zone_inputs(diameter, length, youngs_modulus, shear_modulus, density, coupling,
                mesh: ZoneMesh, inner_diameter: float = 0.0) -> dict:
    from meshing.geometry import PINNED_OPTIONS, gmsh_version

    rounded = _rounded
    return {"format": FORMAT_VERSION, "gmsh": gmsh_version(), "options": PINNED_OPTIONS,
            "diameter_m": rounded(diameter), "length_m": rounded(length),
            "youngs_modulus_pa": rounded(youngs_modulus),
            "shear_modulus_pa": rounded(shear_modulus), "density_kg_m3": rounded(density),
            "coupling": coupling, "mesh": as_dict(mesh)} | (
                {"inner_diameter_m": rounded(inner_diameter)} if inner_diameter else {})


def zone_key(inputs: dict) -> str:
    return hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest()


def default_dir(root: str | os.PathLike | None = None) -> Path:
    """The zones' folder under the cache directory `root` (None: the default one,
    `common.locations.cache_root`: the checkout's .cache/, or the user cache directory)."""
    return Path(cache_root() if root is None else root) / KIND


def cached_zone(diameter, length, youngs_modulus, shear_modulus, density, coupling,
                mesh: ZoneMesh = ZoneMesh(), cache_dir: str | os.PathLike | None = None,
                inner_diameter: float = 0.0) -> ZoneModel:
    """The condensed zone from the cache, or built and stored (a tube with a bore of
    `inner_diameter`; 0: solid, the key of a solid zone unchanged)."""
    inputs = zone_inputs(diameter, length, youngs_modulus, shear_modulus, density, coupling,
                         mesh, inner_diameter)

    def build():
        model = build_zone(diameter, length, youngs_modulus, shear_modulus, density, coupling,
                           mesh, inner_diameter=inner_diameter)
        return {"stiffness": model.stiffness, "mass": model.mass}, {
            "length_m": model.length, "raw_dofs": model.raw_dofs,
            "first_interior_hz": model.first_interior_hz}

    arrays, record = _entry(inputs, build, cache_dir, "end-zone cache entry")
    return ZoneModel(arrays["stiffness"], arrays["mass"], record["length_m"],
                     record["raw_dofs"], record["first_interior_hz"])


def _rounded(x: float) -> float:
    return float(f"{x:.12g}")


def part_inputs(outer, inner, stations, youngs_modulus, shear_modulus, density, couplings,
                mesh: PartMesh, length: float | None = None, piece: int | None = None) -> dict:
    """What a condensed leg part depends on: at one `length`, or over grid `piece`."""
    import skfem

    from meshing.geometry import PINNED_OPTIONS, gmsh_version

    where: dict
    if piece is not None and length is None:
        where = {"piece": int(piece), "piece_grid": [PIECE_ANCHOR, PIECE_RATIO, PIECE_NODES]}
    elif length is not None and piece is None:
        where = {"length_m": _rounded(length)}
    else:
        raise ValueError("a leg part's inputs: its length or its piece, one of the two")
    return {"format": FORMAT_VERSION, "kind": "leg part", "gmsh": gmsh_version(),
            "scikit_fem": skfem.__version__, "options": PINNED_OPTIONS,
            "outer_diameter_m": _rounded(outer), "inner_diameter_m": _rounded(inner),
            "stations": int(stations), "youngs_modulus_pa": _rounded(youngs_modulus),
            "shear_modulus_pa": _rounded(shear_modulus), "density_kg_m3": _rounded(density),
            "couplings": list(couplings), "mesh": as_dict(mesh)} | where


def part_entry_exists(inputs: dict, cache_dir: str | os.PathLike | None = None) -> bool:
    """Whether the entry of `inputs` is on disk (its checks are made when it is read)."""
    directory = Path(cache_dir) if cache_dir is not None else default_dir()
    return (directory / f"{zone_key(inputs)}.json").exists()


def cached_part(outer, inner, length, stations, youngs_modulus, shear_modulus, density,
                couplings, mesh: PartMesh = PartMesh(),
                cache_dir: str | os.PathLike | None = None) -> PartModel:
    """A leg part of one length (a housing: the same in every pose), from the cache or built
    (`leg_part.build_part`) and stored."""
    inputs = part_inputs(outer, inner, stations, youngs_modulus, shear_modulus, density,
                         couplings, mesh, length=length)

    def build():
        model = build_part(outer, inner, length, stations, youngs_modulus, shear_modulus,
                           density, couplings, mesh)
        return {"stiffness": model.stiffness, "mass": model.mass}, {
            "raw_dofs": model.raw_dofs}

    arrays, record = _entry(inputs, build, cache_dir, "leg-part cache entry")
    return PartModel(arrays["stiffness"], arrays["mass"], float(length), record["raw_dofs"])


def cached_piece(outer, inner, piece, stations, youngs_modulus, shear_modulus, density,
                 couplings, mesh: PartMesh = PartMesh(),
                 cache_dir: str | os.PathLike | None = None) -> PartPiece:
    """A leg part over grid piece `piece` of its stroke (`leg_part.build_piece`), from the
    cache or built and stored."""
    inputs = part_inputs(outer, inner, stations, youngs_modulus, shear_modulus, density,
                         couplings, mesh, piece=piece)

    def build():
        made = build_piece(outer, inner, piece, stations, youngs_modulus, shear_modulus,
                           density, couplings, mesh)
        return {"stiffness": made.stiffness, "mass": made.mass}, {
            "lo_m": made.lo, "hi_m": made.hi, "tail": made.tail, "raw_dofs": made.raw_dofs}

    arrays, record = _entry(inputs, build, cache_dir, "leg-piece cache entry")
    return PartPiece(record["lo_m"], record["hi_m"], arrays["stiffness"], arrays["mass"],
                     record["tail"], record["raw_dofs"])


def _entry(inputs: dict, build, cache_dir, what: str) -> tuple[dict, dict]:
    """(arrays, record) of the entry keyed by `inputs`: read and checked, or `build()`-t
    ((arrays, facts)) and stored (npz, then the sealed JSON)."""
    key = zone_key(inputs)
    directory = Path(cache_dir) if cache_dir is not None else default_dir()
    arrays_path, meta = directory / f"{key}.npz", directory / f"{key}.json"
    if meta.exists():
        try:
            record = verify(json.loads(meta.read_text(encoding="utf-8")), {".npz": arrays_path})
            with np.load(arrays_path) as data:
                return {name: data[name] for name in data.files}, record
        except FileNotFoundError:
            pass
        except (ChecksumError, ValueError, KeyError, OSError) as exc:
            report_dropped(what, meta, str(exc) or type(exc).__name__)
    arrays, facts = build()
    directory.mkdir(parents=True, exist_ok=True)

    def save(path: str) -> None:
        with open(path, "wb") as handle:
            np.savez(handle, **arrays)

    atomic_write(arrays_path, save)
    record = dict(inputs, key=key, **facts)
    write_text_atomic(meta, json.dumps(seal(record, {".npz": arrays_path}), indent=1))
    return arrays, record
