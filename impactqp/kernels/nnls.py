"""Non-negative least squares, min ‖Ax − b‖₂ over x ≥ 0 (docs/theory.md §9): the compiled
active-set search of :mod:`impactqp.kernels.active_set` on G = AᵀA, q = −Aᵀb, with the final
support's least-squares problem solved on A itself, so the answer does not carry the squared
condition number of the Gram form (the ``"nnls"`` backend); and :func:`solve_nnls`, SciPy's,
for membership and polishing."""

from __future__ import annotations

import numpy as np
from scipy import linalg, optimize

from ..errors import SolverError
from .active_set import SOLVED, lcp_psd
from .jit import kernel


@kernel(interpretable=True)
def nnls_search(A, b, max_iter):
    """The active-set search of :func:`nnls` on G = AᵀA, q = −Aᵀb: ``(x, support, status)``
    with the status codes of :func:`lcp_psd`."""
    m = A.shape[1]
    G = A.T @ A
    q = -(A.T @ b)
    x = np.zeros(m)
    w = np.zeros(m)
    passive = np.zeros(m, dtype=np.bool_)
    status = lcp_psd(G, q, passive, x, w, max_iter)
    return x, passive, status


def nnls(A: np.ndarray, b: np.ndarray, max_iter: int) -> tuple[np.ndarray, float, int]:
    """min ‖Ax − b‖₂ over x ≥ 0: the compiled active-set search on G = AᵀA, q = −Aᵀb
    (:func:`nnls_search`), then the least-squares problem on the final support solved on A
    itself by SciPy (no squared condition; kept when every entry stays positive).

    Returns ``(x, ‖Ax − b‖₂, status)`` with the status codes of :func:`lcp_psd`.
    """
    x, support, status = nnls_search(A, b, max_iter)
    k = int(support.sum())
    if status == SOLVED and 0 < k <= A.shape[0]:
        xs = linalg.lstsq(A[:, support], b)[0]
        if (xs > 0.0).all():
            x[support] = xs
    r = A @ x - b
    return x, float(np.sqrt(r @ r)), status


def solve_nnls(A: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, float]:
    """``(x, ‖Ax − b‖₂)`` for min ‖Ax − b‖₂ over x ≥ 0, by SciPy's Lawson–Hanson active-set
    NNLS (:func:`scipy.optimize.nnls`: as fast as :func:`nnls` on the small problems of
    membership and polishing, and nothing to compile on a first call). The compiled
    :func:`nnls` is the ``"nnls"`` backend's, which works on the impulse form's Gram matrix.

    Raises
    ------
    SolverError
        When the search does not finish within its iterations (20m + 50 steps).
    """
    A = np.ascontiguousarray(A, dtype=np.float64)
    b = np.ascontiguousarray(b, dtype=np.float64)
    try:
        x, rnorm = optimize.nnls(A, b, maxiter=20 * A.shape[1] + 50)
    except RuntimeError as exc:
        raise SolverError(f"NNLS did not finish: the active-set search on {A.shape[1]} "
                          f"variables hit its step bound ({exc})") from None
    return x, float(rnorm)
