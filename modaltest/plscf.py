"""Poly-reference least-squares complex frequency-domain poles (pLSCF, "PolyMAX": Guillaume,
Verboven, Vanlanduit, Van der Auweraer, Peeters, Proc. IMAC 21, 2003; Peeters, Van der
Auweraer, Guillaume, Leuridan, Shock and Vibration 11:395, 2004): the poles of every model
order of a stabilisation chart from the FRFs of every reference together.

The FRFs of output o to the m references, the row H_o(w) (1 x m), are modelled as a right
matrix-fraction H_o(w) = B_o(w) A(w)^-1 with matrix polynomials in z = exp(i w dt):

    A(w) = sum_{r=0..n} z^r alpha_r (m x m),   B_o(w) = sum_{r=0..n} z^r beta_or (1 x m),

dt = pi / w_top (the band's top on the unit circle's half). Each output's FRFs are weighed by
the inverse of their largest magnitude (a sensor's noise scales with its range, so a weak
output does not vanish beside a strong one). The linearised least squares
sum_o sum_k |B_o(w_k) - H_o(w_k) A(w_k)|^2 eliminates every beta_o, leaving the reduced
normal matrix M = 2 sum_o (T_o - S_o^T R^-1 S_o) (R = Re X^H X, S_o = Re X^H Y_o,
T_o = Re Y_o^H Y_o, X the basis rows [z^0 .. z^n], Y_o = -X kron H_o); with alpha_n = I the
rest solves from M, and the poles are the block companion matrix's eigenvalues z,
lambda = ln(z) / dt. Every order comes from the same R, S_o and T_o (their leading blocks).
A close pair of modes that one reference excites alike and the other apart is two poles from
the lowest orders on: the matrix denominator separates what a scalar one must fit with one.
"""
from __future__ import annotations

import math

import numpy as np


def poles_by_order(frequency_hz, frfs, references: int, max_order: int) -> list[np.ndarray]:
    """The poles (rad/s, complex; both signs of the imaginary part) of the model orders
    1..max_order. `frfs` (outputs, references, lines) on `frequency_hz` (the band's lines,
    evenly spaced or not)."""
    h = np.asarray(frfs, complex)
    outputs, m, lines = h.shape
    if m != references:
        raise ValueError(f"pLSCF: {m} references in the FRF array, {references} said")
    w = 2 * math.pi * np.asarray(frequency_hz, float)
    dt = math.pi / w[-1]
    n = max_order
    x = np.exp(1j * np.outer(w * dt, np.arange(n + 1)))  # (lines, n + 1)
    level = np.abs(h).max(axis=(1, 2), keepdims=True)  # each output weighed by its level
    h = h / np.where(level > 0.0, level, np.inf)  # a dead output weighs nothing
    h = h / np.sqrt(np.mean(np.abs(h) ** 2))  # the scale of the numbers, not of the poles
    r = (x.conj().T @ x).real  # (n + 1, n + 1)
    size = m * (n + 1)
    s_all = np.empty((outputs, n + 1, size))
    t_all = np.zeros((size, size))
    for o in range(outputs):
        y = -(x[:, :, None] * h[o].T[:, None, :]).reshape(lines, size)  # index r * m + q
        s_all[o] = (x.conj().T @ y).real
        t_all += (y.conj().T @ y).real
    out = []
    for order in range(1, n + 1):
        k = order + 1
        rk = r[:k, :k]
        sk = s_all[:, :k, :m * k]
        rinv_s = np.linalg.solve(rk, sk.transpose(1, 0, 2).reshape(k, -1)).reshape(
            k, outputs, m * k).transpose(1, 0, 2)
        mk = 2 * (t_all[:m * k, :m * k] - np.einsum("oki,okj->ij", sk, rinv_s))
        head = m * order
        try:
            alpha = -np.linalg.solve(mk[:head, :head], mk[:head, head:])  # (m n, m)
        except np.linalg.LinAlgError:
            out.append(np.zeros(0, complex))
            continue
        companion = np.zeros((head, head))
        if order > 1:
            companion[:-m, m:] = np.eye(head - m)
        companion[-m:, :] = -alpha.T  # alpha_r^T blocks side by side: A(z)^T's last row
        z = np.linalg.eigvals(companion)
        with np.errstate(divide="ignore", invalid="ignore"):
            out.append(np.log(z.astype(complex)) / dt)
    return out
