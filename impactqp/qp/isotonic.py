"""Exact O(N) Moreau impacts for 1-D chains of balls (docs/theory.md §1, §3, §5).

A chain of ``N`` balls with masses ``m`` has every neighbour contact closed: gap
``g_i = q_{i+1} - q_i``, ``W`` column ``e_{i+1} - e_i``.  Optional fixed walls add the
columns ``e_1`` (left, gap ``q_1 - wall``) and ``-e_N`` (right, gap ``wall - q_N``).  Contact
order everywhere: ``[left wall, gaps 1..N-1, right wall]``.

Moreau's projection (docs/theory.md §3) ``z = argmin sum_i m_i (v_i - u⁻_i)^2`` s.t. ``Wᵀv >= 0``
is the
weighted isotonic regression of ``u⁻`` (``v_1 <= ... <= v_N``); a wall bound ``v_1 >= 0``
or ``v_N <= 0`` is applied by clipping the unbounded regression (checked against a QP in
the tests).  Impulses follow from ``M(u⁺ - u⁻) = WΛ`` (docs/theory.md §1) by a cumulative sum
anchored at
contacts known to be inactive, where ``Λ = 0`` exactly.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np
from scipy.optimize import isotonic_regression

__all__ = ["ChainSolution", "chain_moreau", "chain_moreau_batch", "chain_projection"]


@dataclass(frozen=True)
class ChainSolution:
    """Result of a chain impact (docs/theory.md §3).

    Attributes
    ----------
    u_plus : ndarray, shape (N,) or (k, N)
        Post-impact velocities ``u⁺ = (1+ε) z - ε u⁻``.
    impulses : ndarray, shape (m,) or (k, m)
        Contact impulses ``Λ >= 0`` in the order ``[left wall, gaps 1..N-1, right wall]``.
    z : ndarray, shape (N,) or (k, N)
        The M-projection of ``u⁻`` onto the tangent cone (the ε = 0 answer).
    """

    u_plus: np.ndarray
    impulses: np.ndarray
    z: np.ndarray


def _check(masses, u, eps, ndim: int) -> tuple[np.ndarray, np.ndarray, float]:
    m = np.asarray(masses, dtype=float)
    if m.ndim != 1 or m.size == 0:
        raise ValueError(f"masses must be a non-empty 1-D array, got shape {m.shape}")
    if not (m.min() > 0.0 and m.max() < np.inf):  # NaN fails the first test
        raise ValueError("masses must be positive and finite")
    name = "u_minus" if ndim == 1 else "U_minus"
    u = np.asarray(u, dtype=float)
    if u.ndim != ndim or u.shape[-1] != m.size:
        want = "(N,)" if ndim == 1 else "(k, N)"
        raise ValueError(f"{name} must have shape {want} with N = {m.size}, got {u.shape}")
    if not np.isfinite(u).all():
        raise ValueError(f"{name} must be finite")
    try:
        e = float(eps)
    except (TypeError, ValueError):
        raise ValueError(f"eps must be a real number in [0, 1], got {eps!r}") from None
    if not 0.0 <= e <= 1.0:  # also rejects NaN
        raise ValueError(f"eps must be in [0, 1], got {eps!r}")
    return m, u, e


def _prefix_sums(p: np.ndarray, block: int = 64) -> np.ndarray:
    """Inclusive cumulative sums along axis 1, blocked recursively so that rounding grows
    like ``block * log_block(N)`` ulps instead of ``N`` ulps (plain ``np.cumsum``)."""
    k, n = p.shape
    if n <= block:
        return np.cumsum(p, axis=1)
    nb = -(-n // block)
    q = np.zeros((k, nb * block))
    q[:, :n] = p
    inner = np.cumsum(q.reshape(k, nb, block), axis=2)
    inner[:, 1:, :] += _prefix_sums(inner[:, :, -1], block)[:, :-1, None]
    return inner.reshape(k, nb * block)[:, :n]


def _pava_rows(y: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Weighted isotonic regression of every row of ``y`` by a PAVA vectorised over rows.

    The Python loop runs over the N positions (and over the merges a step triggers); each
    iteration treats all k rows at once, so cost is O(k N) array work for small N.
    """
    k, n = y.shape
    base = np.arange(k) * n  # row r's stack lives in the flat slots base[r] .. base[r]+n-1
    bw, bs, bm = np.empty(k * n), np.empty(k * n), np.empty(k * n)  # weight, sum, mean
    b0 = np.empty(k * n, dtype=np.intp)  # first index of each block
    top = base.copy()  # next free slot per row
    for j in range(n):
        bw[top], bs[top], bm[top], b0[top] = w[j], w[j] * y[:, j], y[:, j], j
        top += 1
        act = np.flatnonzero(bm[top - 2] > bm[top - 1]) if j else top[:0]
        while act.size:  # pool adjacent violators; at most j merges per row
            t = top[act]
            bw[t - 2] += bw[t - 1]
            bs[t - 2] += bs[t - 1]
            bm[t - 2] = bs[t - 2] / bw[t - 2]
            top[act] = t = t - 1
            keep = t - base[act] >= 2
            act, t = act[keep], t[keep]
            act = act[bm[t - 2] > bm[t - 1]]
    valid = np.arange(n)[None, :] < (top - base)[:, None]
    mark = np.zeros((k, n), dtype=np.intp)
    mark[np.nonzero(valid)[0], b0.reshape(k, n)[valid]] = 1
    return bm[np.cumsum(mark, axis=1) - 1 + base[:, None]]


