"""One dense impact of a complementarity law, solved and certified in compiled code
(docs/theory.md §8, §9).

For ``0 ≤ Λ ⟂ γ⁺ + Eγ⁻ ≥ 0`` with ``u⁺ = u⁻ + M⁻¹WΛ`` (Moreau: E = εI; local Newton:
diagonal; Frémond: full), :func:`solve_impact`

1. forms γ⁻ = Wᵀu⁻ and q = (I + E)γ⁻,
2. solves the impulse-form LCP ``0 ≤ Λ ⟂ GΛ + q ≥ 0`` by the active-set search of
   :mod:`impactqp.kernels.active_set` (warm-started from the support of the previous solve),
3. recovers u⁺ and recomputes every residual of the certificate by
   :func:`impactqp.kernels.residuals.dense_residuals`, with the impact equation measured by
   an M⁻¹W of the certificate's own (LU of M, not the Cholesky factor the recovery uses:
   docs/theory.md §8, "Independence"),

and says whether every residual is within the tolerance; the caller returns the answer only
then. The structure's operators travel as one packed array (:func:`pack`): one argument
instead of five keeps the call's own cost small.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.linalg import lapack

from .active_set import SOLVED, lcp_psd_work
from .jit import kernel
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
        M⁻¹W solved by LU with partial pivoting: the certificate's impact equation.
    """

    M: np.ndarray
    Wt: np.ndarray
    MinvW: np.ndarray
    G: np.ndarray
    s: np.ndarray
    check: np.ndarray


def pack(M: np.ndarray, W: np.ndarray) -> np.ndarray:
    """:func:`pack_operators` of M and W, the operators computed here by LAPACK: M = LLᵀ and
    B = L⁻¹W give G = BᵀB and M⁻¹W = L⁻ᵀB (docs/theory.md §1), and the certificate's M⁻¹W is
    solved apart by LU with partial pivoting (``gesv``). M must be symmetric positive
    definite. (A structure packs the operators it has already computed.)"""
    M = np.ascontiguousarray(M, dtype=float)
    W = np.ascontiguousarray(W, dtype=float)
    L, _ = lapack.dpotrf(M, lower=1, clean=1)
    B = lapack.dtrtrs(L, W, lower=1)[0]
    return pack_operators(M, W, lapack.dtrtrs(L, B, lower=1, trans=1)[0], B.T @ B,
                          np.linalg.solve(M, W))


def pack_operators(M: np.ndarray, W: np.ndarray, MinvW: np.ndarray, G: np.ndarray,
                   check: np.ndarray) -> np.ndarray:
    """M (n × n), Wᵀ (m × n), M⁻¹W (n × m), G = WᵀM⁻¹W (m × m), sᵢ = √Gᵢᵢ and the
    certificate's M⁻¹W (n × m) in one flat array (views: :class:`Operators`). ``MinvW`` is
    the recovery's (from the Cholesky factor of M), ``check`` one that shares nothing with
    it (docs/theory.md §8, "Independence"). Plain Python: nothing to compile for a call made
    once per structure."""
    return np.concatenate((np.ravel(M), np.ravel(np.transpose(W)), np.ravel(MinvW),
                           np.ravel(G), np.sqrt(np.diag(G)), np.ravel(check))).astype(float)


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


@kernel(internal=True)
def workspace(n, m):
    """Scratch for :func:`_solve_into` (floats, the factor L, indices, flags): allocated once
    per call of the kernels below, however many impacts they solve."""
    return (np.empty(2 * n + 5 * m), np.empty((m, m)), np.empty(m, dtype=np.int64),
            np.empty(m, dtype=np.bool_))


@kernel(internal=True)
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


@kernel(interpretable=True)
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
