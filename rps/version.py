"""The project's version (from the installed distribution's metadata) and the git commit of
the code when it is known: from the repository checkout it runs in, or the commit pip recorded
when it installed from a git URL (PEP 610 `direct_url.json`). A wheel built from a local
directory records no commit; then there is none to tell.
"""
from __future__ import annotations

import json
import subprocess
from importlib import metadata

from common.locations import DISTRIBUTION, checkout_root


def project_version() -> str:
    try:
        return metadata.version(DISTRIBUTION)
    except metadata.PackageNotFoundError:
        return "unknown (not installed)"


def project_commit() -> str | None:
    """Abbreviated commit hash, with "-dirty" when the checkout has uncommitted changes."""
    checkout = checkout_root()
    if checkout is not None:
        try:
            proc = subprocess.run(
                ["git", "-C", str(checkout), "describe", "--always", "--dirty", "--abbrev=12",
                 "--match=^"],  # match no tag: the bare hash
                capture_output=True, text=True, timeout=10)
        except (OSError, subprocess.SubprocessError):
            proc = None
        if proc is not None and proc.returncode == 0 and proc.stdout.strip():
            return proc.stdout.strip()
    try:
        text = metadata.distribution(DISTRIBUTION).read_text("direct_url.json")
    except metadata.PackageNotFoundError:
        return None
    try:
        commit = json.loads(text or "{}").get("vcs_info", {}).get("commit_id")
    except ValueError:
        return None
    return commit[:12] if commit else None


def describe() -> str:
    """`rps-elastodynamics 0.1.0 (commit 0123456789ab)` or `... (commit unknown)`."""
    return f"{DISTRIBUTION} {project_version()} (commit {project_commit() or 'unknown'})"
