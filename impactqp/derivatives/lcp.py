"""Derivatives of the solution of an LCP ``w = Gλ + q, 0 ≤ λ ⟂ w ≥ 0`` with G symmetric
positive semidefinite (docs/theory.md §18–§19).

On a stable active set (every contact either pressed, λᵢ > 0 = wᵢ, or separating,
λᵢ = 0 < wᵢ) the solution is affine in q and smooth in G: differentiating
``(Gλ + q)_A = 0, λ_I = 0`` gives the tangent. Where some contacts are degenerate
(λᵢ = 0 = wᵢ, a kink) the solution map is only B-differentiable: its one-sided derivative
along a direction solves a |D|-sized LCP on the degenerate contacts, and the limiting
Jacobians are the tangents of the active sets A ∪ S, S ⊆ D (docs/theory.md §19).
"""

from __future__ import annotations

import itertools
from typing import NamedTuple

import numpy as np

from ..errors import InputError, NoSolutionError, ShapeError
from ..qp.lcp import solve_psd_lcp

ENUMERATE_UP_TO = 10
"""Most degenerate contacts whose subsets :func:`directional` enumerates (2¹⁰ small
systems); beyond, the reduced LCP goes to the library's LCP solver."""


class ActiveSet(NamedTuple):
    """Which contacts of an LCP solution press, which are degenerate, and how far the
    solution is from a change of active set (docs/theory.md §18).

    Attributes
    ----------
    active : ndarray of bool, shape (m,)
        λᵢ > 0 and wᵢ = 0 (within the tolerance).
    degenerate : ndarray of bool, shape (m,)
        λᵢ = 0 = wᵢ within the tolerance: a kink of the solution map.
    margin : float
        The smallest λᵢ over active and wᵢ over inactive non-degenerate contacts, in the
        LCP's units (+inf when there is none): the radius measure of the cell.
    """

    active: np.ndarray
    degenerate: np.ndarray
    margin: float

    @property
    def inactive(self) -> np.ndarray:
        """Contacts neither active nor degenerate (λᵢ = 0 < wᵢ)."""
        return ~(self.active | self.degenerate)


def classify(lam: np.ndarray, w: np.ndarray, tol: float) -> ActiveSet:
    """The active set of an LCP solution (λ, w = Gλ + q).

    A contact is degenerate when both λᵢ and wᵢ are at most ``tol``; otherwise it is active
    when λᵢ ≥ wᵢ and inactive when not (docs/theory.md §18).

    Parameters
    ----------
    lam, w : (m,) array_like
        The solution and its slack.
    tol : float
        Absolute tolerance, in the LCP's units.
    """
    lam = np.asarray(lam, dtype=float).ravel()
    w = np.asarray(w, dtype=float).ravel()
    if lam.shape != w.shape:
        raise ShapeError(f"lam and w must have the same shape, got {lam.shape} and {w.shape}")
    degenerate = np.maximum(lam, w) <= tol
    active = ~degenerate & (lam >= w)
    inactive = ~degenerate & ~active
    sizes = np.concatenate([lam[active], w[inactive]])
    return ActiveSet(active, degenerate, float(sizes.min()) if sizes.size else np.inf)


def _rhs(lam: np.ndarray, m: int, dG, dq) -> np.ndarray:
    """r = dG λ + dq as an (m, k) array (k directions)."""
    r = np.zeros((m, 1)) if dq is None else np.asarray(dq, dtype=float)
    if r.ndim == 1:
        r = r[:, None]
    if r.ndim != 2 or r.shape[0] != m:
        raise ShapeError(f"dq must have shape ({m},) or ({m}, k), got {np.shape(dq)}")
    if dG is not None:
        dG = np.asarray(dG, dtype=float)
        if dG.shape != (m, m):
            raise ShapeError(f"dG must have shape ({m}, {m}), got {dG.shape}")
        r = r + (dG @ lam)[:, None]
    return r


RCOND = 1e-12
"""Eigenvalues of G_AA below RCOND times its largest count as zero (redundant contacts)."""


class Factor(NamedTuple):
    """The pseudo-inverse of G restricted to a set of contacts, embedded in m × m
    (docs/theory.md §18).

    Attributes
    ----------
    K : (m, m) ndarray
        K_AA = G_AA⁺ (the Moore–Penrose inverse), zero elsewhere.
    rank : int
        The rank of G_AA: Λ_A is unique when it equals |A|.
    condition : float
        Largest over smallest non-zero eigenvalue of G_AA (1 for an empty set).
    """

    K: np.ndarray
    rank: int
    condition: float


def factor(G: np.ndarray, mask: np.ndarray) -> Factor:
    """The :class:`Factor` of G on the contacts of ``mask`` (a symmetric eigen-decomposition:
    the minimum-norm solution where G_AA is singular)."""
    m = G.shape[0]
    K = np.zeros((m, m))
    idx = np.flatnonzero(mask)
    if not idx.size:
        return Factor(K, 0, 1.0)
    vals, vecs = np.linalg.eigh(G[np.ix_(idx, idx)])
    top = vals.max(initial=0.0)
    keep = vals > RCOND * top
    if not keep.any():
        return Factor(K, 0, np.inf)
    V = vecs[:, keep]
    K[np.ix_(idx, idx)] = (V / vals[keep]) @ V.T
    return Factor(K, int(keep.sum()), float(top / vals[keep].min()))


def _solve_on(G: np.ndarray, mask: np.ndarray, r: np.ndarray) -> np.ndarray:
    """dλ with dλ off ``mask`` = 0 and (G dλ + r) on ``mask`` = 0, minimum-norm where
    G restricted to ``mask`` is singular."""
    return -(factor(G, mask).K @ r)


