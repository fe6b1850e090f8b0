"""The compilation rule every kernel follows."""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

import numba

F = TypeVar("F", bound=Callable)


def kernel(function: F) -> F:
    """Compile ``function`` with numba on its first call, caching the machine code on disk.

    No signature is given, so nothing is compiled at import; ``error_model="numpy"`` lets a
    division by zero give inf/NaN (which every certificate then rejects) instead of raising.
    """
    return numba.njit(cache=True, nogil=True, error_model="numpy")(function)


def inline_kernel(function: F) -> F:
    """:func:`kernel` for a helper of a few operations, inlined into every kernel calling it
    (a call that is not inlined costs as much as the helper's arithmetic)."""
    return numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")(function)
