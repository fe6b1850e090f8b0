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

from .active_set import SOLVED, lcp_psd
from .jit import kernel
from .residuals import dense_residuals


def pack(M: np.ndarray, Wt: np.ndarray, Minv_W: np.ndarray, G: np.ndarray,
         s: np.ndarray) -> np.ndarray:
    """M (n × n), Wᵀ (m × n), M⁻¹W (n × m), G (m × m) and s (m) in one flat array."""
    return np.concatenate([np.ravel(a) for a in (M, Wt, Minv_W, G, s)]).astype(float)


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
def _solve_into(M, Wt, MinvW, G, s, um, E, eps, moreau, tol, passive, up, lam, res):
    """Solve and certify one impact into (u⁺, Λ, residuals); True when certified."""
    n, m = um.size, passive.size
    if moreau:
        E = eps * np.eye(m)
    g = Wt @ um
    q = g + E @ g
    w = np.empty(m)
    if lcp_psd(G, q, passive, lam, w, 20 * m + 50) != SOLVED:
        return False
    for i in range(n):
        total = um[i]
        for j in range(m):
            total += MinvW[i, j] * lam[j]
        up[i] = total
    dense_residuals(M, Wt, MinvW, s, um, up, lam, E, eps, moreau, res)
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
                       out[n:n + m], out[n + m:n + m + 6])


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
    for r in range(k):
        ok[r] = _solve_into(M, Wt, MinvW, G, s, Um[r], E, eps, moreau, tol, passive, Up[r],
                            Lam[r], Res[r])
    return Up, Lam, Res, ok
