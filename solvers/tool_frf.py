"""The dynamic compliance at the tool of one pose: each model's modes at the tool point with
its static compliance (`ToolModel`: receptance, modal table, peaks, least dynamic stiffness,
by `common.frf`), the frf.json record, and the solid's direct frequency response that checks
both models (`direct_check`).

The band: 0 to BAND_ABOVE times the model's highest compared mode (the scene's
fidelity.modes), LINES lines. The sum: every mode the model solved (the analytical model the
compared ones and SUPERPOSED_EXTRA more; the FEM its solved modes), the rest by their residual
flexibility from the model's own static solve, so the 0 Hz line is the static compliance.

The direct check damps all three alike: C = alpha M + beta K, the scene's Rayleigh pair, or
for a modal ratio the pair through it at the FEM's first and highest compared mode
(`common.frf.rayleigh_through`); each model's zeta_j follow from its own omega_j, so a
difference is the models', not the damping's.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import cast

import numpy as np

from analytical.kinematics import PoseGeometry
from analytical.params import Manipulator, ModelOptions
from analytical.substructure import assemble, model_coordinates
from analytical.tool_response import SUPERPOSED_EXTRA, ToolModes, tool_modes
from common.frf import (
    DIRECTIONS,
    LINES,
    Damping,
    band_lines,
    least_dynamic_stiffness,
    modal_table,
    rayleigh_damping,
    rayleigh_through,
    receptance,
    residual_flexibility,
    summed_band_top,
    tidy_groups,
)
from common.frf_peaks import (
    DIRECT_FLOOR,
    PEAK_FLOOR,
    Peak,
    direct_peaks,
    find_peaks,
    peak_windows,
)
from results.tool_records import FrfMode, FrfRecord, Receptance

PAIRS = ("xx", "yy", "zz", "xy", "xz", "yz")


@dataclass(frozen=True)
class ToolModel:
    """One model's dynamic compliance at the tool of one pose."""

    label: str
    modes: ToolModes
    damping: Damping
    compared: int  # the scene's compared modes: the band's top is BAND_ABOVE x f_compared
    factor_entries: int = 0  # the FEM's: its static factor's entries (the direct check's memory)

    @property
    def residual(self) -> np.ndarray:
        return residual_flexibility(self.modes.static, self.modes.omega, self.modes.phi)

    @property
    def zeta(self) -> np.ndarray:
        return self.damping.ratios(self.modes.omega)

    @property
    def band_top_hz(self) -> float:
        return float(summed_band_top(self.modes.omega, self.compared, self.modes.next_omega,
                                     self.damping))

    def lines(self, count: int = LINES, top_hz: float | None = None) -> np.ndarray:
        return band_lines(self.band_top_hz if top_hz is None else top_hz, count)

    def receptance(self, lines_hz) -> np.ndarray:
        return receptance(lines_hz, self.modes.omega, self.zeta, self.modes.phi, self.residual)

    def table(self) -> list[dict]:
        return modal_table(self.modes.omega, self.zeta, self.modes.phi, self.modes.static)

    def windows(self, direction: int, floor: float = PEAK_FLOOR
                ) -> list[tuple[int, float, float]]:
        return peak_windows(self.modes.omega, self.zeta, self.modes.phi, direction, floor)

    def peaks(self, direction: int, floor: float = PEAK_FLOOR) -> list[Peak]:
        """The peaks of |H_dd| (Brent on the modal sum, cheap)."""
        return find_peaks(lambda f: abs(self.receptance([f])[0, direction, direction]),
                          self.windows(direction, floor))

    def least(self, count: int = LINES, lines_hz=None):
        """The least dynamic stiffness along x, y, z over the band, or over `lines_hz`
        (`common.frf`)."""
        m = self.modes
        lines = self.lines(count) if lines_hz is None else np.asarray(lines_hz, float)
        return least_dynamic_stiffness(lines[None], m.omega[None],
                                       self.zeta[None], m.phi[None],
                                       np.diagonal(self.residual)[None])


