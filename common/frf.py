"""Dynamic compliance at the tool: damping and the tool point declared once, and the receptance
of a structure from its modes, shared by both models and the FEM (the formulas are textbook
structural dynamics, checked against closed forms in tests/test_frf.py; each model brings its
own modes and its own static solve).

The tool point t is fixed to the rigid platform at `point` (platform frame, from o). A force F
at t and its displacement u_t, in base coordinates: u_t = Delta + Phi x r = A q_p with
r = R point, A = [I, -[r x]] on the platform's six coordinates q_p = (Delta, Phi) of o, and the
generalised force of F is A^T F. With mass-normalised modes x_j (omega_j, zeta_j) the tool's
modal vector is phi_j = A x_j (3,), and its receptance (m/N), viscously damped mode by mode,

    H(w) = sum_j phi_j phi_j^T / (omega_j^2 - w^2 + 2 i zeta_j omega_j w)  +  R,

    R = G0 - sum_j phi_j phi_j^T / omega_j^2,    G0 = A K^-1 A^T  (the static compliance),

so the modes left out of the sum enter by their static flexibility (the residual flexibility,
"mode acceleration") and H(0) = G0 exactly. Per mode and direction d: the modal stiffness at
the tool k_dj = omega_j^2 / phi_dj^2 and the effective (modal) mass m_dj = 1 / phi_dj^2, the
single-degree-of-freedom system the mode is along d at t (a chatter model's input); a mode
that does not move t along d has them infinite (reported as None).

Damping is proportional (the modes stay real): a ratio per mode (`modal_ratio`), or Rayleigh's
C = alpha M + beta K, for which zeta_j = alpha / (2 omega_j) + beta omega_j / 2 exactly.
The least dynamic stiffness along d is 1 / max_w |H_dd(w)| over the band, at the peak's
frequency, with the mode whose term is largest there (the dominant mode).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import InputError
from .messages import short
from .rigid_body import skew
from .settings import MAX_LENGTH, check_settings, setting

DEFAULT_RATIO = 0.02  # measured on PKM and robot structures: about 2-4 % (the low end)
MIN_RATIO, MAX_RATIO = 1e-4, 0.5  # below, a peak no line resolves; above, no peak worth one
DIRECTIONS = ("x", "y", "z")
LINES = 2000  # frequency lines of a band, default
BAND_ABOVE = 1.25  # the band's top: this times the highest compared mode
REFINE = 20  # the best line's neighbourhood re-sampled this many times finer


@dataclass(frozen=True)
class Damping:
    """[damping]: viscous, proportional (real modes). Give modal_ratio, or the Rayleigh pair,
    not both; with neither, every mode has 2 %."""

    modal_ratio: tuple[float, ...] = setting(
        (), kind=tuple, minimum=MIN_RATIO, maximum=MAX_RATIO,
        doc="damping ratio zeta of every mode (a number), or one per mode from the first (a "
        "list; modes beyond the list take its last value). Neither this nor the Rayleigh pair: "
        f"{DEFAULT_RATIO:g} for every mode, the low end of the 2-4 % measured on parallel "
        "machines and robots")
    rayleigh_alpha: float = setting(
        0.0, unit="1/s", minimum=0.0, maximum=1e4,
        doc="Rayleigh damping C = alpha M + beta K, mass part: zeta_j = alpha / (2 omega_j) + "
        "beta omega_j / 2")
    rayleigh_beta: float = setting(
        0.0, unit="s", minimum=0.0, maximum=1e-2, doc="Rayleigh damping, stiffness part")

    def __post_init__(self) -> None:
        check_settings(self)
        if self.modal_ratio and self.rayleigh:
            raise InputError(f"damping.modal_ratio = {list(self.modal_ratio)} with "
                             "rayleigh_alpha_per_s / rayleigh_beta_s: give one damping, not both")

    @property
    def rayleigh(self) -> bool:
        return self.rayleigh_alpha > 0.0 or self.rayleigh_beta > 0.0

    @property
    def declared(self) -> bool:
        return bool(self.modal_ratio) or self.rayleigh

    def ratios(self, omega) -> np.ndarray:
        """zeta of modes with circular frequencies `omega` (..., m), lowest first."""
        omega = np.asarray(omega, float)
        if self.rayleigh:
            return self.rayleigh_alpha / (2.0 * omega) + 0.5 * self.rayleigh_beta * omega
        listed = np.asarray(self.modal_ratio or (DEFAULT_RATIO,), float)
        index = np.minimum(np.arange(omega.shape[-1]), len(listed) - 1)
        return np.broadcast_to(listed[index], omega.shape).copy()

    def check_table(self, typed: dict, where: str) -> None:
        """Refuse a [damping] table (its keys as typed) that declares no damping: an undamped
        structure's response is infinite at every resonance, and the default is for a scene
        without the table."""
        if not self.declared:
            keys = ", ".join(f"{k} = {short(v)}" for k, v in typed.items()) or "no key"
            raise InputError(f"{where}: {keys}: the table declares no damping (an undamped "
                             "structure's response is infinite at every resonance); give "
                             "modal_ratio, or a positive rayleigh_alpha_per_s or "
                             "rayleigh_beta_s, or leave [damping] out for the default "
                             f"{DEFAULT_RATIO:.0%} of every mode")

    def describe(self) -> str:
        if self.rayleigh:
            return (f"Rayleigh, alpha = {self.rayleigh_alpha:g} 1/s, beta = "
                    f"{self.rayleigh_beta:g} s")
        if not self.modal_ratio:
            return f"modal ratio {DEFAULT_RATIO:g} for every mode (no [damping]: the default)"
        if len(self.modal_ratio) == 1:
            return f"modal ratio {self.modal_ratio[0]:g} for every mode"
        return "modal ratios " + ", ".join(f"{z:g}" for z in self.modal_ratio) + " (last repeats)"


def rayleigh_damping(alpha: float, beta: float) -> Damping:
    """A Rayleigh damping the pipeline derives (the direct check's): its alpha and beta are
    not a scene's keys, so the keys' ranges do not bound them (a machine of high modes takes
    a large alpha, one of low modes a large beta)."""
    damping = object.__new__(Damping)
    for name, value in (("modal_ratio", ()), ("rayleigh_alpha", float(alpha)),
                        ("rayleigh_beta", float(beta))):
        object.__setattr__(damping, name, value)
    if not (damping.rayleigh and math.isfinite(alpha) and math.isfinite(beta)
            and alpha >= 0.0 and beta >= 0.0):
        raise InputError(f"rayleigh_damping({alpha!r}, {beta!r}): need finite alpha, beta >= 0, "
                         "not both 0")
    return damping


REPEATED = 1e-6  # modes this close (relative) are one repeated group, any basis of it a mode


def canonical_groups(omega, phi) -> tuple[np.ndarray, list[list[int]]]:
    """The tool shapes phi (3, m) with every repeated group (frequencies within REPEATED)
    turned to its principal basis at the tool (the right singular vectors of its 3 x k block:
    the first member moves the tool most, the next least in its direction, and so on), signs
    with the largest component positive: the per-mode table no longer depends on the basis
    an eigen solver happened to return (the receptance never did). Returns (phi, groups)."""
    omega, phi = np.asarray(omega, float), np.array(phi, float)
    groups: list[list[int]] = []
    for j in range(len(omega)):
        if groups and omega[j] - omega[groups[-1][-1]] <= REPEATED * omega[j]:
            groups[-1].append(j)
        else:
            groups.append([j])
    for g in groups:
        if len(g) > 1:
            u, sv, _ = np.linalg.svd(phi[:, g], full_matrices=False)
            block = u * sv  # (3, min(3, k)): principal tool motions of the group
            out = np.zeros((3, len(g)))
            out[:, :block.shape[1]] = block
            phi[:, g] = out
        for j in g:
            big = int(np.argmax(np.abs(phi[:, j])))
            if phi[big, j] < 0.0:
                phi[:, j] = -phi[:, j]
    return phi, groups


def whole_groups(omega, phi, next_omega) -> tuple[np.ndarray, float]:
    """The summed modes (omega (m,), phi (3, m)) with a repeated group that the cut splits
    (its first left-out member `next_omega` within REPEATED of the last summed) left out
    whole: the summed members' tool shapes zeroed (the residual flexibility then holds the
    group statically, whatever basis the solver returned) and the band's stop moved to the
    group. Returns (phi, the first frequency left out)."""
    omega, phi = np.asarray(omega, float), np.array(phi, float)
    after = float(next_omega)
    if not math.isfinite(after):
        return phi, after
    j = len(omega)
    while j > 0 and after - omega[j - 1] <= REPEATED * after:
        j -= 1
        after = float(omega[j])
    phi[:, j:] = 0.0
    return phi, after


def tidy_groups(omega, phi, next_omega) -> tuple[np.ndarray, float]:
    """Summed tool shapes with a split repeated group left out whole (`whole_groups`) and
    every repeated group in its principal basis (`canonical_groups`): what every model's
    modes at the tool go through. Returns (phi, the first frequency left out)."""
    phi, after = whole_groups(omega, phi, next_omega)
    return canonical_groups(omega, phi)[0], after


def rayleigh_through(omega_low: float, omega_high: float, zeta: float) -> tuple[float, float]:
    """(alpha, beta) of the Rayleigh damping with ratio `zeta` at both circular frequencies
    (equal to it there, below it between them): the damping matrix C = alpha M + beta K
    a direct (non-modal) solve needs for a modal ratio."""
    if not 0.0 < omega_low <= omega_high:
        raise InputError(f"rayleigh_through: need 0 < {omega_low:g} <= {omega_high:g} rad/s")
    if omega_high <= omega_low * (1.0 + 1e-9):
        return 0.0, 2.0 * zeta / omega_low  # one frequency: stiffness-proportional alone
    total = omega_low + omega_high
    return 2.0 * zeta * omega_low * omega_high / total, 2.0 * zeta / total


@dataclass(frozen=True)
class Tool:
    """[tool]: where the force acts and the response is read."""

    point: tuple[float, float, float] = setting(
        (0.0, 0.0, 0.0), kind=tuple, unit="mm", length=3, minimum=-MAX_LENGTH,
        maximum=MAX_LENGTH, doc="the tool point in the platform frame, from the platform centre "
        "o (z along the platform normal): where the force acts and the receptance is read "
        "(default: o)")

    def __post_init__(self) -> None:
        check_settings(self)


def tool_rows(point, rotation) -> np.ndarray:
    """A (3, 6) (or (..., 3, 6) for a stack of rotations): the tool point's displacement in base
    coordinates from the platform's (Delta, Phi) of o, u_t = Delta - [r x] Phi, r = R point."""
    rotation = np.asarray(rotation, float)
    arm = rotation @ np.asarray(point, float)
    out = np.zeros(arm.shape[:-1] + (3, 6))
    out[..., :, :3] = np.eye(3)
    out[..., :, 3:] = -skew(arm)
    return out


