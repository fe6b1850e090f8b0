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

from ..kernels.chain import project, project_rows

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


def _contacts(L: np.ndarray, left: bool, right: bool) -> np.ndarray:
    """The chain's impulses from L (L_j left of ball j, L_0 and L_N at the walls), in the
    contact order [left wall, gaps, right wall] (works on rows too)."""
    n = L.shape[-1] - 1
    return L[..., (0 if left else 1):(n + 1 if right else n)]


def chain_projection(m: np.ndarray, u: np.ndarray, left: bool,
                     right: bool) -> tuple[np.ndarray, np.ndarray]:
    """z = prox_{T_C}(u⁻) and the impulses Λ_z of M(z − u⁻) = WΛ_z of one chain, without
    checking the inputs (positive finite ``m``, finite ``u``), by the compiled regression
    and anchored sums of :func:`impactqp.kernels.chain.project` (docs/theory.md §3, §5).

    With both walls z = 0 and Λ_z is the least of its half-line (see :func:`chain_moreau`).
    """
    z, L = np.empty(u.size), np.empty(u.size + 1)
    starts, weight = scratch(u.size)
    project(np.ascontiguousarray(m, dtype=float), np.ascontiguousarray(u, dtype=float),
            bool(left), bool(right), z, L, starts, weight)
    return z, _contacts(L, left, right)


_SCRATCH = threading.local()
"""Each thread's block scratch for the projection, kept between solves: fresh pages of a
long chain cost more than the regression (its contents never leave the kernel)."""


def scratch(n: int) -> tuple[np.ndarray, np.ndarray]:
    """(starts, weight) of at least n + 1 and n entries, the calling thread's when they fit
    (and are not more than twice too long)."""
    kept = getattr(_SCRATCH, "arrays", None)
    if kept is None or kept[1].size < n or kept[1].size > 2 * n + 64:
        kept = _SCRATCH.arrays = (np.empty(n + 1, dtype=np.int64), np.empty(n))
    return kept[0][:n + 1], kept[1][:n]


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
) -> ChainSolution:
    """Moreau impacts (docs/theory.md §3) of k chains sharing ``masses``, one per row of
    ``U_minus``, by the compiled projection row by row
    (:func:`impactqp.kernels.chain.project_rows`).

    Parameters
    ----------
    masses : array_like, shape (N,)
        Positive finite masses shared by all rows.
    U_minus : array_like, shape (k, N)
        Pre-impact velocities, one impact per row.
    eps, left_wall, right_wall
        As in :func:`chain_moreau`.

    Returns
    -------
    ChainSolution
        Fields with leading axis k: ``u_plus`` (k, N), ``impulses`` (k, m), ``z`` (k, N);
        row i equals ``chain_moreau(masses, U_minus[i], ...)``.
    """
    m, u, e = _check(masses, U_minus, eps, 2)
    z, L = project_rows(m, np.ascontiguousarray(u), bool(left_wall), bool(right_wall))
    lam = _contacts(L, bool(left_wall), bool(right_wall))
    if e == 0.0:
        return ChainSolution(u_plus=z.copy(), impulses=lam, z=z)
    return ChainSolution(u_plus=(1.0 + e) * z - e * u, impulses=(1.0 + e) * lam, z=z)
