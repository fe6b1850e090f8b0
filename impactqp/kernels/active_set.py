"""The small dense LCP search: a primal active-set method with Cholesky updates
(docs/theory.md §9, "The compiled active-set search").

It solves ``0 ≤ x ⟂ Gx + q ≥ 0`` for a symmetric positive semidefinite G, which is the KKT
system of the convex QP min ½xᵀGx + qᵀx over x ≥ 0. The method is Lawson and Hanson's
active-set scheme on this Gram form:

* a passive set P holds the variables allowed to be positive; the block G_PP is kept
  factorized (G_PP = LLᵀ), a variable joining P appends one row to L, one leaving it
  refactors;
* the variable with the steepest descent −(Gx + q)ⱼ joins P; the minimizer s of the
  quadratic on P is computed and x moves towards it until a variable of P reaches zero,
  which leaves P;
* a joining variable whose column is dependent on those of P (a zero Schur complement:
  redundant contacts) is reached along the ray d with dⱼ = 1, d_P = −G_PP⁻¹G_Pj, on which
  G d = 0 and the objective falls linearly; the ray ends where a variable of P reaches zero
  and trades places with j. A ray that never ends proves that the QP is unbounded below, i.e.
  that the LCP has no solution (for PSD G an LCP is solvable iff feasible).

It needs no inverse and no eigen-decomposition; a warm start enters the passive set of an
earlier solve. NNLS, min ‖Ax − b‖ over x ≥ 0, is the case G = AᵀA, q = −Aᵀb
(:mod:`impactqp.kernels.nnls`).
"""

from __future__ import annotations

import numpy as np

from .jit import inline_kernel, kernel

SOLVED, NO_SOLUTION, ITERATION_LIMIT = 0, 1, 2
"""Status codes of :func:`lcp_psd`."""

PIVOT_TOL = 1e-12
"""A joining column whose Schur complement is at most PIVOT_TOL·Gⱼⱼ counts as dependent."""

DESCENT_TOL = 1e-13
"""A variable joins only when −(Gx + q)ⱼ exceeds DESCENT_TOL·(max|q| + max|G|·max|x|)."""


@kernel(internal=True)
def _append(L, idx, k, G, j):
    """Append variable j to the factor of G_PP (P = idx[:k]); False if its column is dependent.
    The new row is formed in row k of L, which is not part of the factor until it succeeds."""
    total = 0.0
    for a in range(k):
        s = G[idx[a], j]
        for b in range(a):
            s -= L[a, b] * L[k, b]
        L[k, a] = s / L[a, a]
        total += L[k, a] * L[k, a]
    d = G[j, j] - total
    if not d > PIVOT_TOL * G[j, j]:
        return False
    L[k, k] = np.sqrt(d)
    idx[k] = j
    return True


@kernel(internal=True)
def _refactor(L, idx, k, G, x):
    """Factor G_PP anew for P = idx[:k]; variables whose columns turn out dependent leave P
    (with x = 0). Returns the new size of P."""
    kept = np.int64(0)
    for a in range(k):
        j = idx[a]
        if _append(L, idx, kept, G, j):
            kept += 1
        else:
            x[j] = 0.0
    return kept


@kernel(internal=True)
def _solve_factored(L, idx, k, rhs, out):
    """out[idx[:k]] = G_PP⁻¹ rhs[idx[:k]] with G_PP = LLᵀ."""
    solve_factored_into(L, idx, k, rhs, out, np.empty(k))


@kernel(internal=True)
def solve_factored_into(L, idx, k, rhs, out, y):
    """:func:`_solve_factored` in the scratch y of at least k floats (no allocation: the
    derivative kernels call it several times per row)."""
    for a in range(k):
        y[a] = rhs[idx[a]]
    cholesky_solve(L, k, y)
    for a in range(k):
        out[idx[a]] = y[a]


@inline_kernel
def cholesky_solve(L, k, y):
    """y ← (LLᵀ)⁻¹y for the leading k × k block of the lower factor L: forward, then backward
    substitution (as LAPACK's potrs)."""
    for a in range(k):
        s = y[a]
        for b in range(a):
            s -= L[a, b] * y[b]
        y[a] = s / L[a, a]
    for a in range(k - 1, -1, -1):
        s = y[a]
        for b in range(a + 1, k):
            s -= L[b, a] * y[b]
        y[a] = s / L[a, a]


