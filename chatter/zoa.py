"""The zero-order method (Altintas & Budak, CIRP Annals 44:357, 1995): the cutting-force matrix
averaged over a tooth period, F = b A0 (r(t) - r(t - tau)), so chatter at w_c needs

    det(I - b (1 - e^{-i w_c tau}) A0 G(i w_c)) = 0.

With lambda an eigenvalue of A0 G(w_c), b (1 - e^{-i w tau}) = 1 / lambda has a real positive b
only for Re lambda > 0, and then, with kappa = Im lambda / Re lambda,

    b_lim = 1 / (2 Re lambda),   w_c tau = eps + 2 pi k,   eps = pi + 2 atan(kappa),   k = 0, 1, ...

(our sign convention: A0 holds the minus sign Altintas writes in front of Lambda). At a speed
the critical depth is the least b_lim over every lobe k and eigenvalue branch whose phase
condition holds there: found as the crossings of (w tau - eps) / (2 pi) with integers on a fine
grid of chatter frequencies, refined linearly. Hopf lobes only: the average cannot see the
period-doubling (flip) lobes of a low immersion."""
from __future__ import annotations

import math

import numpy as np

from .milling import ToolModes

# chatter frequencies per mode's neighbourhood and over the whole range (a lobe's depth is read
# linearly between two: 4,000 over the range left 0.2 % on a lobe's flank, 40,000 0.002 %)
GRID_PER_MODE = 10_000
GRID_BASE = 40_000
CHUNK = 16  # speeds a pass (bounds the (speeds, frequencies) arrays)


def chatter_grid(modes: ToolModes) -> np.ndarray:
    """Circular frequencies where a lobe may lie: dense about every mode (+-40 half-power
    bandwidths) over a log-spaced base from 0.2 to 3 times the modes' range."""
    w = modes.omega
    base = np.geomspace(0.2 * w.min(), 3.0 * w.max(), GRID_BASE)
    near = [wj * (1.0 + np.linspace(-1, 1, GRID_PER_MODE) * min(0.9, 40 * zj))
            for wj, zj in zip(w, modes.zeta, strict=True)]
    return np.unique(np.concatenate([base, *near]))


def branches(a0: np.ndarray, modes: ToolModes, w: np.ndarray) -> np.ndarray:
    """The two eigenvalues of A0 G(w) (nw, 2), in a continuous order (swapped where that keeps
    them closer to the previous line's)."""
    m = np.einsum("de,fek->fdk", a0, modes.receptance(w))
    tr = m[:, 0, 0] + m[:, 1, 1]
    det = m[:, 0, 0] * m[:, 1, 1] - m[:, 0, 1] * m[:, 1, 0]
    root = np.sqrt(tr**2 / 4 - det)
    lam = np.stack([tr / 2 + root, tr / 2 - root], 1)
    same = np.abs(np.diff(lam[:, 0])) + np.abs(np.diff(lam[:, 1]))
    cross = np.abs(lam[1:, 0] - lam[:-1, 1]) + np.abs(lam[1:, 1] - lam[:-1, 0])
    parity = np.concatenate([[0], np.cumsum(cross < same) % 2]).astype(bool)
    lam[parity] = lam[parity, ::-1]  # each branch continuous from line to line
    return lam


def zoa_depths(a0: np.ndarray, modes: ToolModes, speeds_hz, teeth: int
               ) -> tuple[np.ndarray, np.ndarray]:
    """The zero-order critical depth (m) and its chatter frequency (Hz) at each spindle speed
    (rev/s); inf where no lobe reaches the speed (a cut that excites nothing)."""
    speeds = np.asarray(speeds_hz, float)
    w = chatter_grid(modes)
    lam = branches(a0, modes, w)
    tau = 1.0 / (teeth * speeds)  # (ns,)
    depth = np.full(len(speeds), np.inf)
    freq = np.full(len(speeds), np.nan)
    for b in range(2):
        lr, li = lam[:, b].real, lam[:, b].imag
        ok = lr > 0.0
        if not ok.any():
            continue
        safe = np.where(ok, lr, 1.0)
        eps = np.where(ok, math.pi + 2.0 * np.arctan(li / safe), np.nan)
        blim = np.where(ok, 1.0 / (2.0 * safe), np.inf)
        pair = ok[1:] & ok[:-1] & (np.abs(np.diff(np.where(ok, eps, 0.0))) < 1.0)
        for chunk in range(0, len(speeds), CHUNK):  # a branch that jumps holds no lobe
            part = slice(chunk, chunk + CHUNK)
            k = (w[None, :] * tau[part, None] - eps[None, :]) / (2 * math.pi)  # (ns, nw)
            fk = np.floor(np.where(np.isfinite(k), k, -1.0))
            si, wi = np.nonzero((fk[:, 1:] != fk[:, :-1]) & pair[None, :])
            if not len(si):
                continue
            k0, k1 = k[si, wi], k[si, wi + 1]
            target = np.where(k1 > k0, np.floor(k1), np.floor(k0))
            t = np.clip((target - k0) / (k1 - k0), 0.0, 1.0)
            b_at = blim[wi] + t * (blim[wi + 1] - blim[wi])
            w_at = w[wi] + t * (w[wi + 1] - w[wi])
            b_at = np.where(target >= 0, b_at, np.inf)  # lobe k >= 0: a delay of a period
            best = np.full(k.shape[0], np.inf)
            np.minimum.at(best, si, b_at)
            at = np.full(k.shape[0], np.nan)
            winner = b_at == best[si]
            at[si[winner]] = w_at[winner]
            better = best < depth[part]
            depth[part] = np.where(better, best, depth[part])
            freq[part] = np.where(better, at / (2 * math.pi), freq[part])
    return depth, freq


def absolute_limit(a0: np.ndarray, modes: ToolModes) -> float:
    """The least zero-order depth over every speed, m: 1 / (2 max Re lambda) (inf: none)."""
    w = chatter_grid(modes)
    lam = branches(a0, modes, w)
    j = int(np.unravel_index(np.argmax(lam.real), lam.shape)[0])
    fine = np.linspace(w[max(j - 1, 0)], w[min(j + 1, len(w) - 1)], 2001)  # about the grid's
    top = max(float(lam.real.max()), float(branches(a0, modes, fine).real.max()))  # best line
    return 1.0 / (2.0 * top) if top > 0.0 else math.inf
