"""Active-set polishing: turn an iterative solver's answer into an exact one.

Interior-point and splitting solvers stop at a tolerance; on ill-conditioned impacts
(long chains) a small residual can hide a visible velocity error. Polishing guesses the
active set J from the answer (a constraint is active when its multiplier exceeds its
slack), solves the equality-constrained KKT system on J directly, and keeps the result
only when it is primal and dual feasible.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .program import QPSolution, QuadraticProgram


def _solve(K, rhs):
    if sp.issparse(K):
        with np.errstate(all="ignore"):
            try:
                out = spla.spsolve(sp.csc_matrix(K), rhs)
            except RuntimeError:
                return None
        return out if np.all(np.isfinite(out)) else None
    sol, *_ = np.linalg.lstsq(K, rhs, rcond=None)
    return sol


def polish(qp: QuadraticProgram, sol: QPSolution) -> QPSolution | None:
    """Return the polished solution, or None when the guessed active set does not work."""
    slack = qp.slack(sol.x)
    active = np.flatnonzero(sol.y > slack)
    P, c = qp.P, qp.c
    if qp.nonnegative:
        free = np.setdiff1d(np.arange(qp.n_vars), active)
        x = np.zeros(qp.n_vars)
        if free.size:
            sub = P[free][:, free] if sp.issparse(P) else P[np.ix_(free, free)]
            xf = _solve(sub, -c[free])
            if xf is None:
                return None
            x[free] = xf
        y = np.asarray(P @ x).ravel() + c
    else:
        A = qp.A
        AJ = A[active]
        k, j = qp.n_vars, active.size
        if sp.issparse(P) or sp.issparse(A):
            K = sp.bmat([[sp.csc_matrix(P), -sp.csc_matrix(AJ).T],
                         [sp.csc_matrix(AJ), None]], format="csc")
            if j == 0:
                K = sp.csc_matrix(P)
        else:
            K = np.block([[P, -AJ.T], [AJ, np.zeros((j, j))]])
        out = _solve(K, np.concatenate([-c, qp.constraint_rhs()[active]]))
        if out is None:
            return None
        x = out[:k]
        y = np.zeros(qp.n_constraints)
        y[active] = out[k:]
    return QPSolution(x=x, y=y, status=sol.status, backend=sol.backend,
                      iterations=sol.iterations, info={**sol.info, "polished": True})
