"""What the compiled derivative kernels (:mod:`impactqp.kernels.local_map`) take: a dense
structure's operands, formed once per structure, and the directions of a JVP as arrays
(docs/theory.md §18)."""

from __future__ import annotations

import weakref
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from ..kernels import local_map as compiled


def dense(A: Any) -> np.ndarray:
    """A (dense or sparse) matrix as a C-contiguous float array."""
    return np.ascontiguousarray(A.toarray() if hasattr(A, "toarray") else A, dtype=float)


class Operands(NamedTuple):
    """A dense structure's operands of derivatives, formed once per structure: M, W, M⁻¹
    (symmetrized), Y = M⁻¹W and G = WᵀM⁻¹W (the solver's own), and the packed operators
    of the compiled impact."""

    M: np.ndarray
    W: np.ndarray
    Minv: np.ndarray
    Y: np.ndarray
    G: np.ndarray
    packed: np.ndarray


_OPERANDS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def operands(structure: Any) -> Operands:
    """The :class:`Operands` of a dense structure (kept while the structure lives)."""
    ops = _OPERANDS.get(structure)
    if ops is None:
        M = structure.dense_mass
        Minv = np.linalg.inv(M)
        ops = _OPERANDS[structure] = Operands(
            M, np.ascontiguousarray(structure.dense_Wt.T), 0.5 * (Minv + Minv.T),
            structure.dense_Minv_W, np.ascontiguousarray(dense(structure.delassus)),
            structure.kernel_pack)
    return ops


def directions(t: dict[str, np.ndarray], name: str,
               to_E: Callable[[np.ndarray], np.ndarray]) -> tuple[np.ndarray, ...]:
    """The compiled kernels' directions (du⁻, dM, dW, dE) of tangents ``t`` (the law's
    parameter ``name`` mapped to dE by ``to_E``; an empty array for a missing one)."""
    def get(key: str, ndim: int) -> np.ndarray:
        d = t.get(key)
        return EMPTY[ndim] if d is None else np.ascontiguousarray(d, dtype=float)

    dE = t.get(name)
    return (get("u_minus", 1), get("M", 2), get("W", 2),
            EMPTY[2] if dE is None else np.ascontiguousarray(to_E(dE), dtype=float))


UNPACK = getattr(compiled.unpack_point, "py_func", compiled.unpack_point)
POINT_SIZE = getattr(compiled.point_size, "py_func", compiled.point_size)
"""The packed point's views and size, in Python (no call into compiled code for them)."""

EMPTY = {1: np.zeros(0), 2: np.zeros((0, 0))}
"""What the kernels take for an input a direction leaves alone."""