@kernel(internal=True)
def _gradient(G, q, x, w):
    """w = Gx + q."""
    m = q.size
    for i in range(m):
        s = q[i]
        for j in range(m):
            if x[j] != 0.0:
                s += G[i, j] * x[j]
        w[i] = s


@kernel(internal=True)
def _member(idx, k, i):
    """Whether variable i is in P = idx[:k]."""
    for a in range(k):
        if idx[a] == i:
            return True
    return False


@inline_kernel
def _to_minimizer(L, idx, k, G, q, x, s, joined):
    """Move x towards the minimizer of the quadratic on P = idx[:k] until it is reached with
    x_P > 0, dropping the variables that reach zero on the way (Lawson–Hanson's inner loop).

    Returns (new k, moved). When ``joined`` (the variable that has just entered, last in
    idx) has a non-positive minimizer at once, it leaves again and ``moved`` is False.
    """
    first = True
    while k > 0:
        for a in range(k):
            s[idx[a]] = -q[idx[a]]
        _solve_factored(L, idx, k, s, s)
        positive = True
        for a in range(k):
            positive &= s[idx[a]] > 0.0
        if positive:
            for a in range(k):
                x[idx[a]] = s[idx[a]]
            return k, True
        if first and joined >= 0 and not s[joined] > 0.0:
            x[joined] = 0.0
            return k - 1, False
        first = False
        alpha = 2.0  # some s_i ≤ 0, so the step found is at most 1
        stop = -1
        for a in range(k):
            i = idx[a]
            if not s[i] > 0.0:
                step = x[i] / (x[i] - s[i]) if x[i] > s[i] else 0.0
                if step < alpha:
                    alpha = step
                    stop = i
        kept = np.int64(0)
        for a in range(k):
            i = idx[a]
            x[i] += alpha * (s[i] - x[i])
            if i != stop and (s[i] > 0.0 or x[i] > 0.0):
                idx[kept] = i
                kept += 1
            else:
                x[i] = 0.0
        k = _refactor(L, idx, kept, G, x)
    return k, True


@inline_kernel
def _final_solve(L, idx, k, G, q, x, w, s):
    """The solution on the final support as a function of the support alone (indices in
    order, a fresh factor, one step of iterative refinement), so that the path that found it
    (cold or warm start) leaves no trace; kept only where it stays positive."""
    for a in range(1, k):  # insertion sort: k is small, and np.sort costs seconds to compile
        i = idx[a]
        b = a - 1
        while b >= 0 and idx[b] > i:
            idx[b + 1] = idx[b]
            b -= 1
        idx[b + 1] = i
    if _refactor(L, idx, k, G, s) < k:
        return
    for a in range(k):
        s[idx[a]] = -q[idx[a]]
    _solve_factored(L, idx, k, s, s)
    for _ in range(2):  # the solve, then one refinement step
        ok = True
        for a in range(k):
            ok &= s[idx[a]] > 0.0
        if not ok:
            return
        for i in range(x.size):
            x[i] = 0.0
        for a in range(k):
            x[idx[a]] = s[idx[a]]
        _gradient(G, q, x, w)
        for a in range(k):
            s[idx[a]] = -w[idx[a]]
        _solve_factored(L, idx, k, s, s)
        for a in range(k):
            s[idx[a]] += x[idx[a]]


@kernel(interpretable=True)
def lcp_psd(G, q, passive, x, w, max_iter):
    """Solve ``0 ≤ x ⟂ Gx + q ≥ 0`` for a symmetric positive semidefinite G.

    Parameters
    ----------
    G : (m, m) float array
        Symmetric positive semidefinite (not checked).
    q : (m,) float array
    passive : (m,) bool array
        In: the variables to start with in the passive set (a warm start; all False for a
        cold one). Out: the final passive set (x > 0 only there).
    x, w : (m,) float arrays
        Out: the solution and w = Gx + q.
    max_iter : int
        Bound on the steps that change the passive set.

    Returns
    -------
    int
        :data:`SOLVED`, :data:`NO_SOLUTION` (a ray proves the QP unbounded below, so the
        LCP has no feasible point) or :data:`ITERATION_LIMIT`.
    """
    m = q.size
    return lcp_psd_work(G, q, passive, x, w, max_iter, np.empty((m, m)),
                        np.empty(m, dtype=np.int64), np.empty(m), np.empty(m, dtype=np.bool_))


