"""The tool's modes from a tap test at the tool: receptances (UFF 58) between the tool tip's
directions, their modes by the campaign's own extraction (modaltest.ema: LSCF poles, LSFD
residues), mass-normalised from the driving points: the input of `rps lobes --tool-modes
FILE.unv`.

A mode r's residue in the FRF of response dof j to excitation dof k gives
phi_j phi_k = Re(2 i omega_d A_jk) (modaltest.ema.poles_and_residues). At a driving point
(j = k) that is phi_k^2: its root scales the mode (a mode whose driving-point product is not
positive is noise or not excited there, and is left out, said). With several driving points
(a hammer along x and along y) each mode is scaled from the one that drives it most (the
largest phi_k^2), its other components read from that reference's FRFs: phi_j = (phi_j
phi_k) / phi_k. The components become the tool's displacement vector per mode in the file's
frame (least squares over the measured directions); a direction not measured is zero.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from common.errors import InputError

from . import uff
from .ema import EmaSettings, poles_and_residues


@dataclass(frozen=True)
class TapModes:
    """Modes at the tool from its FRFs: frequencies (Hz), damping ratios and the tool's
    mass-normalised displacement (3, m) in the file's frame (1/sqrt(kg))."""

    frequency_hz: np.ndarray
    damping_ratio: np.ndarray
    shape: np.ndarray
    node: int
    dropped: tuple[str, ...]  # the modes left out, and why


def tap_nodes(frfs: uff.Frfs) -> list[int]:
    """The nodes with a driving point FRF (response and excitation at the same dof)."""
    same = (frfs.dofs.node == frfs.reference.node) & np.all(
        np.abs(frfs.dofs.direction - frfs.reference.direction) < 1e-9, axis=1)
    return sorted({int(n) for n in frfs.dofs.node[same]})


def tap_modes(frfs: uff.Frfs, where: str, node: int | None = None,
              settings: EmaSettings | None = None) -> TapModes:
    """The tool's modes (module docstring) from the FRFs at `node` (default: the one node
    with a driving point); InputError in one line naming `where` when there is none, or
    several and no node chosen, or no mode can be scaled."""
    nodes = tap_nodes(frfs)
    if not nodes:
        raise InputError(f"{where}: no driving-point FRF (response and excitation at the same "
                         "node and direction): a tap test at the tool has one per hammer "
                         "direction, and the modes' scale comes from it")
    if node is None:
        if len(nodes) > 1:
            raise InputError(f"{where}: driving points at nodes {nodes}: name the tool's with "
                             "--tool-node")
        node = nodes[0]
    elif node not in nodes:
        raise InputError(f"{where}: --tool-node {node} has no driving-point FRF (nodes with "
                         f"one: {nodes})")
    rows = np.flatnonzero((frfs.dofs.node == node) & (frfs.reference.node == node))
    tool = uff.Frfs(frfs.frequency_hz, uff.Dofs(frfs.dofs.node[rows], frfs.dofs.direction[rows]),
                    uff.Dofs(frfs.reference.node[rows], frfs.reference.direction[rows]),
                    frfs.values[rows])
    f = tool.frequency_hz
    if settings is None:
        settings = EmaSettings(lower_hz=float(f[f > 0][0]), upper_hz=float(f[-1]))
    poles, residues = poles_and_residues(tool, settings)
    product = np.real(2j * poles.imag[None, :] * residues)  # (k, m): phi_j phi_k
    driving = np.flatnonzero(np.all(np.abs(tool.dofs.direction - tool.reference.direction)
                                    < 1e-9, axis=1))
    keys = [tuple(np.round(d, 9)) for d in tool.reference.direction]
    hz = np.abs(poles) / (2 * math.pi)
    zeta = -poles.real / np.abs(poles)
    kept, shapes, dropped = [], [], []
    every = np.abs(tool.dofs.direction).sum(axis=0) > 1e-9  # the directions measured at all
    for r in range(len(poles)):
        best = driving[np.argmax(product[driving, r])]
        if product[best, r] <= 0.0:
            dropped.append(f"{hz[r]:.4g} Hz (no positive driving-point residue: noise, or "
                           "not excited at the tool)")
            continue
        scale = math.sqrt(product[best, r])
        same = [i for i in range(len(keys)) if keys[i] == keys[best]]
        d = tool.dofs.direction[same]
        u, *_ = np.linalg.lstsq(d, product[same, r] / scale, rcond=None)
        measured = np.abs(d).sum(axis=0) > 1e-9
        if (every & ~measured).any():  # a direction known only from its own driving point:
            axis = "xyz"[int(np.flatnonzero(every & ~measured)[0])]  # its sign is unknown
            raise InputError(f"{where}: the mode at {hz[r]:.4g} Hz is scaled from the hammer "
                             f"that drives it most, whose FRFs do not reach {axis} at node "
                             f"{node}: its {axis} component's sign is unknown; give the cross "
                             "FRFs (every response direction for every hammer direction)")
        kept.append(r)
        shapes.append(np.where(measured, u, 0.0))
    if not kept:
        raise InputError(f"{where}: no mode at node {node} could be scaled from a driving "
                         "point (" + "; ".join(dropped) + ")")
    return TapModes(hz[kept], zeta[kept], np.array(shapes).T, node, tuple(dropped))
