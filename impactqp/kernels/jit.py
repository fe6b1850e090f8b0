"""The compilation rule every kernel follows."""

from __future__ import annotations

import functools
import hashlib
import os
import shutil
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, TextIO, TypeVar

import numba
import numba.core.event
from numba.core import types
from numba.core.imputils import impl_ret_borrowed, lower_builtin
from numba.core.registry import CPUDispatcher
from numba.extending import type_callable

from .first_calls import InterpretableDispatcher

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


KEPT_SOURCES = 4
"""Cache folders of earlier kernel sources kept beside the current one (for a few checkouts
or versions used in turn); older ones are removed when a new one is made."""


def sources_stamp() -> str:
    """A fingerprint of every kernel's source file (name, size, modification time).

    numba drops a kernel's cached machine code when the file that defines it changes, but not
    when a kernel it calls changes in another file: the caller's cached code still holds the
    old callee. Machine code is therefore kept in a folder of its own for each state of the
    kernels' sources (:func:`_cached_in_user_dir`), so an edited or updated checkout never
    loads code compiled from other sources.
    """
    digest = hashlib.blake2b(digest_size=8)
    for name in sorted(os.listdir(_HERE)):
        if name.endswith(".py"):
            stat = os.stat(os.path.join(_HERE, name))
            digest.update(f"{name}:{stat.st_size}:{stat.st_mtime_ns};".encode())
    return digest.hexdigest()


_HERE = os.path.dirname(os.path.abspath(__file__))
_STAMP = sources_stamp()


@functools.cache
def _sources_folder(base: str, stamp: str) -> str:
    """``base``'s folder for the kernel sources of ``stamp``; when it is new, folders of
    other sources beyond the :data:`KEPT_SOURCES` newest are removed."""
    folder = os.path.join(base, f"sources-{stamp}")
    if not os.path.isdir(folder):
        try:
            others = sorted((os.path.join(base, name) for name in os.listdir(base)
                             if name.startswith("sources-")), key=os.path.getmtime)
        except OSError:  # no cache yet
            others = []
        for old in others[:max(len(others) - KEPT_SOURCES, 0)]:
            shutil.rmtree(old, ignore_errors=True)
    return folder


@contextmanager
def _cached_in_user_dir() -> Iterator[None]:
    """numba's cache directory set, while impactqp decorates a kernel (numba picks the
    directory when the cache is created, at decoration), to the folder of the current kernel
    sources (:func:`sources_stamp`) in :func:`cache_dir`, or in the directory the user chose
    with ``NUMBA_CACHE_DIR``; numba's setting is restored afterwards, so nothing else's
    caching changes."""
    chosen = numba.config.CACHE_DIR
    numba.config.CACHE_DIR = _sources_folder(chosen or cache_dir(), _STAMP)
    try:
        yield
    finally:
        numba.config.CACHE_DIR = chosen


OPTIONS = {"nopython": True, "nogil": True, "error_model": "numpy", "boundscheck": None,
           "no_cfunc_wrapper": True}
"""numba's options for every kernel: ``error_model="numpy"`` lets a division by zero give
inf/NaN (which every certificate then rejects) instead of raising; ``no_cfunc_wrapper``
leaves out the wrapper numba builds for calls through a C function pointer, which nothing
makes (kernels are called from Python or from other kernels)."""


class InternalDispatcher(CPUDispatcher):
    """numba's CPU dispatcher for a kernel compiled without a wrapper for calls from Python:
    such a call would jump into missing code, so it raises instead. Kernels calling it are
    compiled by numba from its Python function, without this method."""

    def __call__(self, *args: Any, **kws: Any) -> Any:
        raise TypeError(f"{self.py_func.__module__}.{self.py_func.__name__} is a kernel "
                        "called only by other kernels (kernel(internal=True)); call the "
                        "kernel that uses it")


def kernel(function: F | None = None, *, interpretable: bool = False,
           inline: bool = False, refcounted: bool = True, internal: bool = False) -> Any:
    """Compile ``function`` with numba on its first call, caching the machine code on disk
    (in :func:`cache_dir`).

    No signature is given, so nothing is compiled at import. ``interpretable`` declares that
    the kernel's work is bounded by the sizes of its arrays (no loop over time steps or
    rows): its first small calls in a process that holds no machine code for it run its
    Python text instead (:mod:`.first_calls`). ``inline`` inlines it into every kernel
    calling it. ``refcounted=False`` compiles it without numba's reference counting: for a
    kernel called in an inner loop that allocates no array and returns none, whose every
    call would otherwise pay two atomic counts per array argument. Used bare (``@kernel``)
    or with arguments.

    ``internal=True`` declares a kernel called only by other kernels, never from Python:
    numba then builds neither of the wrappers a call from Python (or through a C function
    pointer) needs (measured: the LZB stage, whose step, stages, roots and events are such
    helpers, compiles in 12.7 s of CPU instead of 13.1–14.0 s). Its machine code is compiled
    into the kernels calling it (and cached with them); a call from Python raises
    :class:`TypeError` (:class:`InternalDispatcher`).

    What a call between kernels costs to compile: numba links the machine code of every
    kernel a kernel calls (and of every kernel those call) into its own, and LLVM optimises
    and generates all of it again there. A kernel that only calls another kernel called
    from Python pays that kernel's whole compile a second time (measured: the friction
    group of ``impactqp compile`` took 8–10 s less CPU, of 84–87 s, without a kernel that
    only packed a problem and called the packed solve).
    """
    if function is None:
        return lambda f: kernel(f, interpretable=interpretable, inline=inline,
                                refcounted=refcounted, internal=internal)
    if interpretable and internal:
        raise TypeError("a kernel called only by kernels has no first calls from Python to "
                        "interpret: interpretable and internal exclude each other")
    if numba.config.DISABLE_JIT:
        return function
    options = {**OPTIONS, "inline": "always"} if inline else dict(OPTIONS)
    if not refcounted:
        options["_nrt"] = False
    if internal:
        options.update(no_cpython_wrapper=True, no_cfunc_wrapper=True)
    with _cached_in_user_dir():
        if interpretable:
            dispatcher = InterpretableDispatcher(py_func=function, locals={},
                                                 targetoptions=options)
        elif internal:
            dispatcher = InternalDispatcher(py_func=function, locals={}, targetoptions=options)
        else:
            dispatcher = CPUDispatcher(py_func=function, locals={}, targetoptions=options)
        dispatcher.enable_caching()
        return dispatcher