def residual_flexibility(static, omega, phi) -> np.ndarray:
    """R = G0 - sum_j phi_j phi_j^T / omega_j^2: what the modes left out add at low frequency.
    static (..., 3, 3), omega (..., m), phi (..., 3, m)."""
    phi = np.asarray(phi, float)
    return np.asarray(static, float) - np.einsum("...dj,...ej,...j->...de", phi, phi,
                                                 1.0 / np.asarray(omega, float) ** 2)


def modal_terms(lines_hz, omega, zeta) -> np.ndarray:
    """1 / (omega_j^2 - w^2 + 2 i zeta_j omega_j w): (..., nf, m) for lines (..., nf) Hz and
    modes (..., m)."""
    w = 2.0 * math.pi * np.asarray(lines_hz, float)[..., :, None]
    omega, zeta = np.asarray(omega, float)[..., None, :], np.asarray(zeta, float)[..., None, :]
    return 1.0 / (omega**2 - w**2 + 2j * zeta * omega * w)


def receptance(lines_hz, omega, zeta, phi, residual) -> np.ndarray:
    """H (nf, 3, 3) complex, m/N, at the lines (Hz): the module docstring's sum plus R."""
    terms = modal_terms(lines_hz, omega, zeta)  # (nf, m)
    phi = np.asarray(phi, float)
    return np.einsum("fj,dj,ej->fde", terms, phi, phi) + np.asarray(residual, float)[None]


