"""One dense impact of a complementarity law, solved and certified in compiled code
(docs/theory.md §8, §9).

For ``0 ≤ Λ ⟂ γ⁺ + Eγ⁻ ≥ 0`` with ``u⁺ = u⁻ + M⁻¹WΛ`` (Moreau: E = εI; local Newton:
diagonal; Frémond: full), :func:`solve_impact`

1. forms γ⁻ = Wᵀu⁻ and q = (I + E)γ⁻,
2. solves the impulse-form LCP ``0 ≤ Λ ⟂ GΛ + q ≥ 0`` by the active-set search of
   :mod:`impactqp.kernels.active_set` (warm-started from the support of the previous solve),
3. recovers u⁺ and recomputes every residual of the certificate by
   :func:`impactqp.kernels.residuals.dense_residuals`,

and says whether every residual is within the tolerance; the caller returns the answer only
then. The structure's operators travel as one packed array (:func:`pack`): one argument
instead of five keeps the call's own cost small.
"""

from __future__ import annotations

import numpy as np

from .active_set import SOLVED, lcp_psd_work
from .jit import kernel
from .residuals import dense_residuals


@kernel
def pack(M, W):
    """M (n × n), Wᵀ (m × n), M⁻¹W (n × m), G = WᵀM⁻¹W (m × m) and sᵢ = √Gᵢᵢ in one flat
    array, from M = LLᵀ and B = L⁻¹W: G = BᵀB, M⁻¹W = L⁻ᵀB (docs/theory.md §1). Plain loops:
    no inverse, no eigen-decomposition, no BLAS call for the small M of one impact.
    M must be symmetric positive definite (the structure has checked it)."""
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
    out = np.empty(n * n + 2 * m * n + m * m + m)
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
    return out


@kernel
def _unpack(packed, n, m):
    """The views (M, Wᵀ, M⁻¹W, G, s) of a :func:`pack`-ed array."""
    a = n * n
    b = a + m * n
    c = b + n * m
    d = c + m * m
    return (packed[:a].reshape((n, n)), packed[a:b].reshape((m, n)),
            packed[b:c].reshape((n, m)), packed[c:d].reshape((m, m)), packed[d:d + m])


@kernel
def workspace(n, m):
    """Scratch for :func:`_solve_into` (floats, the factor L, indices, flags): allocated once
    per call of the kernels below, however many impacts they solve."""
    return (np.empty(2 * n + 5 * m), np.empty((m, m)), np.empty(m, dtype=np.int64),
            np.empty(m, dtype=np.bool_))


@kernel
def _solve_into(M, Wt, MinvW, G, s, um, E, eps, moreau, tol, passive, up, lam, res, work):
    """Solve and certify one impact into (u⁺, Λ, residuals); True when certified."""
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
    dense_residuals(M, Wt, MinvW, s, um, up, lam, E, eps, moreau, res, floats[3 * m:])
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
    M, Wt, MinvW, G, s = _unpack(packed, n, m)
    return _solve_into(M, Wt, MinvW, G, s, um, E, eps, moreau, tol, passive, out[:n],
                       out[n:n + m], out[n + m:n + m + 6], workspace(n, m))


@kernel
def solve_impact_rows(packed, Um, E, eps, moreau, tol, passive):
    """:func:`solve_impact` for every row of U⁻ (each row warm-starts the next).

    Returns (U⁺, Λ, residuals (k × 6), certified mask).
    """
    k, n = Um.shape
    m = passive.size
    M, Wt, MinvW, G, s = _unpack(packed, n, m)
    Up = np.empty((k, n))
    Lam = np.empty((k, m))
    Res = np.empty((k, 6))
    ok = np.empty(k, dtype=np.bool_)
    work = workspace(n, m)
    for r in range(k):
        ok[r] = _solve_into(M, Wt, MinvW, G, s, Um[r], E, eps, moreau, tol, passive, Up[r],
                            Lam[r], Res[r], work)
    return Up, Lam, Res, ok
