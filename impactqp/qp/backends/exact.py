"""Exact QP solution by enumeration of active sets (the reference backend).

For a convex QP the KKT conditions are sufficient, so any active set J whose equality-
constrained KKT system has a solution with slack ≥ 0 and multipliers ≥ 0 gives an optimum.
An optimum with linearly independent active rows always exists (Carathéodory), so the
enumeration, smallest sets first, is complete. Cost: up to 2^r small solves.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from ...base.arrays import as_dense
from ...errors import BackendUnsuitableError, NoSolutionError
from ..program import QPSolution, QuadraticProgram

MAX_CONSTRAINTS = 14

MAX_DENSE_VARIABLES = 2_000
"""Largest sparse program this dense backend converts (a dense P of 32 MB)."""


def _nonneg_candidate(P, c, free):
    """x ≥ 0 shape: x_J = 0 on the active set, P_FF x_F = −c_F on the free set F."""
    x = np.zeros(c.size)
    if free.size:
        sub = P[np.ix_(free, free)]
        xf, *_ = np.linalg.lstsq(sub, -c[free], rcond=None)
        x[free] = xf
    y = P @ x + c
    return x, y


def _general_candidate(P, c, A, b, active):
    """General shape: solve [P −A_Jᵀ; A_J 0][x; y_J] = [−c; b_J]."""
    k, j = c.size, active.size
    AJ = A[active]
    K = np.block([[P, -AJ.T], [AJ, np.zeros((j, j))]])
    sol, *_ = np.linalg.lstsq(K, np.concatenate([-c, b[active]]), rcond=None)
    x = sol[:k]
    y = np.zeros(A.shape[0])
    y[active] = sol[k:]
    return x, y


def unsuitable(qp: QuadraticProgram) -> str | None:
    if qp.sparse and qp.n_vars > MAX_DENSE_VARIABLES:
        return (f"'exact' works on dense matrices; {qp.n_vars} variables of a sparse program "
                f"are more than {MAX_DENSE_VARIABLES}")
    if qp.n_constraints > MAX_CONSTRAINTS:
        return (f"'exact' enumerates 2^r active sets; r = {qp.n_constraints} > "
                f"{MAX_CONSTRAINTS} constraints is too many")
    return None


def solve(qp: QuadraticProgram, *, tol: float = 1e-10, solver: str | None = None) -> QPSolution:
    """Enumerate active sets until one satisfies the KKT conditions to ``tol`` (relative)."""
    r = qp.n_constraints
    reason = unsuitable(qp)
    if reason is not None:
        raise BackendUnsuitableError(reason)
    P, c = as_dense(qp.P), np.asarray(qp.c, dtype=float)
    A, b = as_dense(qp.constraint_matrix()), qp.constraint_rhs()
    scale = max(np.abs(c).max(initial=0.0), np.abs(b).max(initial=0.0), 1e-300)
    pscale = max(np.abs(P).max(initial=0.0), 1.0)
    tried = 0
    for size in range(r + 1):
        for active in combinations(range(r), size):
            active = np.array(active, dtype=int)
            tried += 1
            if qp.nonnegative:
                mask = np.ones(r, dtype=bool)
                mask[active] = False
                free = np.flatnonzero(mask)
                x, y = _nonneg_candidate(P, c, free)
            else:
                x, y = _general_candidate(P, c, A, b, active)
            xscale = max(np.abs(x).max(initial=0.0), 1e-300)
            res = qp.kkt_residuals(x, y)
            ok = (res["stationarity"] <= tol * (scale + pscale * xscale)
                  and res["primal"] <= tol * (scale + pscale * xscale)
                  and res["dual"] <= tol * (scale + pscale * xscale))
            if ok:
                return QPSolution(x=x, y=np.maximum(y, 0.0), status="solved", backend="exact",
                                  iterations=tried, info={"active_set": active.tolist()})
    raise NoSolutionError(f"no active set of the {r} constraints satisfies the KKT conditions: "
                          "the program is infeasible or unbounded below (an LCP with no solution)")