def _check(G, lam) -> tuple[np.ndarray, np.ndarray]:
    G = np.asarray(G, dtype=float)
    lam = np.asarray(lam, dtype=float).ravel()
    m = lam.size
    if G.shape != (m, m):
        raise ShapeError(f"G must have shape ({m}, {m}), got {G.shape}")
    return G, lam


def tangent(G, lam, aset: ActiveSet, dG=None, dq=None) -> np.ndarray:
    """The derivative of λ on the fixed active set ``aset.active`` (docs/theory.md §18).

    Solves dλ_I = 0, (G dλ + dG λ + dq)_A = 0, the minimum-norm solution where G_AA is
    singular. Degenerate contacts are held at dλ = 0 (the default element of docs/theory.md §19).

    Parameters
    ----------
    G : (m, m) array_like
    lam : (m,) array_like
        The solution λ.
    aset : ActiveSet
    dG : (m, m) array_like, optional
    dq : (m,) or (m, k) array_like, optional
        One direction, or k at once (columns).

    Returns
    -------
    ndarray, shape of ``dq`` ((m,) when ``dq`` is None)
    """
    G, lam = _check(G, lam)
    r = _rhs(lam, lam.size, dG, dq)
    out = _solve_on(G, aset.active, r)
    return out if dq is not None and np.ndim(dq) == 2 else out[:, 0]


def _reduced_lcp(G: np.ndarray, aset: ActiveSet, r: np.ndarray) -> np.ndarray:
    """The degenerate contacts' LCP (Schur complement on A), solved by the LCP machinery."""
    A, D = np.flatnonzero(aset.active), np.flatnonzero(aset.degenerate)
    GAA_pinv = np.linalg.pinv(G[np.ix_(A, A)]) if A.size else np.zeros((0, 0))
    GDA, GAD = G[np.ix_(D, A)], G[np.ix_(A, D)]
    S = G[np.ix_(D, D)] - GDA @ GAA_pinv @ GAD
    S = 0.5 * (S + S.T)
    qD = r[D] - GDA @ (GAA_pinv @ r[A])
    dlam_D = solve_psd_lcp(S, qD).z
    out = np.zeros(G.shape[0])
    out[D] = dlam_D
    if A.size:
        out[A] = -GAA_pinv @ (r[A] + GAD @ dlam_D)
    return out


def _directional_one(G: np.ndarray, aset: ActiveSet, r: np.ndarray) -> np.ndarray:
    D = np.flatnonzero(aset.degenerate)
    if D.size > ENUMERATE_UP_TO:
        return _reduced_lcp(G, aset, r)
    scale = (np.abs(G).max(initial=0.0) + 1.0) * (np.abs(r).max(initial=0.0) + 1e-300)
    best, best_violation = None, np.inf
    for mask in limiting_active_sets(aset, cap=2 ** D.size):
        d = _solve_on(G, mask, r[:, None])[:, 0]
        w = G @ d + r
        free = D[~mask[D]]
        violation = max(-d[D[mask[D]]].min(initial=0.0), -w[free].min(initial=0.0),
                        np.abs(w[mask]).max(initial=0.0) / 1e3)
        if violation < best_violation:
            best, best_violation = d, violation
        if violation <= 1e-10 * scale * (1.0 + np.abs(d).max(initial=0.0)):
            return d
    if best is None or best_violation > 1e-6 * scale * (1.0 + np.abs(best).max(initial=0.0)):
        return _reduced_lcp(G, aset, r)
    return best


def directional(G, lam, aset: ActiveSet, dG=None, dq=None) -> np.ndarray:
    """The one-sided derivative of λ along (dG, dq) at a kink (docs/theory.md §19).

    Solves dλ_I = 0, (G dλ + dG λ + dq)_A = 0 and
    0 ≤ dλ_D ⟂ (G dλ + dG λ + dq)_D ≥ 0, a mixed LCP of the size of the degenerate set D:
    by enumerating the subsets S ⊆ D for |D| ≤ :data:`ENUMERATE_UP_TO`, else as the LCP of
    the Schur complement of G_AA solved by :func:`impactqp.qp.lcp.solve_psd_lcp`. Equals
    :func:`tangent` when D is empty.

    Parameters
    ----------
    G, lam, aset, dG, dq
        As for :func:`tangent`; with k columns in ``dq`` each is a separate direction.

    Raises
    ------
    NoSolutionError
        The reduced LCP has no solution (a direction leaving the range of G_AA).
    """
    G, lam = _check(G, lam)
    r = _rhs(lam, lam.size, dG, dq)
    if not aset.degenerate.any():
        out = _solve_on(G, aset.active, r)
    else:
        cols = [_directional_one(G, aset, r[:, j]) for j in range(r.shape[1])]
        out = np.stack(cols, axis=1)
    if not np.isfinite(out).all():
        raise NoSolutionError("the one-sided derivative is not finite: G_AA is too ill "
                              "conditioned along this direction")
    return out if dq is not None and np.ndim(dq) == 2 else out[:, 0]


def limiting_active_sets(aset: ActiveSet, cap: int) -> list[np.ndarray]:
    """The active sets A ∪ S for S ⊆ D (degenerate contacts), smallest S first, at most
    ``cap`` of them: the cells whose tangents are the limiting Jacobians
    (docs/theory.md §19).
    """
    if cap < 1:
        raise InputError(f"cap must be at least 1, got {cap}")
    D = np.flatnonzero(aset.degenerate)
    out: list[np.ndarray] = []
    for size in range(D.size + 1):
        for S in itertools.combinations(D, size):
            mask = aset.active.copy()
            mask[list(S)] = True
            out.append(mask)
            if len(out) >= cap:
                return out
    return out
