"""Where the project's files live: the repository checkout (when run from one), the packaged
scenes, and the cache directory.

Run from the repository checkout (a `pyproject.toml` and a `.git` beside the package root, as in
an editable install), caches stay in the checkout's `.cache/` as always. Installed from a wheel,
the package root is site-packages, which is never written into: caches go to the platform's user
cache directory (platformdirs, imported only then). The scenes ship inside the wheel as
`pipeline/scenes/*.toml`; in the checkout they are read from `scenes/`.
"""
from __future__ import annotations

from pathlib import Path

from .errors import ComputeError

DISTRIBUTION = "rps-elastodynamics"
PACKAGE_ROOT = Path(__file__).resolve().parents[1]  # the checkout, or site-packages


def checkout_root(root: Path = PACKAGE_ROOT) -> Path | None:
    """The repository checkout that holds the packages, or None when they are installed."""
    if (root / "pyproject.toml").is_file() and (root / ".git").exists():
        return root
    return None


def cache_root(root: Path = PACKAGE_ROOT) -> Path:
    """Default directory of the result and mesh caches: `<checkout>/.cache`, else the user's
    cache directory for this project (e.g. ~/.cache/rps-elastodynamics on Linux)."""
    checkout = checkout_root(root)
    if checkout is not None:
        return checkout / ".cache"
    try:
        from platformdirs import user_cache_path
    except ImportError:
        raise ComputeError(f"platformdirs is not installed: install {DISTRIBUTION}[fem] "
                           "for the FEM and its caches") from None
    return user_cache_path(DISTRIBUTION, appauthor=False)


def scenes_dir(root: Path = PACKAGE_ROOT) -> Path:
    """The scene files: `<checkout>/scenes`, or the copy packaged in `pipeline/scenes`."""
    checkout = checkout_root(root)
    return checkout / "scenes" if checkout is not None else root / "pipeline" / "scenes"


def default_scene(root: Path = PACKAGE_ROOT) -> Path:
    """The paper's scene, the default of every command (absolute, independent of the cwd)."""
    return scenes_dir(root) / "paper.toml"