def analytical_tool(manipulator: Manipulator, geometry: PoseGeometry, options: ModelOptions,
                    damping: Damping, point, compared: int, label: str = "analytical"
                    ) -> ToolModel:
    """The analytical model's: its compared modes and SUPERPOSED_EXTRA more (at most every
    coordinate's)."""
    model = assemble(manipulator, geometry, options)
    count = min(compared + SUPERPOSED_EXTRA, model_coordinates(manipulator, options))
    modes = tool_modes(model, geometry.rotation, point, count)
    return ToolModel(label, modes, damping, compared)


def fem_tool(result, damping: Damping, point, compared: int, label: str = "FEM") -> ToolModel:
    """The solid's modal sum: its solved modes (M-orthonormal) at the tool and its static
    compliance (one sparse factorisation)."""
    from fem_reference.response import static_compliance, tool_operator

    a = tool_operator(result, point)
    omega = 2.0 * math.pi * np.asarray(result.frequencies_hz, float)
    static, entries = static_compliance(result, a)
    phi = np.asarray(a @ result.modes_q)  # the last solved mode: where the band must stop
    phi, after = tidy_groups(omega[:-1], phi[:, :-1], float(omega[-1]))
    modes = ToolModes(omega[:-1], phi, static, after)
    return ToolModel(label, modes, damping, compared, entries)


def fem_tool_at(manipulator, geometry, options, runtime, damping: Damping, point,
                compared: int) -> ToolModel:
    """The solid's modal sum at one pose, solved at `options` (its mesh)."""
    from fem_reference import solve_pose

    return fem_tool(solve_pose(manipulator, geometry, options, runtime, keep_system=True),
                    damping, point, compared, label=f"FEM ({options.mesh.size * 1e3:g} mm)")


def two_mesh_percent(fine, coarse, ratio: float) -> np.ndarray:
    """The FEM's two-mesh error estimate of a quantity (%): the larger of Richardson's step
    and the GCI, as for the frequencies."""
    from fem_reference.convergence import two_mesh_error, two_mesh_gci

    pair = (np.abs(np.asarray(fine, float)), np.abs(np.asarray(coarse, float)), ratio)
    return np.maximum(two_mesh_error(*pair), two_mesh_gci(*pair))


def check_damping(damping: Damping, fem: ToolModel) -> Damping:
    """The Rayleigh damping all three share in the direct check (module docstring)."""
    if damping.rayleigh:
        return damping
    f = fem.modes.omega
    top = min(fem.compared, len(f)) - 1
    zeta = damping.ratios(f)
    alpha, beta = rayleigh_through(float(f[0]), float(f[top]), float(np.mean(zeta[:top + 1])))
    return rayleigh_damping(alpha, beta)


def with_damping(model: ToolModel, damping: Damping) -> ToolModel:
    return replace(model, damping=damping)


def direct_check(result, fem: ToolModel, damping: Damping, point) -> dict[int, list[Peak]]:
    """The solid's direct response at its peaks (`common.frf.direct_peaks`), damped by the
    Rayleigh `damping`, in the windows of its own modal sum; its memory checked first
    (MemoryLimitError)."""
    from fem_reference.response import check_direct_memory, direct_receptance, tool_operator

    check_direct_memory(result, fem.factor_entries)
    a = tool_operator(result, point)
    fem = with_damping(fem, damping)
    windows = {d: fem.windows(d, DIRECT_FLOOR) for d in range(3)}

    def solve(f: float) -> np.ndarray:
        return direct_receptance(result, a, [f], damping.rayleigh_alpha,
                                 damping.rayleigh_beta)[0]

    return direct_peaks(solve, windows, fem.modes.omega, fem.zeta)


def _finite(value) -> float | None:
    """A number for JSON: None where nothing moves the tool that way (infinitely stiff)."""
    return float(value) if math.isfinite(value) else None


def _pair_values(h: np.ndarray) -> dict[str, Receptance]:
    index = {"x": 0, "y": 1, "z": 2}
    return {p: {"re": h[:, index[p[0]], index[p[1]]].real.tolist(),
                "im": h[:, index[p[0]], index[p[1]]].imag.tolist()} for p in PAIRS}