def modal_table(omega, zeta, phi, static=None) -> list[dict]:
    """Per mode: frequency (Hz), damping ratio, and along x, y, z at the tool the modal
    stiffness omega^2 / phi_d^2 (N/m) and effective mass 1 / phi_d^2 (kg), None where the mode
    does not move the tool along d (phi_d^2 below 1e-12 of the mode's largest, or its static
    share phi_d^2 / omega^2 below 1e-10 of the tool's static compliance `static` along d: the
    round-off of a mode that leaves the tool still), and the mass-normalised mode's
    displacement phi_d itself (1 / sqrt(kg): signed, so the cross receptances
    phi_x phi_y / (...) follow too)."""
    omega, zeta, phi = (np.asarray(a, float) for a in (omega, zeta, phi))
    share = None if static is None else np.diagonal(np.asarray(static, float))
    out = []
    for j in range(len(omega)):
        sq = phi[:, j] ** 2
        floor = 1e-12 * max(float(sq.max()), 1e-300)
        stiff, mass = {}, {}
        for d, name in enumerate(DIRECTIONS):
            moves = sq[d] > floor and (share is None  # against the tool's static compliance:
                                       or sq[d] / omega[j] ** 2 > 1e-10 * share[d])  # not noise
            stiff[name] = float(omega[j] ** 2 / sq[d]) if moves else None
            mass[name] = float(1.0 / sq[d]) if moves else None
        out.append({"frequency_hz": float(omega[j] / (2.0 * math.pi)),
                    "damping_ratio": float(zeta[j]), "modal_stiffness_n_per_m": stiff,
                    "effective_mass_kg": mass,
                    "tool_shape_per_sqrt_kg": {name: float(phi[d, j])
                                               for d, name in enumerate(DIRECTIONS)}})
    return out


