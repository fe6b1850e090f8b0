"""A global FCLib problem (M v = H r + f, u = Hᵀ v + w) reduced to the local one: the
Delassus matrix W = Hᵀ M⁻¹ H and the free velocity q = Hᵀ M⁻¹ f + w (docs/theory.md §1).

M is first checked to be a mass matrix (its symmetric part positive definite) and factorized
once (:func:`mass_factor`). Where M is block-diagonal with blocks of at most
:data:`BLOCK_LIMIT` (rigid bodies: one block per body, often 1×1), M⁻¹ has the same blocks and
is formed sparse from :data:`BLOCK_LIMIT` solves at most (each column of a probe E picks one
unknown of every block), so W costs what its sparse products cost. Otherwise (a deformable
body couples everything) M⁻¹H is solved in dense blocks of columns, n·(columns of H + 1)
entries, which is refused above :data:`REDUCTION_WORK` before it starts: a file of a few
hundred kilobytes can declare a reduction of hours; so is a W of more than
:data:`REDUCED_ENTRIES` entries, bounded before it is formed. Either way M⁻¹ is checked by
the componentwise (Oettli–Prager) backward error of M Y = B.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.csgraph as csgraph
import scipy.sparse.linalg as spla

from ..base.definite import symmetric_ldl
from ..errors import ProblemFileError

REDUCTION_BLOCK = 256
"""Most columns of H solved at a time in the dense reduction (the work array is at most
n × 256 floats)."""

REDUCTION_RTOL = 1e-8
"""Largest componentwise backward error |M Y − B| ≤ rtol·(|M||Y| + |B|) accepted for
Y = M⁻¹B; above it M is taken as singular (the reduced W would not be Hᵀ M⁻¹ H)."""

BLOCK_LIMIT = 64
"""Largest diagonal block of M (connected unknowns) for which M⁻¹ is formed sparse."""

REDUCTION_WORK = 2e9
"""Most entries n·(columns + 1) of M⁻¹[H f] the dense reduction computes (about 100 ns
each on a loaded 2-core machine: a few minutes)."""

REDUCED_ENTRIES = 1e8
"""Most entries of W = Hᵀ M⁻¹ H (bounded before it is formed: 1.2 GB stored sparse); a few
hundred kilobytes of H whose columns all meet one unknown declare a dense W of (3m)²."""

Error = Callable[[str], ProblemFileError]
"""Makes the reader's error about M from what is wrong."""


def mass_factor(M: sp.csc_matrix, error: Error):
    """The sparse LU of M, once M is known to be a mass matrix: its symmetric part positive
    definite (½vᵀMv > 0 for v ≠ 0), decided by an LU with diagonal pivots in a symmetric
    order (an LDLᵀ: every pivot positive exactly when it is; it is M's own LU when M is
    symmetric, as it nearly always is)."""
    symmetric = (M != M.T).nnz == 0
    try:
        lu, definite = symmetric_ldl(M if symmetric else (M + M.T) * 0.5)
        own = lu if symmetric and definite else spla.splu(M)  # RuntimeError: M is singular
    except RuntimeError:
        raise error("is singular; the global problem cannot be reduced to W = Hᵀ M⁻¹ H") \
            from None
    if not definite:
        pivot = lu.U.diagonal().min()
        raise error(f"is not positive definite (a pivot of its LDLᵀ is {pivot:.3g}): "
                    "a mass matrix gives every velocity a positive kinetic energy ½vᵀMv")
    return own


def _sparse_inverse(M: sp.csc_matrix, lu) -> sp.csc_matrix | None:
    """M⁻¹ of a block-diagonal M with blocks of at most :data:`BLOCK_LIMIT` unknowns, from
    one solve per probe column (None for larger blocks)."""
    n = M.shape[0]
    _, labels = csgraph.connected_components(abs(M) + abs(M.T), directed=False)
    sizes = np.bincount(labels)
    width = int(sizes.max())
    if width > BLOCK_LIMIT:
        return None
    order = np.argsort(labels, kind="stable")
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    rank = np.empty(n, dtype=np.int64)
    rank[order] = np.arange(n) - np.repeat(starts, sizes)  # place of each unknown in its block
    probe = np.zeros((n, width))
    probe[np.arange(n), rank] = 1.0
    Z = lu.solve(probe)  # Z[i, r] = (M⁻¹)[i, the r-th unknown of i's block]
    per_row = sizes[labels]
    rows = np.repeat(np.arange(n), per_row)
    places = np.arange(rows.size) - np.repeat(np.cumsum(per_row) - per_row, per_row)
    cols = order[starts[labels[rows]] + places]
    return sp.csc_matrix((Z[rows, places], (rows, cols)), shape=(n, n))


