"""The one input converter of impactqp: user values to float arrays, numbers and flags.

Every public entry point converts its arguments here, so a bad argument always raises an
:class:`~impactqp.errors.InputError` (a ``ValueError``) that names it: complex, object,
string, ``None`` and boolean values are refused where numbers are meant (numpy would
silently drop an imaginary part or read ``True`` as 1), ragged lists and wrong shapes
raise :class:`~impactqp.errors.ShapeError`, NaN and infinities
:class:`~impactqp.errors.NonFiniteError`.
"""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..errors import InputError, NonFiniteError, ShapeError

Matrix = Any
"""A numpy.ndarray or a scipy.sparse matrix/array."""


def _kind_error(name: str, what: str, value: Any) -> InputError:
    return InputError(f"{name} must hold real numbers, got {what} "
                      f"({type(value).__name__}: {_short(value)})")


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _numeric_dtype(name: str, arr: np.ndarray, value: Any) -> None:
    kind = arr.dtype.kind
    if kind in "fiu":
        return
    if kind == "c":
        raise _kind_error(name, "complex numbers", value)
    if kind == "b":
        raise _kind_error(name, "booleans", value)
    if kind in "USa":
        raise _kind_error(name, "strings", value)
    raise _kind_error(name, f"values of dtype {arr.dtype}", value)


def finite(name: str, values: np.ndarray) -> None:
    """Raise NonFiniteError naming the first NaN or infinite entry of ``values``."""
    if values.size and not np.isfinite(values).all():
        bad = np.argwhere(~np.isfinite(values))[0]
        raise NonFiniteError(f"{name} must be finite; found {values[tuple(bad)]} "
                             f"at index {tuple(int(i) for i in bad)}")


def _has_flag(value: list | tuple) -> bool:
    """Whether a nested list holds a boolean (numpy would read True as 1.0)."""
    stack = [value]
    while stack:
        item = stack.pop()
        for x in item:
            if isinstance(x, (list, tuple)):
                stack.append(x)
            elif isinstance(x, (bool, np.bool_)):
                return True
    return False


def as_array(name: str, value: Any, *, ndim: int | None = None,
             allow_nonfinite: bool = False, copy: bool = True) -> np.ndarray:
    """A float ndarray from ``value`` (list, tuple, ndarray), checked for kind and finiteness.

    Raises
    ------
    InputError
        ``None``, strings, complex, boolean or object values.
    ShapeError
        Ragged nesting or a number of dimensions other than ``ndim``.
    NonFiniteError
        NaN or infinity (unless ``allow_nonfinite``).

    With ``copy=False`` a float array is returned as it is (read-only use of big inputs).
    """
    if value is None:
        raise InputError(f"{name} is required, got None")
    if isinstance(value, (str, bytes)):
        raise _kind_error(name, "a string", value)
    if sp.issparse(value):
        raise InputError(f"{name} must be a dense array here, got a scipy.sparse matrix")
    try:
        arr = np.asarray(value)
    except (ValueError, TypeError) as exc:  # ragged nesting in recent numpy
        raise ShapeError(f"{name} must be a rectangular array of numbers (ragged or "
                         f"mixed nesting: {exc})") from None
    if arr.dtype == object:
        try:
            arr = np.asarray(value, dtype=float)
        except (ValueError, TypeError):
            raise _kind_error(name, "values that are not real numbers", value) from None
        if any(isinstance(v, (bool, np.bool_, complex, str)) or v is None
               for v in np.asarray(value, dtype=object).ravel()):
            raise _kind_error(name, "a mixture of numbers and other values", value)
    _numeric_dtype(name, arr, value)
    if isinstance(value, (list, tuple)) and _has_flag(value):
        raise _kind_error(name, "booleans", value)
    # a private copy (callers may keep it), unless the caller only reads a large input
    arr = np.array(arr, dtype=float) if copy else np.asarray(arr, dtype=float)
    if ndim is not None and arr.ndim != ndim:
        raise ShapeError(f"{name} must have {ndim} dimension{'s' if ndim != 1 else ''}, "
                         f"got shape {arr.shape}")
    if not allow_nonfinite:
        finite(name, arr)
    return arr


def as_vector(name: str, value: Any, length: int) -> np.ndarray:
    """``value`` as a finite float vector of the given length."""
    arr = as_array(name, value)
    if arr.shape != (length,):
        raise ShapeError(f"{name} must have shape ({length},), got {arr.shape}")
    return arr


def as_matrix(name: str, value: Any) -> Matrix:
    """A finite float matrix, kept sparse (CSC) when given sparse."""
    if sp.issparse(value):
        if value.dtype.kind not in "fiu":
            raise _kind_error(name, f"a sparse matrix of dtype {value.dtype}", value)
        mat = sp.csc_matrix(value, dtype=float)
        finite(name, mat.data)
        return mat
    return as_array(name, value)


def as_real(name: str, value: Any, *, low: float | None = None, high: float | None = None,
            positive: bool = False) -> float:
    """One finite real number (a Python or numpy number, not bool), optionally in a range."""
    if type(value) is not float and (isinstance(value, (bool, np.bool_))
                                     or not isinstance(value, numbers.Real)):
        if isinstance(value, np.ndarray) and value.shape == () and value.dtype.kind in "fiu":
            value = value.item()
        else:
            raise InputError(f"{name} must be one real number, got "
                             f"{type(value).__name__}: {_short(value)}")
    x = float(value)
    if not math.isfinite(x):
        raise NonFiniteError(f"{name} must be finite, got {value!r}")
    if positive and not x > 0:
        raise InputError(f"{name} must be positive, got {value!r}")
    if (low is not None and x < low) or (high is not None and x > high):
        raise InputError(f"{name} must lie in [{low}, {high}], got {value!r}")
    return x


def as_flag(name: str, value: Any) -> bool:
    """A boolean flag: True/False only (``"no"`` or 0.5 are refused, not read as truthy)."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise InputError(f"{name} must be True or False, got {type(value).__name__}: "
                     f"{_short(value)}")


def as_count(name: str, value: Any, *, minimum: int = 0) -> int:
    """A whole number ≥ ``minimum`` (not bool, not float)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise InputError(f"{name} must be a whole number ≥ {minimum}, got "
                         f"{type(value).__name__}: {_short(value)}")
    if value < minimum:
        raise InputError(f"{name} must be a whole number ≥ {minimum}, got {value!r}")
    return int(value)


def check_tol(tol: Any, name: str = "tol") -> float:
    """A certificate tolerance: a real number in (0, 1)."""
    if type(tol) is float and 0.0 < tol < 1.0:  # the common case, without conversions
        return tol
    t = as_real(name, tol)
    if not 0.0 < t < 1.0:
        raise InputError(f"{name} must be a tolerance in (0, 1), got {tol!r}")
    return t


def as_dense(A: Any) -> np.ndarray:
    """A float ndarray view of a dense or scipy.sparse matrix (no validation)."""
    return A.toarray() if sp.issparse(A) else np.asarray(A, dtype=float)
