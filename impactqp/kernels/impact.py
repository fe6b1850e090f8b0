"""One dense impact of a complementarity law, solved and certified in compiled code
(docs/theory.md §8, §9).

For ``0 ≤ Λ ⟂ γ⁺ + Eγ⁻ ≥ 0`` with ``u⁺ = u⁻ + M⁻¹WΛ`` (Moreau: E = εI; local Newton:
diagonal; Frémond: full), :func:`solve_impact`

1. forms γ⁻ = Wᵀu⁻ and q = (I + E)γ⁻,
2. solves the impulse-form LCP ``0 ≤ Λ ⟂ GΛ + q ≥ 0`` by the active-set search of
   :mod:`impactqp.kernels.active_set` (warm-started from the support of the previous solve),
3. recovers u⁺ and recomputes every residual of the certificate by
   :func:`impactqp.kernels.residuals.dense_residuals`, with the impact equation measured by
   an M⁻¹W of the certificate's own (Gaussian elimination of M, not the Cholesky factor
   the recovery uses: docs/theory.md §8, "Independence"),

and says whether every residual is within the tolerance; the caller returns the answer only
then. The structure's operators travel as one packed array (:func:`pack`): one argument
instead of five keeps the call's own cost small.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .active_set import SOLVED, lcp_psd_work
from .jit import inline_kernel, kernel
from .residuals import dense_residuals


class Operators(NamedTuple):
    """The views of a :func:`pack`-ed structure.

    Attributes
    ----------
    M : (n, n) float array
    Wt : (m, n) float array
        Wᵀ.
    MinvW : (n, m) float array
        M⁻¹W from the Cholesky factor of M: the recovery u⁺ = u⁻ + M⁻¹WΛ.
    G : (m, m) float array
        The Delassus matrix WᵀM⁻¹W.
    s : (m,) float array
        The contact scales sᵢ = √Gᵢᵢ.
    check : (n, m) float array
        M⁻¹W solved by Gaussian elimination: the certificate's impact equation.
    """

    M: np.ndarray
    Wt: np.ndarray
    MinvW: np.ndarray
    G: np.ndarray
    s: np.ndarray
    check: np.ndarray


@inline_kernel
def lu_solve_columns(M, W, X):
    """X = M⁻¹W by Gaussian elimination on a copy of M (M = LU, L unit lower triangular):
    an M⁻¹W that shares nothing with the Cholesky-based one of :func:`pack`
    (docs/theory.md §8). M is symmetric positive definite, so every pivot is positive
    without row exchanges."""
    n, m = W.shape
    A = M.copy()
    X[:, :] = W
    for k in range(n):
        for i in range(k + 1, n):
            f = A[i, k] / A[k, k]
            for j in range(k + 1, n):
                A[i, j] -= f * A[k, j]
            for c in range(m):
                X[i, c] -= f * X[k, c]
    for c in range(m):
        for i in range(n - 1, -1, -1):
            v = X[i, c]
            for j in range(i + 1, n):
                v -= A[i, j] * X[j, c]
            X[i, c] = v / A[i, i]


@kernel
def pack(M, W):
    """M (n × n), Wᵀ (m × n), M⁻¹W (n × m), G = WᵀM⁻¹W (m × m), sᵢ = √Gᵢᵢ and the
    certificate's M⁻¹W (n × m, :func:`lu_solve_columns`) in one flat array (views:
    :class:`Operators`), from M = LLᵀ and B = L⁻¹W: G = BᵀB, M⁻¹W = L⁻ᵀB (docs/theory.md §1).
    Plain loops: no inverse, no eigen-decomposition, no BLAS call for the small M of one
    impact. M must be symmetric positive definite (the structure has checked it)."""
    n, m = W.shape
    L = np.zeros((n, n))
    for j in range(n):
        d = M[j, j]
        for k in range(j):
            d -= L[j, k] * L[j, k]
        L[j, j] = np.sqrt(d)
        for i in range(j + 1, n):
            v = M[i, j]
            for k in range(j):
                v -= L[i, k] * L[j, k]
            L[i, j] = v / L[j, j]
    B = np.empty((n, m))
    X = np.empty((n, m))
    for c in range(m):
        for i in range(n):  # B = L⁻¹W
            v = W[i, c]
            for k in range(i):
                v -= L[i, k] * B[k, c]
            B[i, c] = v / L[i, i]
        for i in range(n - 1, -1, -1):  # M⁻¹W = L⁻ᵀB
            v = B[i, c]
            for k in range(i + 1, n):
                v -= L[k, i] * X[k, c]
            X[i, c] = v / L[i, i]
    out = np.empty(n * n + 3 * m * n + m * m + m)
    out[:n * n] = M.ravel()
    a = n * n
    for c in range(m):
        for i in range(n):
            out[a + c * n + i] = W[i, c]  # Wᵀ, row by row
            out[a + m * n + i * m + c] = X[i, c]
    d = a + 2 * m * n
    for r in range(m):
        for c in range(m):
            v = 0.0
            for i in range(n):
                v += B[i, r] * B[i, c]
            out[d + r * m + c] = v
        out[d + m * m + r] = np.sqrt(out[d + r * m + r])
    lu_solve_columns(M, W, out[d + m * m + m:].reshape((n, m)))
    return out


@kernel
def _unpack(packed, n, m):
    """The views (:class:`Operators`) of a :func:`pack`-ed array."""
    a = n * n
    b = a + m * n
    c = b + n * m
    d = c + m * m
    e = d + m
    return Operators(packed[:a].reshape((n, n)), packed[a:b].reshape((m, n)),
                     packed[b:c].reshape((n, m)), packed[c:d].reshape((m, m)), packed[d:e],
                     packed[e:e + n * m].reshape((n, m)))


@kernel
def workspace(n, m):
    """Scratch for :func:`_solve_into` (floats, the factor L, indices, flags): allocated once
    per call of the kernels below, however many impacts they solve."""
    return (np.empty(2 * n + 5 * m), np.empty((m, m)), np.empty(m, dtype=np.int64),
            np.empty(m, dtype=np.bool_))


@kernel
def _solve_into(ops, um, E, eps, moreau, tol, passive, up, lam, res, work):
    """Solve and certify one impact of the structure ``ops`` (:class:`Operators`) into
    (u⁺, Λ, residuals); True when certified."""
    M, Wt, MinvW, G, s, check = ops
    n, m = um.size, passive.size
    floats, L, idx, blocked = work
    q = floats[:m]
    w = floats[m:2 * m]
    sv = floats[2 * m:3 * m]
    for i in range(m):  # γ⁻, then q = (I + E)γ⁻
        total = 0.0
        for j in range(n):
            total += Wt[i, j] * um[j]
        sv[i] = total
    for i in range(m):
        total = sv[i]
        if moreau:
            total += eps * sv[i]
        else:
            for j in range(m):
                total += E[i, j] * sv[j]
        q[i] = total
    if lcp_psd_work(G, q, passive, lam, w, 20 * m + 50, L, idx, sv, blocked) != SOLVED:
        return False
    for i in range(n):
        total = um[i]
        for j in range(m):
            total += MinvW[i, j] * lam[j]
        up[i] = total
    dense_residuals(M, Wt, check, s, um, up, lam, E, eps, moreau, res, floats[3 * m:])
    count = 6 if moreau else 4
    for i in range(count):
        if not res[i] <= tol:  # NaN fails
            return False
    return True


@kernel
def solve_impact(packed, um, E, eps, moreau, tol, passive, out):
    """Solve and certify one impact of the structure ``packed``.

    Parameters
    ----------
    packed : float array
        The structure's operators (:func:`pack`).
    um : (n,) float array
        u⁻.
    E : (m, m) float array
        The law's restitution matrix (ignored for Moreau's law, whose E is εI).
    eps : float
        Moreau's ε (used with ``moreau``).
    moreau : bool
        Moreau's law: E = εI, and the energy balance and the duality gap are added.
    tol : float
        Tolerance of every residual.
    passive : (m,) bool array
        Warm start of the LCP search, updated in place.
    out : (n + m + 6,) float array
        Receives u⁺, Λ and the residuals (order of
        :data:`impactqp.kernels.residuals.RESIDUALS`); one buffer, so that the call returns
        no arrays (boxing each would cost more than the solve).

    Returns
    -------
    bool
        Whether the answer is certified.
    """
    n, m = um.size, passive.size
    return _solve_into(_unpack(packed, n, m), um, E, eps, moreau, tol, passive, out[:n],
                       out[n:n + m], out[n + m:n + m + 6], workspace(n, m))


@kernel
def solve_impact_rows(packed, Um, E, eps, moreau, tol, passive):
    """:func:`solve_impact` for every row of U⁻ (each row warm-starts the next).

    Returns (U⁺, Λ, residuals (k × 6), certified mask).
    """
    k, n = Um.shape
    m = passive.size
    ops = _unpack(packed, n, m)
    Up = np.empty((k, n))
    Lam = np.empty((k, m))
    Res = np.empty((k, 6))
    ok = np.empty(k, dtype=np.bool_)
    work = workspace(n, m)
    for r in range(k):
        ok[r] = _solve_into(ops, Um[r], E, eps, moreau, tol, passive, Up[r], Lam[r], Res[r],
                            work)
    return Up, Lam, Res, ok
