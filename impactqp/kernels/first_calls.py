"""The first small calls of a process: the kernels' own Python text instead of a compile.

A kernel's machine code costs seconds to build (the active-set search of one impact and its
certificate about ten, friction's one-call route more) and milliseconds to load once it is in
the cache. A process whose kernels are in neither place, and whose calls are small (a demo, a
first frictional impact, a short script), is better served by running the very same
definitions as Python: each such call takes milliseconds. So a kernel declared
``interpretable`` (its work bounded by the sizes of its arrays: no loop over steps or rows)
decides at a call for which it holds no machine code:

- machine code for it in the disk cache, a large call (more than :data:`SMALL` array
  elements), or the process's interpreted time spent (:data:`BUDGET` seconds): compile, or
  load from the cache, as numba does;
- otherwise: run its Python text, that of every kernel it calls with it. Nothing is
  compiled, so no later call waits for a compile it did not need.

The Python text is the kernel package imported a second time under :data:`TWIN`, with
:mod:`.jit`'s decorators returning the functions as they are: the same definitions, run by
the interpreter (``NUMBA_DISABLE_JIT=1`` runs them the same way for the whole process). The
results are those of the compiled code up to rounding; every certificate is recomputed as
usual. ``IMPACTQP_INTERPRETED_SECONDS`` sets the budget (``0``: always compile), and
:func:`compiling` compiles whatever its block calls, as ``impactqp compile`` needs.
"""

from __future__ import annotations

import importlib
import os
import sys
import threading
import time
import types
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np
from numba.core.dispatcher import OmittedArg
from numba.core.registry import CPUDispatcher

SMALL = 4096
"""Array elements (over all arguments) up to which a call may run as Python."""

BUDGET = float(os.environ.get("IMPACTQP_INTERPRETED_SECONDS", "2.0"))
"""Seconds of interpreted kernels a process may spend before its kernels compile."""

TWIN = "impactqp.kernels_as_python"
"""The name under which the kernel modules are imported a second time, uncompiled: a sibling
of :mod:`impactqp.kernels`, so that their relative imports reach the same modules."""

_lock = threading.Lock()
_state = {"spent": 0.0, "calls": 0, "compiling": 0}
_cold: set[CPUDispatcher] = set()
"""Kernels whose cache this process found without machine code."""


def spent() -> tuple[float, int]:
    """Seconds and calls this process ran as interpreted kernels."""
    return _state["spent"], _state["calls"]


@contextmanager
def compiling() -> Iterator[None]:
    """Inside the block, every kernel compiles (or loads its machine code) at its first call."""
    with _lock:
        _state["compiling"] += 1
    try:
        yield
    finally:
        with _lock:
            _state["compiling"] -= 1


def _elements(args: tuple[Any, ...]) -> int:
    """Array elements among the arguments (arrays inside tuples counted too)."""
    total = 0
    for a in args:
        if isinstance(a, np.ndarray):
            total += a.size
        elif isinstance(a, tuple):
            total += _elements(a)
    return total


def cached(dispatcher: CPUDispatcher) -> bool:
    """The disk cache holds machine code of ``dispatcher`` for the current source (numba's
    index is dropped when the source changed). Unknown cache internals count as cached:
    numba then does what it always does."""
    try:
        return bool(dispatcher._cache._cache_file._load_index())
    except (AttributeError, OSError, EOFError, ValueError):
        return True


def _twin_package() -> types.ModuleType:
    """The package :data:`TWIN`, over the same files as :mod:`impactqp.kernels`, whose
    ``jit`` module returns functions undecorated."""
    package = sys.modules.get(TWIN)
    if package is not None:
        return package
    kernels = importlib.import_module(__package__)
    jit = importlib.import_module(f"{__package__}.jit")
    package = types.ModuleType(TWIN, "impactqp's kernels as Python, for small first calls")
    package.__path__ = list(kernels.__path__)
    package.__package__ = TWIN
    plain = types.ModuleType(f"{TWIN}.jit")
    plain.__dict__.update({name: value for name, value in vars(jit).items()
                           if not name.startswith("__")})
    plain.kernel = plain.inline_kernel = _as_python
    sys.modules[f"{TWIN}.jit"] = plain
    sys.modules[TWIN] = package
    return package


def _as_python(function: Callable | None = None, **_: Any) -> Callable:
    """The twin's decorator: the function itself (with or without decorator arguments)."""
    return function if function is not None else (lambda f: f)


def python_text(dispatcher: CPUDispatcher) -> Callable:
    """The uncompiled twin of a kernel: its definition in :data:`TWIN`."""
    with _lock:
        _twin_package()
        module = importlib.import_module(dispatcher.py_func.__module__.replace(
            __package__, TWIN, 1))
    return getattr(module, dispatcher.py_func.__name__)


def _interpret(dispatcher: CPUDispatcher, args: tuple[Any, ...]) -> bool:
    """Run this call of a cold kernel as Python (see the module's rules)?"""
    if _state["compiling"] or _state["spent"] >= BUDGET or _elements(args) > SMALL:
        return False
    if dispatcher.signatures:
        return False
    if dispatcher not in _cold:  # the cache's index is read once per kernel and process
        if cached(dispatcher):
            return False
        _cold.add(dispatcher)
    return True


def _timed(function: Callable) -> Callable:
    """``function`` on the caller's arguments (numba's omitted defaults unwrapped), its time
    added to the process's interpreted seconds."""
    def call(*args: Any) -> Any:
        start = time.perf_counter()
        try:
            return function(*(a.value if isinstance(a, OmittedArg) else a for a in args))
        finally:
            with _lock:
                _state["spent"] += time.perf_counter() - start
                _state["calls"] += 1
    return call


class InterpretableDispatcher(CPUDispatcher):
    """numba's CPU dispatcher for a kernel whose first small calls may run as Python: a call
    that finds no machine code asks :func:`_interpret` before compiling."""

    def _compile_for_args(self, *args: Any, **kws: Any) -> Callable:
        if not kws and _interpret(self, args):
            return _timed(python_text(self))
        return super()._compile_for_args(*args, **kws)
