"""Exact impulse-form solve by non-negative least squares (scipy.optimize.nnls).

With P = BᵀB and c = Bᵀd,  ½xᵀPx + cᵀx = ½‖Bx + d‖² − ½‖d‖², so the QP over x ≥ 0 is the
NNLS problem min ‖Bx − (−d)‖, solved exactly by an active-set method (docs/theory.md §3, impulse
form).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import nnls

from ...errors import BackendUnsuitableError, SolverError
from ..program import QPSolution, QuadraticProgram

MAX_VARIABLES = 400


def psd_factor(P: np.ndarray) -> np.ndarray:
    """B with P = BᵀB for a symmetric PSD P (via its eigendecomposition)."""
    w, V = np.linalg.eigh(P)
    w = np.clip(w, 0.0, None)
    return np.sqrt(w)[:, None] * V.T


def unsuitable(qp: QuadraticProgram) -> str | None:
    if not qp.nonnegative:
        return "'nnls' solves only the impulse form (x ≥ 0)"
    if qp.sparse or qp.n_vars > MAX_VARIABLES:
        return (f"'nnls' is dense and takes at most {MAX_VARIABLES} variables "
                f"({qp.n_vars}{', sparse' if qp.sparse else ''})")
    return None


def solve(qp: QuadraticProgram, *, tol: float = 1e-10, solver: str | None = None) -> QPSolution:
    """Solve the impulse form x ≥ 0 exactly; refuse other shapes and q ∉ range(P)."""
    reason = unsuitable(qp)
    if reason is not None:
        raise BackendUnsuitableError(reason)
    P = np.asarray(qp.P, dtype=float)
    B = qp.factor if qp.factor is not None else psd_factor(P)
    d = qp.factor_rhs
    if d is None:
        d, *_ = np.linalg.lstsq(B.T, qp.c, rcond=None)
    miss = np.abs(B.T @ d - qp.c).max(initial=0.0)
    scale = np.abs(qp.c).max(initial=0.0) + np.abs(B).max(initial=0.0) * np.abs(d).max(initial=0.0)
    if miss > 1e-10 * scale + 1e-300:
        raise BackendUnsuitableError("q is not in the range of the Delassus matrix (dependent "
                                     "contacts with an inconsistent q); use 'exact' or a QP solver")
    try:
        x, _ = nnls(B, -d, maxiter=50 * max(qp.n_vars, 1))
    except RuntimeError as exc:
        raise SolverError(f"nnls did not converge: {exc}") from exc
    y = P @ x + qp.c
    return QPSolution(x=x, y=np.maximum(y, 0.0), status="solved", backend="nnls")
