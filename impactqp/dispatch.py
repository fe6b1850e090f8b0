"""Run a QP on a list of backends until one answer passes the law's own certificate.

``"auto"`` tries an ordered list of backends; a named backend is tried alone (tightened and
polished before giving up). A failed certificate never becomes a success.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable
from functools import cache
from typing import TypeVar

import numpy as np
from scipy.optimize import linprog

from .backends import get_backend
from .backends.exact import MAX_CONSTRAINTS
from .backends.nnls_ import MAX_VARIABLES
from .certificate import ResidualChecks
from .errors import (
    BackendUnsuitableError,
    CertificateError,
    NoSolutionError,
    SolverError,
    UnknownBackendError,
)
from .polish import polish
from .program import QPSolution, QuadraticProgram

T = TypeVar("T")
EXACT = ("exact", "nnls")
Finish = Callable[[QPSolution], tuple[T, ResidualChecks]]


def auto_backends(qp: QuadraticProgram) -> list[str]:
    """The backends ``"auto"`` tries, fastest correct first."""
    names: list[str] = []
    if qp.nonnegative and not qp.sparse and qp.n_vars <= MAX_VARIABLES:
        names.append("nnls")
    if qp.sparse and _installed("piqp") and _installed("qpsolvers"):
        # measured (benchmarks/): 3-5x faster than Clarabel on sparse impacts of 10⁴
        # contacts, and as accurate after polishing; an optional extra ("solvers")
        names.append("qpsolvers:piqp")
    if qp.n_constraints <= 10:
        names.append("exact")
    names += ["clarabel", "osqp"]
    if qp.n_constraints <= MAX_CONSTRAINTS and "exact" not in names:
        names.append("exact")
    return names


@cache
def _installed(module: str) -> bool:
    return importlib.util.find_spec(module) is not None


def lcp_feasible(qp: QuadraticProgram) -> bool:
    """For the impulse form: is there x ≥ 0 with Px + c ≥ 0? (For PSD P: solvable iff so.)"""
    res = linprog(np.zeros(qp.n_vars), A_ub=-qp.P, b_ub=qp.c, bounds=(0, None), method="highs")
    return bool(res.status == 0)


def solve_certified(qp: QuadraticProgram, backend: str, finish: Finish,
                    *, tol: float = 1e-10) -> tuple[T, ResidualChecks, str, list[str]]:
    """Solve ``qp`` and return (answer, certificate, backend used, log of attempts).

    Raises
    ------
    UnknownBackendError
        Bad backend name or a backend that is not installed.
    NoSolutionError
        The law has no solution (an infeasible LCP).
    CertificateError
        No backend produced an answer within the certificate's tolerance.
    """
    names = auto_backends(qp) if backend == "auto" else [backend]
    log: list[str] = []
    for name in names:
        fn, sub = get_backend(name)
        for attempt_tol in ((tol,) if name in EXACT else (tol, tol * 1e-2)):
            try:
                sol = fn(qp, tol=attempt_tol, solver=sub)
            except BackendUnsuitableError as exc:
                if backend != "auto":
                    raise
                log.append(f"{name}: unsuitable ({exc})")
                break
            except UnknownBackendError:
                if backend != "auto":
                    raise
                log.append(f"{name}: not installed")
                break
            except SolverError as exc:
                log.append(f"{name}: {exc}")
                continue
            answer, cert = finish(sol)
            if name not in EXACT:
                # iterative answers stop at a tolerance: try the exact active-set solve and
                # keep it when its own certificate is at least as good. Small residuals do
                # not mean accurate velocities on ill-conditioned impacts (a 10⁵-ball chain
                # passes at 1e-9 with velocities off by 1e-6), so this is always tried.
                polished = polish(qp, sol)
                if polished is not None:
                    answer_p, cert_p = finish(polished)
                    if cert_p.ok and (not cert.ok or cert_p.worst[1] <= cert.worst[1]):
                        return answer_p, cert_p, f"{sol.backend}+polish", log
            if cert.ok:
                return answer, cert, sol.backend, log
            log.append(f"{name} (tol {attempt_tol:.0e}): certificate failed, "
                       f"{cert.worst[0]} = {cert.worst[1]:.1e}")
    if qp.nonnegative and not lcp_feasible(qp):
        raise NoSolutionError("the LCP 0 ≤ Λ ⟂ GΛ + q ≥ 0 has no feasible point, so the law "
                              "has no solution for this pre-impact velocity")
    raise CertificateError("no backend met the certificate: " + "; ".join(log))