UNDERFLOW = 1e-250
"""Entries of M Y − B below this fraction of their column's largest |M||Y| + |B| are not
judged: a decaying M⁻¹ (a chain of springs: 0.27ᵏ) reaches the subnormals, where a product
keeps a few bits and the componentwise test would call a well-conditioned M singular."""


def _solves(M: sp.csc_matrix, B: sp.spmatrix | np.ndarray, Y) -> bool:
    """Whether Y solves M Y = B to :data:`REDUCTION_RTOL` componentwise (above
    :data:`UNDERFLOW` of each column's scale), and is finite."""
    with np.errstate(over="ignore", invalid="ignore", under="ignore"):
        scale = abs(M) @ abs(Y) + abs(B)
        floor = UNDERFLOW * np.asarray(scale.max(axis=0).toarray() if sp.issparse(scale)
                                       else scale.max(axis=0)).ravel()
        excess = abs(M @ Y - B) - REDUCTION_RTOL * scale
        finite = np.all(np.isfinite(Y.data if sp.issparse(Y) else Y))
    if sp.issparse(excess):
        excess = sp.coo_matrix(excess)
        return bool(finite and np.all(excess.data <= floor[excess.col]))
    return bool(finite and np.all(excess <= floor))


def reduce_global(M: sp.csc_matrix, H: sp.csc_matrix, f: np.ndarray,
                  error: Error) -> tuple[sp.csc_matrix, np.ndarray]:
    """(Hᵀ M⁻¹ H, Hᵀ M⁻¹ f) of a global problem (see the module doc).

    Raises
    ------
    ProblemFileError
        (made by ``error``) M singular, not positive definite or too ill-conditioned, a
        dense reduction over :data:`REDUCTION_WORK`, or a W beyond the floats.
    """
    lu = mass_factor(M, error)
    rhs = sp.hstack([H, sp.csc_matrix(f.reshape(-1, 1))], format="csc")
    inverse = _sparse_inverse(M, lu)
    ill = "is singular or too ill-conditioned to reduce the global problem (M⁻¹H does not " \
          "solve M Y = H)"
    if inverse is not None:
        Y = sp.csc_matrix(inverse @ rhs)
        # W's entries are at most Σₖ (entries of row k of Y)·(entries of row k of H)
        bound = float(np.dot(np.diff(sp.csr_matrix(Y).indptr), np.diff(sp.csr_matrix(H).indptr)))
    else:
        bound = float(rhs.shape[1]) ** 2
    if bound > REDUCED_ENTRIES:
        raise error(f"reduces to a W = Hᵀ M⁻¹ H of up to {bound:.3g} entries (the columns of H "
                    f"share unknowns), over the limit {REDUCED_ENTRIES:.3g}")
    if inverse is not None:
        if not _solves(M, rhs, Y):
            raise error(ill)
        reduced = sp.csc_matrix(H.T @ Y)
    else:
        n, columns = rhs.shape
        if n * columns > REDUCTION_WORK:
            raise error(f"couples its {n} unknowns, so reducing the global problem takes "
                        f"dense solves of n·(columns + 1) = {n * columns:.3g} entries, over the "
                        f"work limit {REDUCTION_WORK:.3g}; reduce it to W = Hᵀ M⁻¹ H with a "
                        "sparse solver of your own and save the local problem "
                        "(iq.save_fclib)")
        blocks = []
        for start in range(0, columns, REDUCTION_BLOCK):
            B = rhs[:, start:start + REDUCTION_BLOCK].toarray()
            with np.errstate(over="ignore", invalid="ignore"):
                Y = lu.solve(B)
            if not _solves(M, B, Y):
                raise error(ill)
            blocks.append(sp.csc_matrix(H.T @ Y))
        reduced = sp.hstack(blocks, format="csc")
    if not np.all(np.isfinite(reduced.data)):
        raise error("Hᵀ M⁻¹ H or Hᵀ M⁻¹ f overflows the floats; rescale the problem")
    return sp.csc_matrix(reduced[:, :-1]), reduced[:, -1].toarray().ravel()
