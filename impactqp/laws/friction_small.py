"""The route of a frictional problem of a few contacts: one compiled call and a thin result
(docs/theory.md §15).

:func:`solve_few` hands W (dense, or compressed as scipy holds it), q and μ to
:func:`impactqp.kernels.friction_packed.pack`, which poses the problem in its contacts'
units, and the pack to :func:`impactqp.kernels.friction_packed.solve_packed`, which solves
it by the ``"kernel"`` method (or, for a few dozen contacts, sweeps it once), scales the
answer back and recomputes its certificate from W and q as given, and returns the verdict.
The pack is kept on the problem: a problem solved again is solved from it. Nothing but the
verdict is turned into Python objects at the call: the :class:`SmallFrictionResult` holds
the array the call filled (r, u, the certificate's figures and the iterations) and builds
the certificate, the error and the attempts from it when they are read.

A solve again of a 1-contact problem takes about 2.4 µs of thread CPU (quiet machine): the
compiled work about 1.0 µs (unpacking the pack ~0.2, the sweep ~0.4 with a sliding
contact's slip-angle search 0.13–0.44, the certificate ~0.4), numba's call boundary about
0.2 µs (~45 ns an argument; a returned tuple would add ~40 ns, so the call returns one
integer and writes the iterations into its array), the new array ~0.13 µs, and the
Python around it the rest (:func:`impactqp.solve_friction`'s checks ~0.3 µs,
:meth:`~impactqp.FrictionContactProblem.holds` ~0.13, the result ~0.17). So each step of
the path is counted: a solve from a pack takes its path first, the result is one entry in a
new object's dictionary (:class:`SmallFrictionResult`), what a pack's solves share is built
once with the pack (:class:`_Packed`), the machine code they call is found once, to be
called without numba's dispatch (:data:`_solve_from_pack`), and the route takes no frame it
does not need.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cached_property
from time import perf_counter
from typing import NamedTuple

import numpy as np

from ..kernels.friction import kernel_mu
from ..kernels.friction_packed import answer_size, pack, solve_packed
from ..kernels.friction_tiny import CERTIFIED, FRICTION_FIGURES
from ..kernels.jit import machine_code
from ..model.friction import FrictionCertificate, FrictionContactProblem, friction_certificate
from ..qp.friction import methods
from ..qp.friction.newton import NEWTON_STEPS
from .result import FrictionResult

__all__ = ["SmallFrictionResult", "solve_few"]

_DENSE = (np.empty(0, dtype=np.int32), np.empty(0, dtype=np.int32), np.empty(0), False)
"""The ``rows`` of :func:`~impactqp.kernels.friction_packed.pack` for a dense W."""
_NO_W = np.empty((0, 0))
"""The ``W`` of :func:`~impactqp.kernels.friction_packed.pack` for a compressed W."""
_FIGURES = len(FRICTION_FIGURES)
_KEPT = "_kept"
"""The attribute of a problem :func:`solve_few` has solved, a :class:`_Kept`
(:attr:`FrictionContactProblem._kept <impactqp.model.friction.FrictionContactProblem._kept>`)."""
_SCALED = 4
"""The entry of a packed problem's integer array that says whether its units are not all 1
(:data:`~impactqp.kernels.friction_packed.PACKED_HEADER`)."""
SWEPT_CONTACTS = 64
"""Most contacts of a problem beyond :data:`~impactqp.qp.friction.methods.SMALL_CONTACTS`
whose first sweep :func:`solve_few` tries in one compiled call before the general route:
where it does not certify, the general route starts over, and it cost 2–3 % of that route's
time on the FCLib problems of 52 to 60 contacts (65 µs of 2.4 ms on Confeti-ex03)."""

_new = object.__new__
_empty = np.empty


class SmallFrictionResult(FrictionResult):
    """A :class:`~impactqp.friction.FrictionResult` of :func:`solve_few`: the same attributes,
    each read from the compiled call when first asked for.

    A new result holds one entry, ``_call``: (the array the call filled with r, u, the
    certificate's figures and the iterations, then its work
    (:func:`~impactqp.kernels.friction_packed.answer_size`), the tolerance, the seconds, the
    route), the route
    (d·m, whether the problem was posed in other units than given, the method's name) shared
    by the results of one pack. A Python object's every further attribute costs about 25 ns
    to set and free, a tenth of a solve again's Python; a plain tuple, not a named one
    (about 0.3 µs to make). ``ok`` (hence ``success`` and ``status``) is the compiled call's
    verdict on the figures it computed; ``certificate`` is the
    :class:`~impactqp.friction.FrictionCertificate` of the same figures, whose ``ok`` is that
    verdict (the same comparisons, NaN failing both).
    """

    @property
    def ok(self) -> bool:
        """True: only a certified call makes this result (``certificate.ok`` says the same)."""
        return "_call" in self.__dict__ or self.certificate.ok

    @cached_property
    def r(self) -> np.ndarray:  # type: ignore[override]
        out, _, _, (size, _, _) = self._call
        return out[:size]

    @cached_property
    def u(self) -> np.ndarray:  # type: ignore[override]
        out, _, _, (size, _, _) = self._call
        return out[size:2 * size]

    @cached_property
    def certificate(self) -> FrictionCertificate:  # type: ignore[override]
        out, tol, _, (size, _, _) = self._call
        return friction_certificate(out[2 * size:2 * size + _FIGURES], tol)

    @cached_property
    def error(self) -> float:  # type: ignore[override]
        return self.certificate.error

    @cached_property
    def iterations(self) -> int:  # type: ignore[override]
        out, _, _, (size, _, _) = self._call
        return int(out[2 * size + _FIGURES])  # where the call wrote them (iterations_at)

    @cached_property
    def solve_time(self) -> float:  # type: ignore[override]
        return self._call[2]

    @cached_property
    def backend(self) -> str:  # type: ignore[override]
        return self._call[3][2]

    @cached_property
    def attempts(self) -> list[str]:  # type: ignore[override]
        _, scaled, backend = self._call[3]
        note = ["solved in its contacts' units (2^0)"] if scaled else []
        return [*note, f"{backend} (friction): certified"]


def solve_few(problem: FrictionContactProblem, tol: float, start: float,
              sweeps: bool = True) -> SmallFrictionResult | None:
    """The certified answer of one compiled solve
    (:func:`impactqp.kernels.friction_packed.solve_packed`), ``start`` the
    ``time.perf_counter()`` of the solve's start: for at most
    :data:`~impactqp.qp.friction.methods.SMALL_CONTACTS` contacts the ``"kernel"``
    method's; with ``sweeps``, for at most :data:`SWEPT_CONTACTS`, that of one sweep of the
    projected Gauss–Seidel (the first sweep of the ``"nsgs-short"`` method). None where the
    problem has more contacts, q in contact units needs the scale-first rule, or the call's
    answer fails its certificate: the general route then runs (and tries the method again
    among the others).

    A problem solved is kept packed (:func:`~impactqp.kernels.friction_packed.pack`:
    posed in its contacts' units, with its diagonal blocks and their steps) on the problem, as
    :meth:`~impactqp.FrictionContactProblem.in_contact_units` keeps its units: later solves
    start from it. The pack is made by a call of its own, not inside the solve (which would
    cost ``impactqp compile`` 6–10 s of CPU, see
    :mod:`~impactqp.kernels.friction_packed`), so the first solve keeps it for the cost
    of one assignment; a problem that no
    longer :meth:`~impactqp.FrictionContactProblem.holds` the state it was packed in (q
    rewritten, W or μ replaced) is solved from its arrays and packed again. Every call fills
    an array of its own: a result is never changed by a later solve.
    """
    kept = problem._kept
    if kept is not None and (sweeps or kept.small) and problem.holds(kept.state):
        packed = kept.packed  # solved before, in the state packed: the same d·m and route
        out = _empty(packed.out_size)
        if _solve_from_pack(packed.floats, packed.ints, tol, out) != CERTIFIED:
            return None
        result = _new(SmallFrictionResult)
        result.__dict__["_call"] = (out, tol, perf_counter() - start, packed.route)
        return result
    m = problem.n_contacts
    small = m <= methods.SMALL_CONTACTS  # the "kernel" method's own limit
    if not (small or (sweeps and m <= SWEPT_CONTACTS)):
        return None
    state = problem.state()
    packed, out, outcome = _pack(problem, small, tol)
    problem._kept = _Kept(state, small, packed)  # one assignment
    if outcome != CERTIFIED:
        return None
    result = _new(SmallFrictionResult)
    result.__dict__["_call"] = (out, tol, perf_counter() - start, packed.route)
    return result


class _Packed(NamedTuple):
    """A problem packed by :func:`~impactqp.kernels.friction_packed.pack` (``floats``,
    ``ints``), the size of the array a solve of it fills and the route its results share
    (see :class:`SmallFrictionResult`)."""

    floats: np.ndarray
    ints: np.ndarray
    out_size: int
    route: tuple[int, bool, str]


def _pack(problem: FrictionContactProblem, small: bool,
          tol: float) -> tuple[_Packed, np.ndarray, int]:
    """``problem`` packed for the ``"kernel"`` method (``small``) or the first sweep of
    ``"nsgs-short"``, and its solve at ``tol`` through numba's dispatch (which compiles,
    loads or interprets :func:`~impactqp.kernels.friction_packed.solve_packed` as it must,
    and from which :data:`_solve_from_pack` takes the machine code): the :class:`_Packed`,
    the array the solve filled and its outcome."""
    global _solve_from_pack
    floats, ints = pack(*_given(problem), _budgets(small))
    size = problem.q.size
    out = np.empty(answer_size(size))
    outcome = _solve_from_pack(floats, ints, tol, out)
    if _solve_from_pack is solve_packed:
        _solve_from_pack = machine_code(solve_packed, floats, ints, tol, out)
    route = (size, bool(ints[_SCALED]), "kernel" if small else "nsgs-short")
    return _Packed(floats, ints, out.size, route), out, outcome


_solve_from_pack: Callable[..., int] = solve_packed
"""What solves a pack (:func:`solve_few`): :func:`~impactqp.kernels.friction_packed.solve_packed`
through numba's dispatch until a pack's first solve (:func:`_pack`) finds its machine code
(:func:`~impactqp.kernels.jit.machine_code`), that code from then on, called without the
dispatch (typing each argument and finding the code: ~0.15 µs of a ~3 µs solve again).
Every argument of a solve from a pack is of the types that code was compiled for: the
pack's two arrays (:func:`~impactqp.kernels.friction_packed.pack` makes them), the float
``tol`` (:func:`~impactqp.base.arrays.check_tol`) and a new float array. Kept in the module,
not on the problem: a problem with its pack still pickles."""


class _Kept:
    """What :func:`solve_few` keeps on a problem it has solved: the problem's
    :meth:`~impactqp.FrictionContactProblem.state` it solved, whether by the ``"kernel"``
    method (``small``), and the :class:`_Packed` problem, made at once and set in one
    assignment (a thread solving the same problem sees all of it or none)."""

    __slots__ = ("state", "small", "packed")

    def __init__(self, state: tuple, small: bool, packed: _Packed) -> None:
        self.state, self.small, self.packed = state, small, packed


def _given(problem: FrictionContactProblem) -> tuple:
    """(W, rows, q, μ, d) of :func:`~impactqp.kernels.friction_packed.pack` for
    ``problem``: W dense, or its compressed arrays (CSC kept as columns, other formats as
    CSR rows)."""
    W = problem.W
    if isinstance(W, np.ndarray):
        W = np.ascontiguousarray(W)
        rows = _DENSE
    else:
        form = W.format  # a property: ~0.1 µs a read
        if form not in ("csr", "csc"):
            W, form = W.tocsr(), "csr"
        rows = (W.indptr.astype(np.int32, copy=False), W.indices.astype(np.int32, copy=False),
                np.asarray(W.data, dtype=float), form == "csc")
        W = _NO_W
    return W, rows, problem.q, kernel_mu(problem.mu), problem.contact_dim


def _budgets(small: bool) -> tuple[int, int, int, bool]:
    """(Newton steps, sweeps, local iterations, whole) of the ``"kernel"`` method
    (``small``) or of the first sweep of ``"nsgs-short"``."""
    return (NEWTON_STEPS, methods.NSGS_SHORT,
            methods.SMALL_LOCAL if small else methods.NSGS_LOCAL, small)