def band_top(frequencies_hz, compared: int, next_hz=np.inf, next_zeta=0.0) -> np.ndarray:
    """The band's top (Hz) for modes (..., m) summed of which the first `compared` are
    compared: BAND_ABOVE times the highest compared, and below the resonance of the first
    mode left out (`next_hz`, by its half-power band and two more: next_hz / (1 + 3 zeta);
    inf: none left out), so every
    mode that resonates in the band is in the sum and those left out enter by their static
    flexibility, what they are below their resonance (a repeated pair split by the cut is
    left out whole)."""
    f = np.asarray(frequencies_hz, float)
    after = np.asarray(next_hz, float)
    with np.errstate(invalid="ignore"):  # inf / inf where nothing is left out
        cut = np.where(np.isfinite(after), after / (1.0 + 3.0 * np.asarray(next_zeta, float)),
                       np.inf)
    return np.minimum(BAND_ABOVE * f[..., min(compared, f.shape[-1]) - 1], cut)


def summed_band_top(omega, compared: int, next_omega, damping: Damping) -> np.ndarray:
    """`band_top` of summed modes omega (..., m) rad/s whose first left out is `next_omega`
    (..., inf: none), its ratio from `damping` as the (m + 1)-th mode's."""
    omega, after = np.asarray(omega, float), np.asarray(next_omega, float)
    with np.errstate(invalid="ignore"):  # a ratio at inf (nothing left out): masked below
        zeta = damping.ratios(np.concatenate([omega, after[..., None]], axis=-1))[..., -1]
    return band_top(omega / (2.0 * math.pi), compared, after / (2.0 * math.pi), zeta)


def band_lines(top_hz, count: int = LINES) -> np.ndarray:
    """`count` lines from 0 to `top_hz` (..., broadcast): (..., count)."""
    if count < 3:
        raise InputError(f"lines = {count}: need at least 3 frequency lines")
    return np.asarray(top_hz, float)[..., None] * np.linspace(0.0, 1.0, count)


@dataclass(frozen=True)
class LeastStiffness:
    """Per pose and direction (N, 3): 1 / max |H_dd| over the band (N/m), the peak's
    frequency (Hz) and the dominant mode there (0-based)."""

    stiffness_n_per_m: np.ndarray
    peak_hz: np.ndarray
    mode: np.ndarray


