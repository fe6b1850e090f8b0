"""Active-set polishing: turn an iterative solver's answer into an exact one.

Interior-point and splitting solvers stop at a tolerance; on ill-conditioned impacts
(long chains) a small residual can hide a visible velocity error. Polishing guesses the
active set J from the answer (a constraint is active when its multiplier exceeds its
slack) and solves the equality-constrained KKT system on J directly:

    [P   A_Jᵀ] [ x ]   [ −c  ]
    [A_J  0  ] [−y_J] = [ b_J ]

Redundant contacts make this system singular, so it is solved through the regularized,
quasi-definite matrix (δ on the diagonal) followed by iterative refinement against the
exact one, which converges to an exact solution whenever the system is consistent. The
result is kept only when the caller's certificate accepts it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.optimize import nnls
from scipy.sparse.linalg import lsqr

from .program import QPSolution, QuadraticProgram

REFINEMENT_STEPS = 8


def _regularized_solver(K, shift: np.ndarray) -> Callable[[np.ndarray], np.ndarray] | None:
    """Factor K + diag(shift) once (sparse LU or dense LU); None when that fails."""
    with np.errstate(all="ignore"):
        try:
            if sp.issparse(K):
                lu = spla.splu(sp.csc_matrix(K + sp.diags(shift)))
                return lu.solve
            factors = sla.lu_factor(K + np.diag(shift), check_finite=True)
            return lambda r: sla.lu_solve(factors, r)
        except (RuntimeError, ValueError, np.linalg.LinAlgError):
            return None


def solve_refined(K, rhs: np.ndarray, shift: np.ndarray) -> np.ndarray | None:
    """Solve K s = rhs through K + diag(shift) with iterative refinement on K itself."""
    solve = _regularized_solver(K, shift)
    if solve is None:
        return None
    s = solve(rhs)
    best, best_res = s, np.inf
    for _ in range(REFINEMENT_STEPS):
        r = rhs - K @ s
        res = float(np.abs(r).max(initial=0.0))
        if not np.isfinite(res):
            return None
        if res < best_res:
            best, best_res = s, res
        if res <= 1e-15 * max(float(np.abs(rhs).max(initial=0.0)), 1e-300):
            break
        s = s + solve(r)
    return best


def nonnegative_multipliers(AJ, g: np.ndarray, y0: np.ndarray) -> np.ndarray:
    """y ≥ 0 with A_Jᵀy ≈ g: the solver's own multipliers y0 (≥ 0, nearly right) plus the
    least-norm correction (LSQR); scipy's exact NNLS when that correction leaves y ≥ 0
    violated and the problem is dense."""
    AT = sp.csr_matrix(AJ.T) if sp.issparse(AJ) else np.asarray(AJ).T
    y0 = np.maximum(y0, 0.0)
    d = lsqr(AT, g - AT @ y0, atol=1e-15, btol=1e-15, iter_lim=20 * AT.shape[1])[0]
    y = y0 + d
    if y.min() >= -1e-12 * max(float(np.abs(y).max(initial=0.0)), 1e-300) or sp.issparse(AJ):
        return np.maximum(y, 0.0)
    return nnls(AT, g, maxiter=50 * AT.shape[1])[0]


def polish(qp: QuadraticProgram, sol: QPSolution) -> QPSolution | None:
    """Return the polished solution, or None when the KKT system on the guessed active set
    cannot be solved."""
    slack = qp.slack(sol.x)
    active = np.flatnonzero(sol.y > slack)
    P, c = qp.P, qp.c
    scale = max(float(abs(P).max()), 1e-300)
    delta = 1e-10 * scale
    if qp.nonnegative:
        free = np.setdiff1d(np.arange(qp.n_vars), active)
        x = np.zeros(qp.n_vars)
        if free.size:
            sub = P[free][:, free] if sp.issparse(P) else P[np.ix_(free, free)]
            xf = solve_refined(sub, -c[free], np.full(free.size, delta))
            if xf is None:
                return None
            x[free] = xf
        y = np.asarray(P @ x).ravel() + c
    else:
        AJ = qp.A[active]
        k, j = qp.n_vars, active.size
        if sp.issparse(P) or sp.issparse(AJ):
            K = sp.bmat([[sp.csc_matrix(P), sp.csc_matrix(AJ).T],
                         [sp.csc_matrix(AJ), None]], format="csc") if j else sp.csc_matrix(P)
        else:
            K = np.block([[P, AJ.T], [AJ, np.zeros((j, j))]])
        shift = np.concatenate([np.full(k, delta), np.full(j, -delta)])
        out = solve_refined(K, np.concatenate([-c, qp.constraint_rhs()[active]]), shift)
        if out is None:
            return None
        x = out[:k]
        y = np.zeros(qp.n_constraints)
        y[active] = -out[k:]
        if j and y[active].min() < 0:
            # redundant active rows: the multipliers are a set, and the regularized solve
            # picked one with negative entries; look for a non-negative one for the same x
            y[active] = nonnegative_multipliers(AJ, np.asarray(P @ x).ravel() + c,
                                                sol.y[active])
    return QPSolution(x=x, y=y, status=sol.status, backend=sol.backend,
                      iterations=sol.iterations, info={**sol.info, "polished": True})
