"""The ``"kernel"`` backend: the prepared active-set kernel for small dense LCPs.

Serves the impulse form ``x ≥ 0`` with a dense P of at most
:data:`~impactqp.qp.active_set.MAX_CONTACTS` variables (docs/theory.md §9). The kernel (the
inverses of every invertible principal block of P) is prepared once per program owner and
tag, so repeated impacts of one structure pay only a few tiny products.
"""

from __future__ import annotations

import weakref

import numpy as np

from ...errors import SolverError
from ..active_set import MAX_CONTACTS, ActiveSetKernel
from ..program import QPSolution, QuadraticProgram

_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def unsuitable(qp: QuadraticProgram) -> str | None:
    if qp.sparse:
        return "'kernel' takes dense programs only"
    if not 0 < qp.n_vars <= MAX_CONTACTS:
        return (f"'kernel' takes at most {MAX_CONTACTS} contacts (impulse variables), "
                f"got {qp.n_vars}")
    return None


def prepared(qp: QuadraticProgram) -> ActiveSetKernel:
    """The kernel of ``qp.P``, shared by every program with the same owner and tag."""
    if qp.cache_owner is None:
        return ActiveSetKernel(np.asarray(qp.P, dtype=float))
    return prepared_for(qp.cache_owner, qp.cache_tag, qp.P)


def prepared_for(owner: object, tag: str, P: np.ndarray) -> ActiveSetKernel:
    """The kernel of P kept for (owner, tag): P must be the same matrix at every call."""
    per_owner = _CACHE.setdefault(owner, {})
    kernel = per_owner.get(tag)
    if kernel is None:
        kernel = per_owner[tag] = ActiveSetKernel(np.asarray(P, dtype=float))
    return kernel


def solve(qp: QuadraticProgram, *, tol: float = 1e-10, solver: str | None = None) -> QPSolution:
    lam = prepared(qp).solve(qp.c)
    if lam is None:
        raise SolverError("kernel: no invertible support fits (q is not in the range of P)")
    return QPSolution(x=lam, y=np.maximum(qp.P @ lam + qp.c, 0.0), status="solved",
                      backend="kernel")


def solve_many(qp: QuadraticProgram, C: np.ndarray, *, tol: float = 1e-10,
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(X, Y, solved mask) for the rows of C as linear terms, vectorised over rows."""
    X, done = prepared(qp).solve_batch(C)
    return X, X @ qp.P + C, done