def _squared(lines_hz, omega, zeta, sq_t, residual, dtype) -> np.ndarray:
    """|H_dd|^2 (c, k, 3) on lines (c, k) Hz of modes omega, zeta (c, m) with squared tool
    components sq_t (c, m, 3) and the residual's diagonal (c, 3), in `dtype`: the terms
    1 / (a + i b) = (a - i b) / (a^2 + b^2) in real arrays, two batched products."""
    w = (2.0 * math.pi * lines_hz[:, :, None]).astype(dtype)  # (c, k, 1)
    om = omega[:, None, :].astype(dtype)  # (c, 1, m)
    a = om * om - w * w
    b = (2.0 * zeta[:, None, :].astype(dtype) * om) * w
    inv = a * a
    inv += b * b
    np.reciprocal(inv, out=inv)
    a *= inv
    b *= inv
    sq_t = sq_t.astype(dtype)
    re = np.matmul(a, sq_t)
    re += residual[:, None, :].astype(dtype)
    im = np.matmul(b, sq_t)
    re *= re
    im *= im
    re += im
    return re


def least_dynamic_stiffness(lines_hz, omega, zeta, phi, residual_diag,
                            chunk: int = 32) -> LeastStiffness:
    """The least dynamic stiffness along x, y, z of N poses (lines (N, nf) Hz; modes omega,
    zeta (N, m); phi (N, 3, m); the residual's diagonal (N, 3)): |H_dd| on every line and at
    every mode's damped peak w_j sqrt(1 - 2 zeta_j^2) inside the band (a peak narrower than
    the lines' spacing is not missed between them), the largest taken, then its neighbourhood
    (a line spacing, or three half-power half-widths zeta f if narrower, either side) searched
    twice REFINE times finer, each search around the previous one's best: the peak's height
    to (spacing / 20 REFINE)^2 of it. The scan picks the largest in single precision (twice
    the speed; a candidate within 1e-6 of the largest may be picked, and the refinement, in
    double precision, finds the same peak); the values returned are double. Batched in
    chunks of poses so the (chunk, nf, m) terms stay in cache."""
    lines_hz, omega, zeta, phi, residual_diag = (
        np.asarray(a, float) for a in (lines_hz, omega, zeta, phi, residual_diag))
    n, nf = lines_hz.shape
    stiffness, peak, mode = (np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3), int))
    sq_t = np.swapaxes(phi**2, 1, 2)  # (N, m, 3)
    steps = np.linspace(-1.0, 1.0, 2 * REFINE + 1)
    damped = omega * np.sqrt(np.clip(1.0 - 2.0 * zeta**2, 0.0, None)) / (2.0 * math.pi)
    inside = np.where((damped > lines_hz[:, :1]) & (damped < lines_hz[:, -1:]), damped,
                      lines_hz[:, -1:])  # a damped peak outside the band: its last line
    spacing = (lines_hz[:, -1] - lines_hz[:, 0]) / max(nf - 1, 1)
    for start in range(0, n, chunk):
        s = slice(start, min(n, start + chunk))
        c = s.stop - s.start
        rows = np.arange(c)
        candidates = np.concatenate([lines_hz[s], inside[s]], axis=1)  # (c, nf + m)
        best = np.argmax(_squared(candidates, omega[s], zeta[s], sq_t[s], residual_diag[s],
                                  np.float32), axis=1)  # (c, 3)
        for d in range(3):
            centre = candidates[rows, best[:, d]]
            near = np.argmin(np.abs(omega[s] / (2.0 * math.pi) - centre[:, None]), axis=1)
            width = np.minimum(spacing[s], 3.0 * zeta[s][rows, near] * centre)
            for _ in range(2):
                fine = np.clip(centre[:, None] + width[:, None] * steps, lines_hz[s][:, :1],
                               lines_hz[s][:, -1:])
                h2 = _squared(fine, omega[s], zeta[s], sq_t[s], residual_diag[s],
                              np.float64)[..., d]
                k = np.argmax(h2, axis=1)
                centre, width = fine[rows, k], width / REFINE
            with np.errstate(divide="ignore"):  # a direction nothing moves: infinitely stiff
                stiffness[s, d] = 1.0 / np.sqrt(h2[rows, k])
            peak[s, d] = centre
        terms = modal_terms(peak[s][:, :, None], omega[s][:, None, :], zeta[s][:, None, :])
        contrib = np.abs(terms[:, :, 0, :] * np.swapaxes(sq_t[s], 1, 2))  # (c, 3, m)
        mode[s] = np.argmax(contrib, axis=-1)
    return LeastStiffness(stiffness, peak, mode)
