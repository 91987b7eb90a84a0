"""On-disk mesh cache keyed by the geometry content and the mesh settings.

Key: SHA-256 of the canonical JSON of the bodies (rounded to 1e-12 m), the mesh settings, the
pinned gmsh options, the element-quality threshold and its repair options, the gmsh version and
the cache format version. An entry is two files:
`<key>.vtu` (the mesh, written by meshio) and `<key>.json` (digest of the mesh arrays and
metadata, with the SHA-256 of the mesh file and of the JSON itself), each written to a
temporary file in the same directory and moved into place with os.replace, the JSON last: an
entry whose files fail their checksums, without a valid JSON, or whose mesh does not read back
to the recorded digest, is treated as corrupt, removed (one line on stderr) and rebuilt - never
a crash, never a stale mesh. Files are ordinary (0666 less the umask: 0644 usually).
"""
from __future__ import annotations

import contextlib
import hashlib
import io
import json
import os
from pathlib import Path

import meshio

from common.atomic import atomic_write
from common.checksum import ChecksumError, report_dropped, seal, verify
from common.locations import cache_root

from .bodies import Assembly
from .geometry import (
    MIN_QUALITY,
    PINNED_OPTIONS,
    REPAIR_OPTIONS,
    MeshSettings,
    build_mesh,
    gmsh_version,
)
from .mesh import MeshFormatError, SolidMesh

FORMAT_VERSION = 1
# <checkout>/.cache/meshes, or the user cache directory when installed: never site-packages
DEFAULT_DIR = cache_root() / "meshes"


def cache_key(assembly: Assembly, settings: MeshSettings) -> str:
    content = {
        "format": FORMAT_VERSION,
        "gmsh": gmsh_version(),
        "options": PINNED_OPTIONS,
        "quality": {"minimum": MIN_QUALITY, "repair": REPAIR_OPTIONS},
        "assembly": assembly.canonical(),
        "settings": settings.canonical(),
    }
    return hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()


class MeshCache:
    def __init__(self, directory: str | os.PathLike | None = None):
        self.directory = Path(directory) if directory is not None else DEFAULT_DIR

    def paths(self, key: str) -> tuple[Path, Path]:
        return self.directory / f"{key}.vtu", self.directory / f"{key}.json"

    def load(self, key: str) -> SolidMesh | None:
        """The cached mesh, or None if absent or corrupt (a corrupt entry is removed, with one
        line on stderr)."""
        mesh_path, meta_path = self.paths(key)
        if not meta_path.exists():
            return None
        try:
            meta = verify(json.loads(meta_path.read_text(encoding="utf-8")),
                          {".vtu": mesh_path})
            with contextlib.redirect_stderr(io.StringIO()), \
                    contextlib.redirect_stdout(io.StringIO()):
                raw = meshio.read(mesh_path, file_format="vtu")  # may sys.exit on bad XML
            mesh = SolidMesh.from_meshio(raw, groups=meta["groups"], info=meta.get("info", {}))
            if meta.get("digest") != mesh.digest():
                raise MeshFormatError("digest mismatch")
            return mesh
        except FileNotFoundError:  # removed by another process since the check above
            return None
        except (Exception, SystemExit) as exc:  # unreadable or inconsistent entry: drop, rebuild
            why = str(exc) if isinstance(exc, ChecksumError) else type(exc).__name__
            report_dropped("mesh-cache entry", meta_path, why)
            self.remove(key)
            return None

    def store(self, key: str, mesh: SolidMesh) -> None:
        self.directory.mkdir(parents=True, exist_ok=True)
        mesh_path, meta_path = self.paths(key)
        m = mesh.to_meshio()
        atomic_write(mesh_path, lambda p: meshio.write(p, m, file_format="vtu",
                                                        binary=True, compression="zlib"))
        meta = {"key": key, "digest": mesh.digest(), "n_nodes": mesh.n_nodes,
                "n_tets": int(len(mesh.tets)), "groups": mesh.groups(), "info": mesh.info}
        sealed = seal(meta, {".vtu": mesh_path})  # SHA-256 of the mesh file and of this record
        atomic_write(meta_path, lambda p: Path(p).write_text(json.dumps(sealed, indent=1),
                                                              encoding="utf-8"))

    def remove(self, key: str) -> None:
        for p in self.paths(key):
            try:
                p.unlink()
            except OSError:
                pass


def cached_mesh(assembly: Assembly, settings: MeshSettings,
                cache_dir: str | os.PathLike | None = None,
                use_cache: bool = True) -> tuple[SolidMesh, bool]:
    """(mesh, cache_hit): from the cache if a valid entry exists, else built and stored."""
    key = cache_key(assembly, settings)
    cache = MeshCache(cache_dir)
    if use_cache:
        mesh = cache.load(key)
        if mesh is not None:
            return mesh, True
    mesh = build_mesh(assembly, settings)
    if use_cache:
        cache.store(key, mesh)
    return mesh, False
