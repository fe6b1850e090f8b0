"""Solves with the Cholesky factor of a small dense M in the calling thread (docs/theory.md §1).

OpenBLAS runs LAPACK's ``trtrs`` on its thread pool at every size, and BLAS's ``trsm`` from
1024 entries of the right-hand side on. On a loaded machine the caller then waits
milliseconds for a worker to be scheduled (a 20 × 10 problem built in 14 ms instead of
50 µs), and the worker, spinning a while after its job, slows the caller's next calls.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import blas

SMALL = 64
"""Degrees of freedom and columns of W up to which a dense structure is built and solved in
the calling thread (:func:`cholesky_solve`): below it OpenBLAS keeps every other call of the
build and of a first solve there (Cholesky below n = 64, LU below 100, products below
2.6·10⁵ multiply-adds), and its threads would save microseconds while a loaded machine
keeps the caller waiting milliseconds for a worker to be scheduled."""

_BLOCK = 1023
"""Entries of a right-hand side that OpenBLAS's ``trsm`` solves in the calling thread (it
threads from 1024 on)."""


def cholesky_solve(L: np.ndarray, X: np.ndarray, transpose: bool = False) -> np.ndarray:
    """L⁻¹X, or L⁻ᵀX with ``transpose``, for the lower Cholesky factor L of M = LLᵀ
    (docs/theory.md §1), by BLAS's ``trsm``; for a problem within :data:`SMALL`, in blocks
    of columns of at most 1023 entries, each solved in the calling thread. The columns are
    independent, so the blocks give the bits of one call.

    BLAS's ``trsm`` rather than LAPACK's ``trtrs``, the same arithmetic to the bit: OpenBLAS
    runs its ``trtrs`` on its thread pool at every size. A successful Cholesky factor has
    no zero pivot, the one failure ``trtrs`` would report."""
    n, m = X.shape
    width = max(1, _BLOCK // n)
    if m <= width or n > SMALL or m > SMALL:
        return blas.dtrsm(1.0, L, X, lower=1, trans_a=int(transpose))
    out = np.array(X, dtype=float, order="F")  # each block solved in place
    for j in range(0, m, width):
        blas.dtrsm(1.0, L, out[:, j:j + width], lower=1, trans_a=int(transpose),
                   overwrite_b=1)
    return out
