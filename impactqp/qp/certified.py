"""Run programs on backends until one answer passes the caller's own certificate: the one
certified loop of impactqp, for quadratic programs, cone programs and frictional contact
problems (docs/theory.md §9).

The caller hands a :class:`Plan` (form, program, ``finish``: the caller's recovery of its
answer from the backend's solution together with its certificate, and the backends to try):
``"auto"`` lists them from the registry, a named backend is tried alone. Iterative
answers are polished (docs/theory.md §9, §15) and quadratic and cone programs retried once
with a tighter tolerance; a failed certificate never becomes a success. Every QP backend sees
the program normalized to order one (:mod:`.scaling`), so answers do not depend on units. This
layer knows nothing of impacts: the certificate is whatever ``finish`` returns, and the
backend an answer reports is always a name the caller can pass back.
"""

from __future__ import annotations

import logging
import math
import time
import weakref
from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

import numpy as np

from ..base.checks import ResidualChecks
from ..errors import (
    BackendUnsuitableError,
    CertificateError,
    InputError,
    NoSolutionError,
    SolverError,
    UnknownBackendError,
)
from . import backends
from .backends.exact import MAX_CONSTRAINTS
from .friction.order import friction_order
from .kinds import kind_of
from .program import QuadraticProgram

Finish = Callable[[Any], tuple[Any, ResidualChecks]]
"""The caller's recovery of its answer from a backend's solution, with its certificate."""

LOG = logging.getLogger(__name__)


def _verdict(cert: ResidualChecks) -> None:
    """The certificate's residuals at DEBUG (formatted only when someone listens)."""
    if LOG.isEnabledFor(logging.DEBUG):
        LOG.debug("certificate %s", cert.summary())


def _note(log: list[str], message: str, level: int = logging.DEBUG) -> None:
    """Record one attempt in the result's ``attempts`` and in the ``impactqp`` log."""
    log.append(message)
    LOG.log(level, message)

FAST_PATHS = ("kernel", "isotonic")
"""Exact special-structure backends that ``"auto"`` tries before any general one."""


class Plan(NamedTuple):
    """The ways to try one program of a given form: its ``backends`` in order, and
    ``checked`` when each is known to take the program (else the loop asks when it gets
    there)."""

    form: str
    program: Any
    finish: Finish
    backends: Sequence[str]
    checked: bool = True


class Outcome(NamedTuple):
    """A certified answer and how it was reached: the backend's ``solution`` it was recovered
    from and the registry name of the ``backend`` (one the caller may pass back)."""

    answer: Any
    checks: ResidualChecks
    solution: Any
    backend: str
    form: str
    attempts: list[str]


def auto_order(qp: Any, form: str) -> list[str]:
    """The backends ``"auto"`` tries on ``qp``, least overhead and exact first. Cone and
    friction programs: :data:`~impactqp.qp.backends.AUTO_ORDER` (whether each takes ``qp`` is
    asked when the loop reaches it: most answers come from the first). Quadratic programs
    (measured in benchmarks/): the kernel and isotonic regression beat every QP solver where
    they apply; NNLS is exact and fastest on dense impulse forms; PIQP is 3–5× faster than
    Clarabel on sparse impacts of 10⁴ contacts and as accurate after polishing; that order
    depends on the program's shape only, so it is kept per owner and tag."""
    if form == backends.FRICTION:  # the repairs' place depends on the size (docs/theory.md §22)
        return friction_order(backends.AUTO_ORDER[form], qp)
    if form not in backends.FORMS:
        return list(backends.AUTO_ORDER[form])
    if qp.cache_owner is None:
        return _auto_order(qp, form)
    per_owner = _ORDERS.setdefault(qp.cache_owner, {})
    key = (qp.cache_tag, form)
    if key not in per_owner:
        per_owner[key] = _auto_order(qp, form)
    return per_owner[key]


_ORDERS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _auto_order(qp: QuadraticProgram, form: str) -> list[str]:
    names: list[str] = []
    for name in ("kernel", "isotonic", "nnls"):
        entry = backends.REGISTRY[name]
        if backends.unsuitable(entry, qp, form) is None:
            names.append(name)
    if qp.sparse and backends._importable("piqp") and backends._importable("qpsolvers"):
        names.append("qpsolvers:piqp")
    small = qp.n_constraints <= 10
    if small:
        names.append("exact")
    names += [name for name in ("clarabel", "osqp")
              if backends.unsuitable(backends.REGISTRY[name], qp, form) is None]
    if not small and qp.n_constraints <= MAX_CONSTRAINTS:
        names.append("exact")
    return names


def plan(form: str, qp: Any, finish: Finish, backend: str) -> Plan:
    """The plan for one program: the auto order, or the named backend alone.

    Raises
    ------
    UnknownBackendError
        Unknown or uninstalled backend.
    BackendUnsuitableError
        A named backend that cannot take the program (the message says why).
    """
    if backend == "auto":
        return Plan(form, qp, finish, auto_order(qp, form), form in backends.FORMS)
    entry, _ = backends.parse_backend(backend)
    reason = backends.unsuitable(entry, qp, form)
    if reason is not None:
        raise BackendUnsuitableError(reason)
    return Plan(form, qp, finish, (backend,))


Stage = tuple[str, Callable[[], Any], Finish]


