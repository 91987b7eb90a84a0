"""What a modal test measured, as the readers hand it on (`uff.read_uff`, `ema.identify_modes`):
nodes, measured dofs, modes and FRFs, frozen and checked (shape, finiteness), SI inside:
metres, hertz, receptance in m/N; directions are unit vectors of the base frame."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from common.errors import InputError
from common.messages import one_line

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
ComplexArray = npt.NDArray[np.complex128]


class UffError(InputError):
    """A UFF file, or data meant for one, refused: one line naming it and what is wrong."""


def _array(values: Any, dtype: type, what: str, shape: tuple[int | None, ...]) -> Any:
    """A read-only finite copy of `values` with this dtype and shape (None: any length); ids
    (int64) may come as floats with integral values."""
    try:
        raw = np.asarray(values)
    except ValueError as exc:  # ragged
        raise UffError(f"{what}: {one_line(exc)}") from None
    if raw.dtype.kind not in ("iufc" if dtype is np.complex128 else "iuf"):
        raise UffError(f"{what}: {raw.dtype} values where {dtype.__name__} ones are expected")
    if dtype is np.int64 and not np.all(np.isfinite(raw) & (raw == np.round(raw))):
        raise UffError(f"{what}: ids must be integers")
    arr: Any = raw.astype(dtype)  # a copy
    if arr.ndim != len(shape) or any(n is not None and n != s for n, s in zip(shape, arr.shape)):
        expected = "(" + ", ".join("n" if n is None else str(n) for n in shape) + ")"
        raise UffError(f"{what}: shape {arr.shape}, expected {expected}")
    if not np.all(np.isfinite(arr)):
        raise UffError(f"{what}: non-finite values")
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False)
class Nodes:
    """Node ids and their coordinates (m) in the file's frame."""

    ids: IntArray  # (n,)
    xyz: FloatArray  # (n, 3)

    def __post_init__(self) -> None:
        ids = _array(self.ids, np.int64, "Nodes.ids", (None,))
        object.__setattr__(self, "ids", ids)
        object.__setattr__(self, "xyz", _array(self.xyz, np.float64, "Nodes.xyz", (len(ids), 3)))
        unique, counts = np.unique(ids, return_counts=True)
        if np.any(counts > 1):
            raise UffError(f"node {unique[counts > 1][0]} is defined twice")


@dataclass(frozen=True, eq=False)
class Dofs:
    """Degrees of freedom: a node and a unit direction (x, y, z of the base frame, signed)."""

    node: IntArray  # (k,)
    direction: FloatArray  # (k, 3)

    def __post_init__(self) -> None:
        node = _array(self.node, np.int64, "Dofs.node", (None,))
        object.__setattr__(self, "node", node)
        direction = _array(self.direction, np.float64, "Dofs.direction", (len(node), 3))
        if np.any(np.abs(np.linalg.norm(direction, axis=1) - 1.0) > 1e-9):
            raise UffError("Dofs.direction: not unit vectors")
        object.__setattr__(self, "direction", direction)

    @classmethod
    def from_codes(cls, node: Any, codes: Any) -> Dofs:
        """Dofs from UFF direction codes: 1, 2, 3 = +x, +y, +z; negative = minus."""
        c = np.asarray(codes, dtype=np.int64)
        if np.any((c == 0) | (np.abs(c) > 3)):
            raise UffError(f"direction codes {sorted(set(c.tolist()))}: only +-1, 2, 3")
        return cls(node, np.sign(c)[:, None] * np.eye(3)[np.abs(c) - 1])

    def codes(self) -> IntArray:
        """The UFF direction codes (+-1, 2, 3); UffError for a direction off the axes."""
        d = self.direction
        axis = np.argmax(np.abs(d), axis=1)
        off = np.abs(np.abs(d) - np.eye(3)[axis]).max(axis=1, initial=0.0) > 1e-12
        if np.any(off):
            i = int(np.flatnonzero(off)[0])
            raise UffError(f"dof at node {self.node[i]}: direction {d[i].tolist()} is not along "
                           "x, y or z (a UFF direction is +-x, +-y or +-z)")
        codes: IntArray = (np.sign(d[np.arange(len(d)), axis]) * (axis + 1)).astype(np.int64)
        return codes


@dataclass(frozen=True, eq=False)
class Modes:
    """Real modes at measured dofs."""

    frequencies_hz: FloatArray  # (m,)
    damping_ratios: FloatArray | None  # (m,), or None when the file gives none (all zero)
    dofs: Dofs
    shapes: FloatArray  # (k, m)

    def __post_init__(self) -> None:
        hz = _array(self.frequencies_hz, np.float64, "Modes.frequencies_hz", (None,))
        if np.any(hz <= 0.0):
            k = int(np.flatnonzero(hz <= 0.0)[0])
            raise UffError(f"Modes.frequencies_hz: mode {k + 1} at {hz[k]:g} Hz; a mode has a "
                           "positive frequency")
        object.__setattr__(self, "frequencies_hz", hz)
        if (zeta := self.damping_ratios) is not None:
            zeta = _array(zeta, np.float64, "Modes.damping_ratios", (len(hz),))
            object.__setattr__(self, "damping_ratios", zeta)
        shapes = _array(self.shapes, np.float64, "Modes.shapes", (len(self.dofs.node), len(hz)))
        null = ~np.any(shapes != 0.0, axis=0)
        if np.any(null):
            raise UffError(f"Modes.shapes: mode {int(np.flatnonzero(null)[0]) + 1} is zero at "
                           "every measured dof")
        object.__setattr__(self, "shapes", shapes)


@dataclass(frozen=True, eq=False)
class Frfs:
    """Receptances (m/N) on one frequency axis, one excitation dof per FRF."""

    frequency_hz: FloatArray  # (nf,)
    dofs: Dofs  # response dofs, k
    reference: Dofs  # excitation dof per FRF, k
    values: ComplexArray  # (k, nf)

    def __post_init__(self) -> None:
        f = _array(self.frequency_hz, np.float64, "Frfs.frequency_hz", (None,))
        if len(f) < 2 or f[0] < 0.0 or np.any(np.diff(f) <= 0.0):
            raise UffError("Frfs.frequency_hz: expected at least 2 lines, >= 0, increasing")
        object.__setattr__(self, "frequency_hz", f)
        if (k := len(self.dofs.node)) != len(self.reference.node):
            raise UffError(f"Frfs: {k} response dofs, {len(self.reference.node)} references")
        object.__setattr__(self, "values", _array(self.values, np.complex128, "Frfs.values",
                                                  (k, len(f))))


@dataclass(frozen=True, eq=False)
class UffContent:
    path: str
    nodes: Nodes
    modes: Modes | None
    frfs: Frfs | None
    length_unit_m: float  # metres per file length unit


def complex_to_real_shape(psi: Any) -> FloatArray:
    """Re(psi e^(-i theta)), theta = arg(sum psi^2) / 2: the common phase rotation that maximises
    the real part's norm (the best real shape up to scale); signed: largest component > 0."""
    z = np.asarray(psi, dtype=np.complex128)
    real: FloatArray = (z * np.exp(-0.5j * np.angle(np.sum(z * z)))).real
    return -real if real.size and real[int(np.argmax(np.abs(real)))] < 0 else real
