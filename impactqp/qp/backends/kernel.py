"""The ``"kernel"`` backend: the compiled active-set search for dense LCPs, and the compiled
call that solves a frictional contact problem of a few contacts whole (form ``"friction"``,
docs/theory.md §15).

Serves the impulse form ``x ≥ 0`` with a dense P of at most :data:`MAX_VARIABLES` variables
(docs/theory.md §9) by :func:`impactqp.kernels.active_set.lcp_psd`. The support found last is
kept per program owner and tag, so repeated impacts of one structure start from it; a batch
warm-starts each row from the row before.
"""

from __future__ import annotations

import weakref

import numpy as np

from ...errors import NoSolutionError, SolverError
from ...kernels.active_set import NO_SOLUTION, SOLVED, lcp_psd_rows, solve_lcp_psd
from ..friction import FrictionProgram, FrictionSolution, methods
from ..friction.newton import FrictionData
from ..program import QPSolution, QuadraticProgram

MAX_VARIABLES = 400
"""Most impulse variables served (the search costs O(m³) at most)."""

_WARM: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def unsuitable(qp: QuadraticProgram) -> str | None:
    if qp.sparse:
        return "'kernel' takes dense programs only"
    if not 0 < qp.n_vars <= MAX_VARIABLES:
        return (f"'kernel' takes 1 to {MAX_VARIABLES} contacts (impulse variables), "
                f"got {qp.n_vars}")
    return None


def _warm_start(qp: QuadraticProgram) -> np.ndarray:
    """The support kept for the program's owner and tag (a fresh one without an owner)."""
    if qp.cache_owner is None:
        return np.zeros(qp.n_vars, dtype=bool)
    per_owner = _WARM.setdefault(qp.cache_owner, {})
    passive = per_owner.get(qp.cache_tag)
    if passive is None or passive.size != qp.n_vars:
        passive = per_owner[qp.cache_tag] = np.zeros(qp.n_vars, dtype=bool)
    return passive


def solve(qp: QuadraticProgram, *, tol: float = 1e-10, solver: str | None = None) -> QPSolution:
    x, w, status = solve_lcp_psd(np.asarray(qp.P, dtype=float), qp.c, _warm_start(qp))
    if status == NO_SOLUTION:
        raise NoSolutionError("kernel: the LCP has no solution (a ray x ≥ 0 with Px = 0 and "
                              "cᵀx < 0 makes its QP unbounded below)")
    if status != SOLVED:
        raise SolverError("kernel: the active-set search hit its step bound")
    return QPSolution(x=x, y=np.maximum(w, 0.0), status="solved", backend="kernel")


def solve_many(qp: QuadraticProgram, C: np.ndarray, *, tol: float = 1e-10,
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(X, Y, solved mask) for the rows of C as linear terms."""
    P = np.ascontiguousarray(qp.P, dtype=float)
    X, Y, status = lcp_psd_rows(P, np.ascontiguousarray(C, dtype=float), _warm_start(qp),
                                20 * qp.n_vars + 50)
    return X, Y, status == SOLVED


def unsuitable_friction(program: FrictionProgram) -> str | None:
    if program.n_contacts > methods.SMALL_CONTACTS:
        return (f"'kernel' takes frictional problems of at most {methods.SMALL_CONTACTS} "
                f"contacts, got "
                f"{program.n_contacts}")
    return None


def solve_friction(data: FrictionData, start: np.ndarray | None, *, tol: float,
                   method: str) -> FrictionSolution:
    """The problem whole in one compiled call (:func:`impactqp.qp.friction.methods.small`)."""
    return methods.small(data, tol)
