"""On-disk cache of condensed end zones, keyed by content.

Key: SHA-256 of the canonical JSON of everything the superelement depends on: diameter, zone
length, E, G, rho, the joint coupling, the zone's mesh settings (`common.settings.as_dict`), the
pinned gmsh options and gmsh version, and this format's version. An entry is `<key>.npz` (the
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

from .zone import ZoneMesh, ZoneModel, build_zone

FORMAT_VERSION = 1
KIND = "joint_ends"  # the entries' folder under a cache directory, beside the other kinds


def zone_inputs(diameter, length, youngs_modulus, shear_modulus, density, coupling,
                mesh: ZoneMesh, inner_diameter: float = 0.0) -> dict:
    from meshing.geometry import PINNED_OPTIONS, gmsh_version

    rounded = lambda x: float(f"{x:.12g}")  # noqa: E731
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
    key = zone_key(inputs)
    directory = Path(cache_dir) if cache_dir is not None else default_dir()
    arrays, meta = directory / f"{key}.npz", directory / f"{key}.json"
    if meta.exists():
        try:
            record = verify(json.loads(meta.read_text(encoding="utf-8")), {".npz": arrays})
            with np.load(arrays) as data:
                return ZoneModel(data["stiffness"], data["mass"], record["length_m"],
                                 record["raw_dofs"], record["first_interior_hz"])
        except FileNotFoundError:
            pass
        except (ChecksumError, ValueError, KeyError, OSError) as exc:
            report_dropped("end-zone cache entry", meta, str(exc) or type(exc).__name__)
    model = build_zone(diameter, length, youngs_modulus, shear_modulus, density, coupling,
                       mesh, inner_diameter=inner_diameter)
    directory.mkdir(parents=True, exist_ok=True)
    atomic_write(arrays, lambda p: _save(p, model))
    record = dict(inputs, key=key, length_m=model.length, raw_dofs=model.raw_dofs,
                  first_interior_hz=model.first_interior_hz)
    write_text_atomic(meta, json.dumps(seal(record, {".npz": arrays}), indent=1))
    return model


def _save(path: str, model: ZoneModel) -> None:
    with open(path, "wb") as handle:
        np.savez(handle, stiffness=model.stiffness, mass=model.mass)