def inline_kernel(function: F | None = None, *, interpretable: bool = False) -> Any:
    """:func:`kernel` for a helper of a few operations, inlined into every kernel calling it
    (a call that is not inlined costs as much as the helper's arithmetic).

    numba inlines it before typing, at every call site, running its front end again each
    time, and an inlined helper's own inlined helpers once per site of it: nested inlining
    multiplies. A small helper under other inlined helpers is better ``kernel(internal=True)``:
    compiled once, and inlined by LLVM into each caller where that pays (check the caller's
    LLVM code for calls left). Measured before the chain certificate's rewrite: the
    residuals' folds, inlined about fifty times into each chain kernel, cost 12 s of the
    155 s of CPU of ``impactqp compile`` (chains stage 5.1 s, 1.5 s without).
    """
    return kernel(function, interpretable=interpretable, inline=True)


def machine_code(dispatcher: Any, *args: Any) -> Callable:
    """The machine code numba has compiled of the kernel ``dispatcher`` for the types of
    ``args``, to be called without numba's dispatch on arguments of exactly those types,
    which it does not check; ``dispatcher`` itself where there is none (not compiled in this
    process: run as Python, or ``NUMBA_DISABLE_JIT``). Typing the arguments in Python takes
    ~40 µs: a caller keeps what it found (laws/friction_small.py, a solve again from a pack)."""
    if not getattr(dispatcher, "overloads", None):  # nothing compiled (yet)
        return dispatcher
    try:
        return dispatcher.overloads[tuple(numba.typeof(a) for a in args)].entry_point
    except (AttributeError, KeyError):
        return dispatcher


def read_only(a: Any) -> Any:
    """A read-only view of the array ``a`` (no copy): a kernel's callers pass arrays with
    one set of flags, since each other set compiles the kernel (and every kernel it calls
    with them) once more. u⁻ is kept read-only by the problems, so callers pass read-only
    velocities.

    Kernels call it too (compiled to nothing but the array itself, typed read-only): a
    kernel whose callers hold its inputs some writable and some read-only is called with
    every input passed through it, and compiles once.
    """
    view = a.view()
    view.setflags(write=False)
    return view


@type_callable(read_only)
def _type_read_only(context: Any) -> Callable:
    def typer(a: Any) -> Any:
        if isinstance(a, types.Array):
            return a.copy(readonly=True)
        return None
    return typer


@lower_builtin(read_only, types.Array)
def _lower_read_only(context: Any, builder: Any, sig: Any, args: Any) -> Any:
    return impl_ret_borrowed(context, builder, sig.return_type, args[0])


NOTICE_AFTER = 1.0
"""Seconds impactqp's kernels may compile before :class:`CompileNotice` says so."""


def _ours(event: numba.core.event.Event) -> bool:
    """The event is the compilation of one of impactqp's kernels."""
    dispatcher = (event.data or {}).get("dispatcher")
    module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
    return module.startswith("impactqp.")


class CompileNotice(numba.core.event.Listener):
    """Says on stderr, once per process, that impactqp is compiling its kernels when a
    compilation has gone on for more than :data:`NOTICE_AFTER` seconds: what happens, that
    it happens once, and where the machine code is kept. A kernel loaded from the disk cache
    raises no compile event, so a warm start stays silent."""

    def __init__(self, stream: Callable[[], TextIO] = lambda: sys.stderr) -> None:
        self.stream = stream
        self.depth = 0
        self.said = False
        self.timer: threading.Timer | None = None

    def message(self) -> str:
        """The notice's one line."""
        where = numba.config.CACHE_DIR or cache_dir()
        return ("impactqp: compiling its numba kernels for this call, once: the machine code "
                f"is cached in {where} (`impactqp compile` compiles every kernel ahead of "
                "time)")

    def say(self) -> None:
        """Write the notice, unless it was written already."""
        if not self.said:
            self.said = True
            print(self.message(), file=self.stream(), flush=True)

    def on_start(self, event: numba.core.event.Event) -> None:
        if not _ours(event):
            return
        self.depth += 1
        if self.depth == 1 and not self.said:
            self.timer = threading.Timer(NOTICE_AFTER, self.say)
            self.timer.daemon = True
            self.timer.start()

    def on_end(self, event: numba.core.event.Event) -> None:
        if not _ours(event):
            return
        self.depth = max(self.depth - 1, 0)
        if self.depth == 0 and self.timer is not None:
            self.timer.cancel()
            self.timer = None


NOTICE = CompileNotice()
numba.core.event.register("numba:compile", NOTICE)
