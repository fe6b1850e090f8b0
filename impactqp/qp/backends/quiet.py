"""Third-party solvers kept quiet: what a solver reached through cvxpy or qpsolvers prints
(HiGHS' banner, OSQP's polishing note, written by their C code straight to the process's
standard output) and the warnings it raises (qpsolvers' ``SparseConversionWarning``,
OSQP's ``PendingDeprecationWarning``) never reach the user, unless ``verbose=2`` (impactqp's
log at DEBUG, every backend attempt) or the solver's own ``verbose`` option asks for them.

Solvers write through Python's ``sys.stdout`` (OSQP's C code calls back into it) or from C
straight to file descriptor 1 (HiGHS' banner), so while a solver runs both point at the null
device. Threads
that solve at once (:func:`impactqp.solve_batch`) share one redirection, counted; standard
error is left alone (impactqp's own notices and the command line's heartbeat use it).
"""

from __future__ import annotations

import ctypes
import logging
import os
import sys
import threading
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TextIO

LOG = logging.getLogger("impactqp")

_LOCK = threading.Lock()
_saved: int | None = None
"""A duplicate of the real standard output while it is redirected."""
_stream: TextIO | None = None
"""Python's ``sys.stdout`` while it is replaced by the null device."""
_filters: warnings.catch_warnings | None = None
"""The warning filters to put back when the last thread leaves."""
_depth = 0
"""How many threads are inside :func:`quiet` now (the first one in redirects, the last one
out restores: a thread of its own would restore another's state)."""


def wanted(options: dict | None) -> bool:
    """Whether the solver's output should be shown: impactqp's log at DEBUG (``verbose=2``)
    or a truthy ``verbose`` among the solver's own options."""
    return LOG.isEnabledFor(logging.DEBUG) or bool((options or {}).get("verbose"))


def _c_flush() -> Callable[[], object]:
    """The C library's ``fflush(NULL)`` (a no-op where there is none to load)."""
    try:
        fflush = ctypes.CDLL(None).fflush
    except (OSError, AttributeError, TypeError):  # no C library by that route (Windows)
        return lambda: None
    fflush.argtypes = [ctypes.c_void_p]
    return lambda: fflush(None)


_fflush = _c_flush()


def _flush() -> None:
    """Flush what Python and the C library hold for standard output: C's stdio buffers
    fully when the output is not a terminal, and what a solver wrote must land on the side
    of the redirection it was written on."""
    stream = sys.stdout
    if stream is not None:
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed or detached stream has nothing to flush
            pass
    _fflush()


def _redirect() -> None:
    global _saved, _stream, _filters, _depth
    with _LOCK:
        if _depth == 0:
            _filters = warnings.catch_warnings()
            _filters.__enter__()
            warnings.simplefilter("ignore")
            _flush()
            _stream, sys.stdout = sys.stdout, open(os.devnull, "w")
            try:
                saved = os.dup(1)
            except OSError:  # no standard output at all: nothing can reach a terminal
                saved = None
            if saved is not None:
                null = os.open(os.devnull, os.O_WRONLY)
                os.dup2(null, 1)
                os.close(null)
            _saved = saved
        _depth += 1


def _restore() -> None:
    global _saved, _stream, _filters, _depth
    with _LOCK:
        _depth -= 1
        if _depth:
            return
        null, sys.stdout = sys.stdout, _stream
        null.close()
        _stream = None
        if _saved is not None:
            _flush()
            os.dup2(_saved, 1)
            os.close(_saved)
            _saved = None
        if _filters is not None:
            _filters.__exit__(None, None, None)
            _filters = None


@contextmanager
def quiet(options: dict | None = None) -> Iterator[None]:
    """While it lasts, a third-party solver's printing and warnings are discarded (unless
    :func:`wanted`)."""
    if wanted(options):
        yield
        return
    _redirect()
    try:
        yield
    finally:
        _restore()