@kernel(internal=True)
def lcp_psd_work(G, q, passive, x, w, max_iter, L, idx, s, blocked):
    """:func:`lcp_psd` with its workspace given: L (m × m), idx (m integers), s (m floats)
    and blocked (m booleans), so that a loop over many LCPs allocates nothing."""
    m = q.size
    blocked[:] = False
    x[:] = 0.0
    qmax = 0.0
    gmax = 0.0
    for i in range(m):
        qmax = max(qmax, abs(q[i]))
        for j in range(m):
            gmax = max(gmax, abs(G[i, j]))
    k = np.int64(0)  # not a literal: callees compile for int64 only (one signature)
    for j in range(m):
        if passive[j] and _append(L, idx, k, G, j):
            k += 1
    restore = k > 0  # a warm start first moves to the minimizer on its passive set
    status = ITERATION_LIMIT
    for _ in range(max_iter):
        joined = np.int64(-1)
        if not restore:
            _gradient(G, q, x, w)
            xmax = 0.0
            for i in range(m):
                xmax = max(xmax, x[i])
            best = DESCENT_TOL * (qmax + gmax * xmax)
            for i in range(m):
                if -w[i] > best and not blocked[i] and not _member(idx, k, i):
                    best = -w[i]
                    joined = i
            if joined < 0:
                status = SOLVED
                break
            if not _append(L, idx, k, G, joined):
                # dependent column: follow the ray d (d_j = 1, d_P = −G_PP⁻¹G_Pj), G d = 0
                for a in range(k):
                    s[idx[a]] = -G[idx[a], joined]
                _solve_factored(L, idx, k, s, s)
                t = np.inf
                leave = -1
                for a in range(k):
                    i = idx[a]
                    if s[i] < 0.0 and x[i] / -s[i] < t:
                        t = x[i] / -s[i]
                        leave = a
                if leave < 0:
                    status = NO_SOLUTION
                    break
                for a in range(k):
                    x[idx[a]] += t * s[idx[a]]
                x[idx[leave]] = 0.0
                x[joined] = t
                idx[leave] = joined
                k = _refactor(L, idx, k, G, x)
                blocked[:] = False
                restore = True
                continue
            k += 1
        restore = False
        k, moved = _to_minimizer(L, idx, k, G, q, x, s, joined)
        if moved:
            blocked[:] = False
        else:  # round-off: the joining variable would leave at once; keep it out
            blocked[joined] = True
    if status == SOLVED and k > 0:
        _final_solve(L, idx, k, G, q, x, w, s)
    _gradient(G, q, x, w)
    passive[:] = False
    for a in range(k):
        passive[idx[a]] = x[idx[a]] > 0.0
    return status


@kernel
def lcp_psd_rows(G, Q, passive, max_iter):
    """:func:`lcp_psd` for every row of Q as q, each row warm-started by the support of the
    row before. Returns (X, W, status) with X, W of Q's shape and one status per row."""
    k, m = Q.shape
    X = np.empty((k, m))
    W = np.empty((k, m))
    status = np.empty(k, dtype=np.int64)
    for r in range(k):
        status[r] = lcp_psd(G, Q[r], passive, X[r], W[r], max_iter)
    return X, W, status


def solve_lcp_psd(G: np.ndarray, q: np.ndarray, passive: np.ndarray | None = None,
                  ) -> tuple[np.ndarray, np.ndarray, int]:
    """``(x, w, status)`` of ``0 ≤ x ⟂ w = Gx + q ≥ 0`` by :func:`lcp_psd`, cold or warm.

    ``passive`` (a bool array of size m, updated in place) carries a warm start from one
    call to the next; the step bound is 20m + 50, far above the m to 3m steps usually taken.
    """
    G = np.ascontiguousarray(G, dtype=np.float64)
    q = np.ascontiguousarray(q, dtype=np.float64)
    m = q.size
    if passive is None:
        passive = np.zeros(m, dtype=np.bool_)
    x, w = np.zeros(m), np.zeros(m)
    status = lcp_psd(G, q, passive, x, w, 20 * m + 50)
    return x, w, int(status)
