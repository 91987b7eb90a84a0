"""What a solve of a pose answers, whichever the legs' discretisation: the `FemAnswer`
protocol that `tetrahedra.FemResult` and `harmonic_result.HarmonicResult` both satisfy (what
the pipeline, the studies and the reports read), and the helpers both build and read one with:
the modes' sign, the plain record, the sampling stations and the section twist.
"""
from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from .options import FemError, FemOptions


@runtime_checkable
class FemAnswer(Protocol):
    """A solved pose, as its callers read it (solvers.compare, rps.commands.fem, pipeline.bench,
    studies.hard_cases, convergence.study_from_results, refinement_study)."""

    frequencies_hz: np.ndarray  # (modes,) ascending
    dofs: int  # free coordinates after the joints are eliminated
    raw_dofs: int  # dofs of the unconstrained bodies (legs; the plate if meshed)
    mesh_size: float  # m, the global element size h
    timings: dict  # seconds: mesh, assemble, solve, total
    clusters: list  # groups of (near-)repeated modes, 0-based indices
    cache_hit: bool  # the mesh was read from the mesh cache
    mesh_digest: str
    n_elements: int
    options: FemOptions
    min_quality: float  # the mesh's smallest element quality (1: ideal)

    @property
    def platform_motion(self) -> np.ndarray:
        """(6, n_modes): translation of o and rotation of the platform."""
        ...

    def leg_axis_displacements(self, fractions) -> np.ndarray:
        """(3 legs, len(fractions), 3, n_modes): translation of the leg axis points
        B_i + t (A_i - B_i), base coordinates."""
        ...

    def leg_axis_twists(self, fractions) -> np.ndarray:
        """(3 legs, len(fractions), n_modes): rotation of the legs' sections about the axis."""
        ...

    def write_vtu(self, path, pvd: bool = False) -> None:
        """The mode shapes for ParaView (and with `pvd` the .pvd collection beside them)."""
        ...

    def to_dict(self) -> dict:
        """The plain record of the solve (`solve_record`)."""
        ...


def solve_record(result, **extra) -> dict:
    """The plain record of a solve (any `FemAnswer`) and its extras."""
    return {
        "frequencies_hz": [float(f) for f in result.frequencies_hz],
        "dofs": result.dofs,
        "raw_dofs": result.raw_dofs,
        "mesh_size_m": result.mesh_size,
        "elements": result.n_elements,
        "min_scaled_jacobian": result.min_quality,
        "timings": dict(result.timings),
        "clusters": result.clusters,
        "cache_hit": result.cache_hit,
        "mesh_digest": result.mesh_digest,
        "platform": result.options.platform,
        "coupling": result.options.coupling,
        "legs": result.options.legs,
        **extra,
    }


def section_arms(axis: np.ndarray, radius: float, count: int = 6) -> np.ndarray:
    """(count, 3): points at `radius` from a section's centre, evenly around `axis`. The mean
    tangential displacement over `count` such points sees harmonics 0 (the twist) and
    multiples of `count` only: six keeps section distortions up to n = 5 out of the twist."""
    axis = np.asarray(axis, float)
    e1 = np.cross(axis, np.eye(3)[np.argmin(np.abs(axis))])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    angles = 2 * np.pi * np.arange(count) / count
    return radius * (np.cos(angles)[:, None] * e1 + np.sin(angles)[:, None] * e2)


def twist_from_section(axis: np.ndarray, arms: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Section rotation about `axis` from displacements u (..., k, 3, m) at `arms` (k, 3):
    mean over the points of axis . (arm x u) / |arm|^2 (translations and bending cancel in
    the mean over points evenly around the axis)."""
    cross = np.cross(arms[:, :, None], u, axis=-2)  # (..., k, 3, m)
    return np.einsum("c,...kcm->...m", np.asarray(axis, float), cross) / (
        len(arms) * float(np.sum(arms[0] ** 2)))


def station_fractions(fractions) -> np.ndarray:
    """The fractions t of a leg (B_i -> A_i) where shapes are sampled, checked to lie in
    [0, 1] (FemError naming them)."""
    t = np.atleast_1d(np.asarray(fractions, float))
    if t.ndim != 1 or np.any(~np.isfinite(t)) or np.any(t < 0) or np.any(t > 1):
        raise FemError(f"fractions = {np.asarray(fractions).tolist()!r}: need values in [0, 1]")
    return t


def normalise_signs(v: np.ndarray) -> np.ndarray:
    """Deterministic sign: the largest-magnitude entry of every mode is positive."""
    idx = np.argmax(np.abs(v), axis=0)
    s = np.sign(v[idx, np.arange(v.shape[1])])
    s[s == 0] = 1
    return v * s

