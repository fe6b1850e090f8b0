"""The arrays a batch of impacts writes into: fresh ones, or those of an earlier result
passed back as ``out=`` (a stream of batches then writes into pages it has already touched,
instead of having the system map and zero about 88 bytes per 3-ball row at every call).

A buffer is taken only when the batch can write every entry of it and read nothing of it
before: float64, C-contiguous where compiled passes write it (U⁺, Λ), writable, of the
batch's shape, and sharing no memory with u⁻ or with another buffer (the certificate
reads u⁻, u⁺ and Λ after the solve wrote them). Residuals that are not the rows of one
table are filled chunk by chunk from a scratch block.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError, ShapeError

Buffers = tuple[np.ndarray, np.ndarray, dict, "np.ndarray | None"]
"""(U⁺, Λ, residuals by name, the (r, k) table whose rows are the residuals, or None)."""


def fresh(U: np.ndarray, m: int, table: tuple[str, ...] | None) -> Buffers:
    """New arrays for k = ``len(U)`` rows: U⁺ like U, Λ (k, m) and, when ``table`` names
    the residuals, one (r, k) table whose rows are them (else residuals come later). None is
    zeroed: every route of a batch writes every entry (as it must into a reused ``out``)."""
    k = U.shape[0]
    columns = None if table is None else np.empty((len(table), k))
    residuals = {} if table is None else dict(zip(table, columns))
    return np.empty((k, U.shape[1])), np.empty((k, m)), residuals, columns


def _buffer(name: str, value: Any, shape: tuple[int, ...], contiguous: bool = True
            ) -> np.ndarray:
    """``value`` when a batch may write ``shape`` float64 entries into it (C-contiguous if
    ``contiguous``: compiled passes write it), else a named error: ShapeError for the
    shape, InputError for type, dtype, layout or read-only."""
    if not isinstance(value, np.ndarray):
        raise InputError(f"out.{name} must be a numpy array, got {type(value).__name__}")
    if value.dtype != np.float64:
        raise InputError(f"out.{name} must have dtype float64, got {value.dtype}")
    if value.shape != shape:
        raise ShapeError(f"out.{name} must have shape {shape}, got {value.shape}")
    if contiguous and not value.flags.c_contiguous:
        raise InputError(f"out.{name} must be C-contiguous")
    if not value.flags.writeable:
        raise InputError(f"out.{name} is read-only")
    return value


def _overlap(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether a and b share an entry (strided columns of one array interleave without
    sharing one; decided exactly, which for arrays of at most two axes is quick)."""
    return bool(np.shares_memory(a, b))


def _table(residuals: dict, names: tuple[str, ...], k: int) -> np.ndarray | None:
    """The (r, k) array whose rows are ``residuals`` in the order ``names`` (a compiled pass
    writes the residual columns of a block into it side by side), or None when they are
    not the rows of one such array (then they are filled chunk by chunk from a scratch)."""
    table = residuals[names[0]].base if names else None
    if not (isinstance(table, np.ndarray) and table.shape == (len(names), k)
            and table.dtype == np.float64 and table.flags.c_contiguous
            and table.flags.writeable):
        return None
    start = table.__array_interface__["data"][0]
    if any(residuals[name].__array_interface__["data"][0] != start + i * k * 8
           for i, name in enumerate(names)):
        return None
    return table


def reused(out: Any, U: np.ndarray, m: int, names: tuple[str, ...] | None) -> Buffers:
    """The arrays of ``out`` (an earlier batch's result) checked for a batch of the rows of
    ``U`` with m contacts.

    Parameters
    ----------
    out : BatchResult
        Its ``u_plus``, ``impulses`` and ``residuals`` are overwritten.
    U : (k, n) ndarray
        The rows to be solved (no buffer may share memory with it).
    m : int
        Contacts.
    names : tuple of str, optional
        The residuals the batch writes, when known before solving (then ``out`` must hold
        exactly them; when they are the rows of one table, it is returned as such).

    Raises
    ------
    ShapeError
        An array of ``out`` of another shape than the batch's.
    InputError
        Not a result's arrays, another dtype, not C-contiguous, read-only, other residual
        names, or memory shared with ``U`` or between two arrays of ``out``.
    """
    k, n = U.shape
    Up = _buffer("u_plus", getattr(out, "u_plus", None), (k, n))
    Lam = _buffer("impulses", getattr(out, "impulses", None), (k, m))
    given = getattr(out, "residuals", None)
    if not isinstance(given, dict):
        raise InputError("out.residuals must be a dict of (k,) arrays")
    if names is not None and tuple(given) != names:
        raise InputError(f"out holds the residuals {tuple(given)}, this batch writes {names}")
    residuals = {key: _buffer(f"residuals[{key!r}]", value, (k,), contiguous=False)
                 for key, value in given.items()}
    columns = _table(residuals, names, k) if names else None
    arrays = {"u_plus": Up, "impulses": Lam}  # a table's rows are apart by construction
    arrays.update({"residuals": columns} if columns is not None else
                  {f"residuals[{key!r}]": value for key, value in residuals.items()})
    for name, value in arrays.items():
        if _overlap(value, U):
            raise InputError(f"out.{name} shares memory with U_minus (the certificate reads "
                             "u⁻ after u⁺ and Λ are written)")
    items = list(arrays.items())
    for i, (name, value) in enumerate(items):
        for other, array in items[i + 1:]:
            if _overlap(value, array):
                raise InputError(f"out.{name} and out.{other} share memory")
    return Up, Lam, residuals, columns
