"""The numbers of a run that no timing can move, for the golden results of the shipped scenes.

A run's chosen analytical model is the fastest candidate within the tolerance, so which one is
chosen may follow the machine's timings; every candidate's error is measured all the same.
`digest(results)` keeps what is decided by the physics alone: every case's pose and FEM
frequencies, every candidate's worst error over the cases and study poses, the workspace
validation's per-pose errors and the reachable workspace. tests/test_scenes.py compares a CI
run of each shipped scene with tests/baselines/results/<scene>.json (`make update-baselines`
rewrites them, with the error tables, on purpose only).
"""
from __future__ import annotations

from typing_extensions import TypedDict

import results

RELATIVE = 1e-6  # round-off of dense and sparse eigen solves on the same meshes: ~1e-9
# ... and an absolute floor for numbers near zero: most of the digest's numbers are errors in
# percent, some a few thousandths of a percent, and their round-off is relative to the
# frequencies, not to the error: a frequency moved by RELATIVE moves an error by 100 RELATIVE
# percentage points, whatever its size. Measured 2026-11-26: the same code and library versions
# on another machine of the same kind moved the goldens of 2026-11-25 by up to 1.65e-6 pp
# (slender.json: an EB s = 1 error of -0.05107 %) and FEM frequencies by up to 4e-9. The floor
# is 100 RELATIVE = 1e-4 pp, sixty times that, and 200 times below the 0.02 pp the error-table
# baselines call a change of the physics.
ABSOLUTE = 100 * RELATIVE  # in the number's own unit: percentage points (Hz, mm, degrees)


class CaseDigest(TypedDict):
    name: str
    pose: results.Pose
    fem_hz: list[float]
    fem_dofs: int


class PoseDigest(TypedDict):
    height_mm: float
    azimuth_deg: float
    tilt_deg: float
    fem_hz: list[float] | None
    models: dict[str, list[float | None]] | None


class Digest(TypedDict):
    """tests/baselines/results/<scene>.json."""
    profile: str
    cases: list[CaseDigest]
    candidates: dict[str, float]  # setting -> its worst error over the cases and study poses, %
    mesh_size_mm: float
    validation_poses: list[PoseDigest]
    reachable_workspace: results.ReachableWorkspace


def digest(run: results.Results) -> Digest:
    studies = run["studies"]
    validation = studies["workspace_validation"]
    return Digest(
        profile=run["profile"],
        cases=[CaseDigest(name=c["name"], pose=c["pose"], fem_hz=c["fem"]["frequencies_hz"],
                          fem_dofs=c["fem"]["dofs"]) for c in run["cases"]],
        candidates={c["setting"]: c["worst_error_percent"]
                    for c in run["fidelity"]["candidates"]},
        mesh_size_mm=run["fidelity"]["fem"]["mesh_size_mm"],
        validation_poses=[PoseDigest(height_mm=p["height_mm"], azimuth_deg=p["azimuth_deg"],
                                     tilt_deg=p["tilt_deg"], fem_hz=p["fem_hz"],
                                     models=p["models"])
                          for p in (validation["poses"] if validation else [])],
        reachable_workspace=studies["reachable_workspace"])


def differences(golden, current, where: str = "", relative: float = RELATIVE,
                absolute: float = ABSOLUTE) -> list[str]:
    """Where two digests differ: numbers beyond `relative` of their size plus `absolute`,
    anything else exactly."""
    if isinstance(golden, dict) and isinstance(current, dict):
        if golden.keys() != current.keys():
            return [f"{where}: keys {sorted(set(golden) ^ set(current))}"]
        return [d for k in golden for d in differences(golden[k], current[k], f"{where}/{k}",
                                                        relative, absolute)]
    if isinstance(golden, list) and isinstance(current, list):
        if len(golden) != len(current):
            return [f"{where}: {len(golden)} items, now {len(current)}"]
        return [d for k, (a, b) in enumerate(zip(golden, current))
                for d in differences(a, b, f"{where}/{k}", relative, absolute)]
    if isinstance(golden, (int, float)) and isinstance(current, (int, float)) \
            and not isinstance(golden, bool):
        scale = max(abs(golden), abs(current), 1e-12)
        return [] if abs(golden - current) <= relative * scale + absolute else \
            [f"{where}: {golden!r}, now {current!r}"]
    return [] if golden == current else [f"{where}: {golden!r}, now {current!r}"]