def _finish(m, u, z, eps, left: bool, right: bool) -> ChainSolution:
    """Clip for the walls, then impulses by anchored cumulative sums (rows of 2-D arrays)."""
    k, n = u.shape
    if left and right:
        z = np.zeros_like(z)
    elif left:
        z = np.maximum(z, 0.0)
    elif right:
        z = np.minimum(z, 0.0)
    # L[:, j] is the impulse of the contact left of ball j (j = 0: left wall, j = n: right
    # wall); m_j (z_j - u_j) = L_j - L_{j+1}, so L_j = L_a + C_a - C_j for any anchor a,
    # where C_j = sum_{i<j} m_i (z_i - u_i).  Anchors have L_a = 0: absent walls and
    # inactive contacts (z strictly separating), per complementarity (docs/theory.md §3).
    c = np.zeros((k, n + 1))
    c[:, 1:] = _prefix_sums(m * (z - u))
    if left and right:
        # z = 0: every contact is active and Λ is one of the set Λ_min + t (1, ..., 1),
        # t >= 0 (W has rank N, N+1 columns).  Λ_min (componentwise least, so least in
        # every norm) takes L_0 = max_j C_j (C_0 = 0 keeps L_0 >= 0).
        lam = c.max(axis=1, keepdims=True) - c
    else:
        a = np.empty((k, n + 1), dtype=bool)
        a[:, 0] = (z[:, 0] > 0.0) if left else True
        a[:, n] = (z[:, -1] < 0.0) if right else True
        np.greater(z[:, 1:], z[:, :-1], out=a[:, 1:n])
        pos = np.flatnonzero(a)  # anchors, flat index into c
        counts = np.empty_like(pos)
        if left:  # every row ends with an anchor (L_N = 0): use the next anchor
            counts[:1] = pos[:1] + 1
            np.subtract(pos[1:], pos[:-1], out=counts[1:])
        else:  # every row starts with an anchor (L_0 = 0): use the last anchor
            counts[-1:] = k * (n + 1) - pos[-1:]
            np.subtract(pos[1:], pos[:-1], out=counts[:-1])
        lam = np.repeat(c.ravel()[pos], counts).reshape(k, n + 1) - c
    lam = lam[:, (0 if left else 1):(n + 1 if right else n)]
    if eps == 0.0:
        return ChainSolution(u_plus=z.copy(), impulses=lam, z=z)
    return ChainSolution(u_plus=(1.0 + eps) * z - eps * u, impulses=(1.0 + eps) * lam, z=z)


