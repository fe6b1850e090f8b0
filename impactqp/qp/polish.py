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

import logging
import warnings
from collections.abc import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..kernels.nnls import solve_nnls
from .program import QPSolution, QuadraticProgram

LOG = logging.getLogger(__name__)

REFINEMENT_STEPS = 8


def _regularized_solver(K, shift: np.ndarray) -> Callable[[np.ndarray], np.ndarray] | None:
    """Factor K + diag(shift) once (sparse LU or dense LU); None when that fails."""
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", sla.LinAlgWarning)
        warnings.simplefilter("ignore", spla.MatrixRankWarning)
        try:
            if sp.issparse(K):
                lu = spla.splu(sp.csc_matrix(K + sp.diags(shift)))
                return lu.solve
            factors = sla.lu_factor(K + np.diag(shift), check_finite=True)
            return lambda r: sla.lu_solve(factors, r)
        except (RuntimeError, ValueError, np.linalg.LinAlgError):
            return None


def solve_refined(K, rhs: np.ndarray, shift: np.ndarray) -> np.ndarray | None:
    """Solve K s = rhs with iterative refinement against K: through a factorization of K
    itself when it has one (exact, also when ill-conditioned), else of K + diag(shift)
    (singular K: redundant contacts). Returns the iterate with the smallest residual."""
    best, best_res = None, np.inf
    target = 1e-14 * max(float(np.abs(rhs).max(initial=0.0)), 1e-300)
    for trial in (np.zeros_like(shift), shift):
        solve = _regularized_solver(K, trial)
        if solve is None:
            continue
        s, res = _refine(K, rhs, solve)
        if res < best_res:
            best, best_res = s, res
        if best_res <= target:
            break
    return best


def _refine(K, rhs: np.ndarray, solve) -> tuple[np.ndarray | None, float]:
    """Iterative refinement from solve(rhs); the iterate with the smallest residual."""
    best, best_res = None, np.inf
    with np.errstate(all="ignore"):
        s = solve(rhs)
        for _ in range(REFINEMENT_STEPS):
            r = rhs - K @ s
            res = float(np.abs(r).max(initial=0.0))
            if not np.isfinite(res):
                break
            if res < best_res:
                best, best_res = s, res
            if res <= 1e-15 * max(float(np.abs(rhs).max(initial=0.0)), 1e-300):
                break
            s = s + solve(r)
    return best, best_res


def least_norm_step(B, r: np.ndarray, delta: float) -> np.ndarray | None:
    """d of least norm with Bᵀd = r (B of shape (j, n)), from the system [I B; Bᵀ 0]."""
    j, n = B.shape
    if sp.issparse(B):
        Bc = sp.csc_matrix(B)
        K = sp.bmat([[sp.identity(j, format="csc"), Bc], [Bc.T, None]], format="csc")
    else:
        K = np.block([[np.eye(j), B], [B.T, np.zeros((n, n))]])
    shift = np.concatenate([np.zeros(j), np.full(n, -delta)])
    out = solve_refined(K, np.concatenate([np.zeros(j), r]), shift)
    return None if out is None else out[:j]


def nonnegative_multipliers(AJ, g: np.ndarray, y0: np.ndarray, delta: float) -> np.ndarray:
    """y ≥ 0 with A_Jᵀy = g: the solver's own multipliers y0 (≥ 0, nearly right) plus the
    least-norm correction; the exact NNLS of the compiled active-set search when that
    correction breaks y ≥ 0 on a dense problem."""
    y0 = np.maximum(y0, 0.0)
    d = least_norm_step(AJ, g - np.asarray(AJ.T @ y0).ravel(), delta)
    y = y0 + (d if d is not None else 0.0)
    if y.min() >= -1e-12 * max(float(np.abs(y).max(initial=0.0)), 1e-300) or sp.issparse(AJ):
        return np.maximum(y, 0.0)
    return solve_nnls(np.asarray(AJ).T, g)[0]


ACTIVE_SET_ROUNDS = 6


def _solve_on(qp: QuadraticProgram, sol: QPSolution, active: np.ndarray, delta: float,
              ) -> tuple[np.ndarray, np.ndarray] | None:
    """(x, y) solving the KKT system with the rows in ``active`` held as equalities."""
    P, c = qp.P, qp.c
    if qp.nonnegative:
        free = np.setdiff1d(np.arange(qp.n_vars), active)
        x = np.zeros(qp.n_vars)
        if free.size:
            # P_FF x_F = −c_F, reached from the solver's x by the least-norm step: the unique
            # solution when P_FF is invertible, else the nearest point of the solution set
            # (redundant contacts), which keeps x ≥ 0 when the solver's x is interior
            sub = P[free][:, free] if sp.issparse(P) else P[np.ix_(free, free)]
            x0 = np.maximum(sol.x[free], 0.0)
            d = least_norm_step(sub, -c[free] - np.asarray(sub @ x0).ravel(), delta)
            if d is None:
                return None
            x[free] = x0 + d
        return x, np.asarray(P @ x).ravel() + c
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
                                            sol.y[active], delta)
    return x, y


def polish(qp: QuadraticProgram, sol: QPSolution) -> QPSolution | None:
    """Return the polished solution, or None when no KKT system could be solved.

    The first active set is the solver's (multiplier ≥ slack); when its solution violates a
    sign (x_F < 0 or y_J < 0 in the impulse form, slack < 0 or y_J < 0 otherwise), the
    offending rows change sides and the system is solved again, a few rounds at most.
    """
    slack = qp.slack(sol.x)
    active = np.flatnonzero(sol.y >= slack)  # a tie (both 0) is a degenerate active row
    scale = max(float(abs(qp.P).max()), 1e-300)
    delta = 1e-10 * scale
    best = None
    for _ in range(ACTIVE_SET_ROUNDS):
        found = _solve_on(qp, sol, active, delta)
        if found is None:
            break
        x, y = found
        best = (x, y)
        s = qp.slack(x)
        tiny = 1e-14 * max(float(np.abs(x).max(initial=0.0)), float(np.abs(y).max(initial=0.0)),
                           1e-300)
        drop = active[y[active] < -tiny]
        inactive = np.setdiff1d(np.arange(qp.n_constraints), active)
        add = inactive[s[inactive] < -tiny]
        if drop.size == 0 and add.size == 0:
            break
        LOG.debug("polish: active set of %d rows changes (%d leave, %d join)", active.size,
                  drop.size, add.size)
        active = np.union1d(np.setdiff1d(active, drop), add)
    if best is None:
        return None
    x, y = best
    return QPSolution(x=x, y=y, status=sol.status, backend=sol.backend,
                      iterations=sol.iterations, info={**sol.info, "polished": True})