def solve_in_forms(stages: Sequence[Stage], backend: str,
                   options: dict | None = None) -> Outcome:
    """Solve the first form (form, build the program, finish) that gives a certified answer;
    a program is built only when its form is reached (the impulse form of a long chain
    would form its Delassus matrix for nothing). ``options`` go to the named backend's solver
    (validated by :func:`~impactqp.qp.backends.check_options`).

    Raises
    ------
    UnknownBackendError
        Unknown or uninstalled backend.
    BackendUnsuitableError
        A named backend that suits none of the forms (the message says why).
    NoSolutionError
        An impulse-form LCP without a feasible point.
    CertificateError
        No form and backend gave an answer within the certificate's tolerance.
    """
    unsuitable, failures, log = [], [], []
    for form, build, finish in stages:
        try:
            planned = plan(form, build(), finish, backend)
        except BackendUnsuitableError as exc:
            unsuitable.append(str(exc))
            LOG.info("%s form refused by %s: %s", form, backend, exc)
            continue
        try:
            out = solve_certified(planned, named=backend != "auto", options=options)
        except CertificateError as exc:
            failures.append(str(exc))
            _note(log, f"{form} form: {exc}", logging.INFO)
            continue
        return Outcome(out.answer, out.checks, out.solution, out.backend, out.form,
                       log + out.attempts)
    if failures:
        raise CertificateError("; ".join(failures))
    raise BackendUnsuitableError("; ".join(dict.fromkeys(unsuitable)))


def _work(sol: Any, seconds: float) -> str:
    """What an attempt cost, for its note: its iterations where the solution counts them,
    and its time (polish included)."""
    its = getattr(sol, "iterations", None)
    return f" after {its} iterations, {seconds:.3g} s" if its is not None else \
        f" after {seconds:.3g} s"


def _better(new: ResidualChecks, old: ResidualChecks) -> bool:
    a, b = new.worst[1], old.worst[1]
    return new.ok and (not old.ok or not math.isfinite(b) or a <= b)


def solve_certified(planned: Plan, *, named: bool, tol: float = 1e-10,
                    options: dict | None = None) -> Outcome:
    """The one certified loop: try each backend of the plan until an answer passes its
    certificate, for quadratic programs, cone programs and frictional contact problems
    alike (how each kind is run and polished: :mod:`.kinds`). Iterative answers are polished
    and kept when their certificate is at least as good; every attempt is recorded.

    Raises
    ------
    UnknownBackendError, BackendUnsuitableError
        A named backend that is not installed or cannot take the program.
    NoSolutionError
        The impulse-form LCP has no feasible point (the law has no solution).
    CertificateError
        No backend produced an answer within the certificate's tolerance; its ``best`` is
        the :class:`Outcome` whose certificate came closest (None if no backend answered)
        and ``attempts`` every attempt.
    """
    form, program, finish = planned.form, planned.program, planned.finish
    log: list[str] = []
    kind = kind_of(form)
    warm, warm_value = None, math.inf  # the best uncertified answer, where a method starts
    best: Outcome | None = None  # and as the caller will see it, if nothing certifies
    for name in planned.backends:
        entry, sub = backends.parse_backend(name)
        try:
            module = backends.load(entry)
        except UnknownBackendError:
            if named:
                raise
            _note(log, f"{name}: not installed", logging.INFO)
            continue
        if not planned.checked:
            reason = backends.unsuitable(entry, program, form)
            if reason is not None:
                _note(log, f"{name}: unsuitable ({reason})")
                continue
        prepared = kind.prepare(entry, program)
        for attempt_tol in kind.tolerances(entry, tol):
            began = time.perf_counter()
            try:
                raw = kind.run(module, entry, sub, prepared, attempt_tol, options, warm)
            except InputError:  # the user's options: theirs to mend, not a solver failure
                raise
            except (BackendUnsuitableError, UnknownBackendError) as exc:
                if named:
                    raise
                _note(log, f"{name}: unsuitable ({exc})", logging.INFO)
                break
            except (SolverError, NoSolutionError, FloatingPointError, ValueError,
                    np.linalg.LinAlgError) as exc:
                _note(log, f"{name} ({form}): {exc}")
                if entry.exact:
                    break
                continue
            sol = kind.solution(prepared, raw)
            answer, cert = finish(sol)
            if not entry.exact:
                polished = kind.polish(prepared, raw, attempt_tol)
                if polished is not None:
                    sol_p = kind.solution(prepared, polished)
                    answer_p, cert_p = finish(sol_p)
                    if _better(cert_p, cert):
                        _note(log, f"{sol.backend} ({form}): polished, certified")
                        _verdict(cert_p)
                        return Outcome(answer_p, cert_p, sol_p, sol.backend, form, log)
            if cert.ok:
                _note(log, f"{sol.backend} ({form}): certified")
                _verdict(cert)
                return Outcome(answer, cert, sol, sol.backend, form, log)
            worst, value = cert.worst
            if value < warm_value:
                warm, warm_value = sol, value
                best = Outcome(answer, cert, sol, sol.backend, form, log)
            _note(log, f"{name} ({form}, tol {attempt_tol:.0e}): certificate failed, "
                       f"{worst} = {value:.1e}{_work(sol, time.perf_counter() - began)}")
    failure = kind.failure(program, log)
    if isinstance(failure, CertificateError):
        failure.best, failure.attempts = best, list(log)
    raise failure
