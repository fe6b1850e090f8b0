"""The compilation rule every kernel follows."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TypeVar

import numba

F = TypeVar("F", bound=Callable)


def cache_dir() -> str:
    """Where impactqp's compiled kernels are cached: ``$XDG_CACHE_HOME/impactqp/numba``
    (``~/.cache/impactqp/numba`` by default), unless ``NUMBA_CACHE_DIR`` names another.

    Not beside the installed sources: files there are not in the package's install record,
    so ``pip uninstall`` would leave an ``impactqp`` folder without ``__init__.py`` in
    site-packages, a namespace package that hides a later editable install.
    """
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "impactqp", "numba")


@contextmanager
def _cached_in_user_dir() -> Iterator[None]:
    """numba's cache directory set to :func:`cache_dir` while impactqp decorates a kernel
    (numba picks the directory when the cache is created, at decoration); a directory the
    user chose with ``NUMBA_CACHE_DIR`` is kept, and nothing else's caching changes."""
    if numba.config.CACHE_DIR:
        yield
        return
    numba.config.CACHE_DIR = cache_dir()
    try:
        yield
    finally:
        numba.config.CACHE_DIR = ""


def kernel(function: F) -> F:
    """Compile ``function`` with numba on its first call, caching the machine code on disk
    (in :func:`cache_dir`).

    No signature is given, so nothing is compiled at import; ``error_model="numpy"`` lets a
    division by zero give inf/NaN (which every certificate then rejects) instead of raising.
    """
    with _cached_in_user_dir():
        return numba.njit(cache=True, nogil=True, error_model="numpy")(function)


def inline_kernel(function: F) -> F:
    """:func:`kernel` for a helper of a few operations, inlined into every kernel calling it
    (a call that is not inlined costs as much as the helper's arithmetic)."""
    with _cached_in_user_dir():
        return numba.njit(cache=True, nogil=True, error_model="numpy",
                          inline="always")(function)