def _scan(v: np.ndarray) -> None:
    """Inclusive prefix sums of ``v`` in place, by pairs: each level adds neighbours (vector
    operations over strided views, not numpy's sequential loop) and recurses on the pair
    sums, so rounding grows like ``log2 N`` ulps. ``v.size`` must be a power of two times
    at most 64 (the size below which ``np.cumsum`` finishes)."""
    if v.size <= 64:
        np.cumsum(v, out=v)
        return
    pairs = v.reshape(-1, 2)
    first, second = pairs[:, 0], pairs[:, 1]
    second += first
    _scan(second)
    first[1:] += second[:-1]


_SCRATCH = threading.local()
"""Each thread's prefix-sum buffer, kept between solves: a fresh buffer of a long chain costs
more in page faults than the sums themselves (its contents never leave chain_projection)."""


def _prefix_buffer(n: int) -> np.ndarray:
    """A buffer of length 1 + n', n' ≥ n the size :func:`_scan` takes (n' / 2^k ≤ 64), whose
    first entry and tail beyond n are zero (the calling thread's, reused when it fits)."""
    k = max(0, int(np.ceil(np.log2(max(n, 1) / 64))))
    size = 1 + -(-n // 2**k) * 2**k
    buffer = getattr(_SCRATCH, "buffer", None)
    if buffer is None or buffer.size < size or buffer.size > 2 * size:
        buffer = _SCRATCH.buffer = np.empty(size)
    E = buffer[:size]
    E[0] = 0.0
    E[n + 1:] = 0.0
    return E


def chain_projection(m: np.ndarray, u: np.ndarray, left: bool,
                     right: bool) -> tuple[np.ndarray, np.ndarray]:
    """z = prox_{T_C}(u⁻) and the impulses Λ_z of M(z − u⁻) = WΛ_z of one chain, without
    checking the inputs (positive finite ``m``, finite ``u``): one isotonic regression, one
    prefix sum, anchors from the regression's blocks (docs/theory.md §3, §5).

    Each block of the regression is a run of equal z whose mean is the weighted mean of u,
    so Σ m(z − u) over a block is 0 and the contact before each block start carries no
    impulse: with E_j = Σ_{i<j} mᵢ(zᵢ − uᵢ), the impulse left of ball j is
    L_j = E_a − E_j for the block start a ≤ j. A clipped run at a wall (z = 0) takes the
    first free block start as anchor; with both walls z = 0 and Λ_z is the least of its
    half-line (see :func:`chain_moreau`).
    """
    n = m.size
    if n > 1:
        res = isotonic_regression(u, weights=m)
        z, starts = res.x, res.blocks
    else:
        z, starts = u.copy(), np.array([0, 1])
    # blocks whose mean is at most 0, before the walls clip them
    free = int(np.searchsorted(z[starts[:-1]], 0.0, side="right")) if left or right else 0
    if left and right:
        z[:] = 0.0
    elif left:
        np.maximum(z, 0.0, out=z)
    elif right:
        np.minimum(z, 0.0, out=z)
    E = _prefix_buffer(n)
    d = E[1:n + 1]
    np.subtract(z, u, out=d)
    d *= m
    _scan(E[1:])
    if left and right:
        return z, E[:n + 1].max() - E[:n + 1]
    values, lengths = E[starts[:-1]], np.diff(starts)
    if left:  # the clipped blocks (z = 0) and the wall hang from the first free block start
        k = starts[free]
        values = np.concatenate((E[k:k + 1], values[free:]))
        lengths = np.concatenate(([k], lengths[free:]))
    elif right:  # the clipped blocks and the wall hang from the first clipped block start
        k = starts[free]
        values = np.concatenate((values[:free], E[k:k + 1]))
        lengths = np.concatenate((lengths[:free], [n + 1 - k]))
    lam = np.repeat(values, lengths)  # E at each contact's anchor
    lo = 0 if left else 1
    np.subtract(lam[lo:], E[lo:lo + lam.size - lo], out=lam[lo:])
    return z, lam[lo:]


def chain_moreau(
    masses, u_minus, eps: float = 0.0, *, left_wall: bool = False, right_wall: bool = False
) -> ChainSolution:
    """Moreau impact (docs/theory.md §3) of a chain of balls with all contacts closed, exact in
    O(N).

    Parameters
    ----------
    masses : array_like, shape (N,)
        Positive finite masses (``M = diag(masses)``).
    u_minus : array_like, shape (N,)
        Pre-impact velocities ``u⁻``.
    eps : float, default 0.0
        Global restitution coefficient ε in [0, 1].
    left_wall, right_wall : bool, default False
        Fixed wall before ball 1 (``u_1 >= 0``) / after ball N (``u_N <= 0``).

    Returns
    -------
    ChainSolution
        ``u_plus``, ``impulses`` (order ``[left wall, gaps 1..N-1, right wall]``, length
        ``N - 1 + left_wall + right_wall``) and ``z``.

    Notes
    -----
    ``z`` is the mass-weighted isotonic regression of ``u⁻`` (PAVA, O(N)), clipped at 0 on
    a wall side; ``u⁺ = (1+ε) z - ε u⁻`` and ``Λ = (1+ε) Λ_z`` with ``M(z - u⁻) = W Λ_z``
    (docs/theory.md §1, §3).  With one or no wall ``W`` has full column rank and ``Λ`` is
    unique.  With both walls ``z = 0`` and the valid impulses (``Λ >= 0``, complementary with
    ``γ⁺ + εγ⁻``) form the half-line ``Λ_min + t (1, ..., 1)``, ``t >= 0``; the one returned
    is ``Λ_min``, the componentwise least, hence the least in max-norm (and every norm).

    Examples
    --------
    >>> chain_moreau([1.0, 1.0, 1.0], [3.0, 0.0, 0.0]).u_plus  # docs/theory.md §5, ε = 0
    array([1., 1., 1.])
    """
    m, u, e = _check(masses, u_minus, eps, 1)
    z, lam = chain_projection(m, u, bool(left_wall), bool(right_wall))
    if e == 0.0:
        return ChainSolution(u_plus=z.copy(), impulses=lam, z=z)
    return ChainSolution(u_plus=(1.0 + e) * z - e * u, impulses=(1.0 + e) * lam, z=z)


def chain_moreau_batch(
    masses,
    U_minus,
    eps: float = 0.0,
    *,
    left_wall: bool = False,
    right_wall: bool = False,
    pava_max_n: int = 64,
) -> ChainSolution:
    """Moreau impacts (docs/theory.md §3) of k chains sharing ``masses``, one per row of
    ``U_minus``.

    Parameters
    ----------
    masses : array_like, shape (N,)
        Positive finite masses shared by all rows.
    U_minus : array_like, shape (k, N)
        Pre-impact velocities, one impact per row.
    eps, left_wall, right_wall
        As in :func:`chain_moreau`.
    pava_max_n : int, default 64
        For ``N <= pava_max_n`` and ``k >= 2 N`` a PAVA vectorised over rows is used
        (its cost is ~N Python-level steps); otherwise scipy's ``isotonic_regression`` row
        by row.  Both are exact and agree to rounding.

    Returns
    -------
    ChainSolution
        Fields with leading axis k: ``u_plus`` (k, N), ``impulses`` (k, m), ``z`` (k, N);
        row i equals ``chain_moreau(masses, U_minus[i], ...)``.
    """
    m, u, e = _check(masses, U_minus, eps, 2)
    if (m.size <= pava_max_n and u.shape[0] >= 2 * m.size) or u.shape[0] == 0:
        z = _pava_rows(u, m)
    else:
        z = np.stack([isotonic_regression(r, weights=m).x for r in u])
    return _finish(m, u, z, e, bool(left_wall), bool(right_wall))