def frf_record(tool: ToolModel, point_mm, damping: Damping, lines_hz) -> FrfRecord:
    """frf.json's physics (the command adds the scene, case and pose)."""
    h = tool.receptance(lines_hz)
    least = tool.least(lines_hz=lines_hz)
    static = tool.modes.static
    return {
        "model": tool.label,
        "convention": "H(f) = sum over modes of phi phi^T / (w_j^2 - w^2 + 2 i zeta_j w_j w) "
                      "+ residual_flexibility_m_per_n, w = 2 pi f, phi = tool_shape_per_sqrt_kg "
                      "(base frame); the residual is the static compliance less the modes' "
                      "sum of phi phi^T / w_j^2 (the modes not summed, quasi-static: exact at "
                      "0 Hz, short of their dynamic part near the band's top, which stops "
                      "below the first one's resonance); modal stiffness w_j^2 / phi_d^2, "
                      "effective mass 1 / phi_d^2 (null: the mode leaves the tool still "
                      "that way); a repeated group in its principal basis at the tool",
        "point_mm": [float(v) for v in point_mm],
        "damping": damping.describe(),
        "frequency_hz": [float(f) for f in lines_hz],
        "receptance_m_per_n": _pair_values(h),
        "static_compliance_m_per_n": static.tolist(),
        "modes_superposed": int(len(tool.modes.omega)),
        "residual_flexibility_m_per_n": tool.residual.tolist(),
        "modes": cast(list[FrfMode], tool.table()),  # common.frf.modal_table's rows
        "peaks": {DIRECTIONS[d]: [{"frequency_hz": p.frequency_hz,
                                   "magnitude_m_per_n": p.magnitude_m_per_n,
                                   "mode": p.mode + 1} for p in tool.peaks(d)]
                  for d in range(3)},
        "least_dynamic_stiffness": {
            DIRECTIONS[d]: {"stiffness_n_per_m": _finite(least.stiffness_n_per_m[0, d]),
                            "frequency_hz": float(least.peak_hz[0, d]),
                            "mode": int(least.mode[0, d]) + 1} for d in range(3)},
    }


@dataclass(frozen=True)
class FemCheck:
    """The solid at one pose for the direct check: its modal sum at the run's size and one
    size coarser, the Rayleigh damping all three share, its direct response's peaks (empty,
    with the reason, when its memory would not allow them)."""

    fem: ToolModel
    coarse: ToolModel
    damping: Damping
    direct: dict[int, list[Peak]]
    not_solved: str | None
    ratio: float  # coarse size / size

    def two_mesh_percent(self, fine, coarse) -> np.ndarray:
        """The FEM's estimated error (%) of positive quantities of the two meshes: the larger
        of Richardson's step and the GCI at the rims' order, as for its frequencies."""
        return two_mesh_percent(fine, coarse, self.ratio)


def fem_check(manipulator, geometry, damping: Damping, point, compared: int, fine_options,
              coarse_options, runtime) -> FemCheck:
    """The FEM's side of the direct check (module docstring): two solves, the direct response
    at the fine one's peaks (its complex factors' memory checked first)."""
    from fem_reference import solve_pose
    from fem_reference.resources import MemoryLimitError

    fine = solve_pose(manipulator, geometry, fine_options, runtime, keep_system=True)
    fem = fem_tool(fine, damping, point, compared)
    shared = check_damping(damping, fem)
    not_solved = None
    try:
        direct = direct_check(fine, fem, shared, point)
    except MemoryLimitError as exc:  # a side study's budget: said, not fatal to the run
        direct, not_solved = {}, f"the solid's direct response was not solved: {exc}"
    del fine  # its matrices are large: the coarse solve need not hold both
    coarse = fem_tool(solve_pose(manipulator, geometry, coarse_options, runtime,
                                 keep_system=True), damping,
                      point, compared)
    return FemCheck(fem, coarse, shared, direct, not_solved,
                    coarse_options.mesh.size / fine_options.mesh.size)
