"""Exact impulse-form solve by non-negative least squares (docs/theory.md §3, §9).

With P = BᵀB and c = Bᵀd,  ½xᵀPx + cᵀx = ½‖Bx + d‖² − ½‖d‖², so the QP over x ≥ 0 is the
NNLS problem min ‖Bx − (−d)‖. The compiled active-set search of
:mod:`impactqp.kernels.active_set` finds the support and the final least-squares solve runs
on the factor B itself. Programs without a factor, or whose c is not in the range of P (then
no such d exists), are solved by the same search on P and c directly.
"""

from __future__ import annotations

import numpy as np

from ...errors import BackendUnsuitableError, NoSolutionError, SolverError
from ...kernels.active_set import NO_SOLUTION, SOLVED, solve_lcp_psd
from ...kernels.nnls import nnls
from ..program import QPSolution, QuadraticProgram

MAX_VARIABLES = 400


def unsuitable(qp: QuadraticProgram) -> str | None:
    if not qp.nonnegative:
        return "'nnls' solves only the impulse form (x ≥ 0)"
    if qp.sparse or qp.n_vars > MAX_VARIABLES:
        return (f"'nnls' is dense and takes at most {MAX_VARIABLES} variables "
                f"({qp.n_vars}{', sparse' if qp.sparse else ''})")
    return None


def _factor_form(qp: QuadraticProgram) -> tuple[np.ndarray, np.ndarray] | None:
    """(B, d) with P = BᵀB and c = Bᵀd, when the program carries them and they fit."""
    B, d = qp.factor, qp.factor_rhs
    if B is None or d is None:
        return None
    B = np.asarray(B, dtype=float)
    miss = np.abs(B.T @ d - qp.c).max(initial=0.0)
    scale = np.abs(qp.c).max(initial=0.0) + np.abs(B).max(initial=0.0) * np.abs(d).max(initial=0.0)
    return (B, np.asarray(d, dtype=float)) if miss <= 1e-10 * scale else None


def solve(qp: QuadraticProgram, *, tol: float = 1e-10, solver: str | None = None) -> QPSolution:
    """Solve the impulse form x ≥ 0 exactly (refuse other shapes)."""
    reason = unsuitable(qp)
    if reason is not None:
        raise BackendUnsuitableError(reason)
    P = np.asarray(qp.P, dtype=float)
    factored = _factor_form(qp)
    if factored is not None:
        B, d = factored
        x, _, status = nnls(np.ascontiguousarray(B), -d, 20 * qp.n_vars + 50)
    else:
        x, _, status = solve_lcp_psd(P, qp.c)
    if status == NO_SOLUTION:
        raise NoSolutionError("the impulse-form LCP has no solution: a ray x ≥ 0 with Px = 0 "
                              "and cᵀx < 0 makes its QP unbounded below")
    if status != SOLVED:
        raise SolverError("nnls: the active-set search hit its step bound")
    y = P @ x + qp.c
    return QPSolution(x=x, y=np.maximum(y, 0.0), status="solved", backend="nnls")
