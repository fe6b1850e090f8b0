"""Whether a symmetric sparse matrix is positive definite, by the factor that also solves with it.

SuperLU with diagonal pivots on a symmetric ordering (minimum degree on M + Mᵀ) computes
an LDLᵀ in LU form: U's diagonal is D, and M is positive definite exactly when every pivot
is positive and no row was exchanged off the diagonal. One definition for the mass matrix
of a problem, of a global FCLib file, and for the Delassus matrix of an LCP.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def symmetric_ldl(M: sp.spmatrix) -> tuple[spla.SuperLU, bool]:
    """The LU of the symmetric sparse ``M`` with diagonal pivots in a symmetric order.

    Parameters
    ----------
    M : scipy.sparse matrix
        Square and symmetric (only then are the pivots those of an LDLᵀ).

    Returns
    -------
    (scipy.sparse.linalg.SuperLU, bool)
        The factor, and whether M is positive definite (every pivot > 0, rows in the
        columns' order).

    Raises
    ------
    RuntimeError
        SuperLU's, when M is exactly singular.
    """
    lu = spla.splu(sp.csc_matrix(M), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                   options={"SymmetricMode": True})
    definite = bool(np.array_equal(lu.perm_r, lu.perm_c) and np.all(lu.U.diagonal() > 0))
    return lu, definite
