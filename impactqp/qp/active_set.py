"""A prepared exact kernel for small impacts: active-set enumeration with cached inverses.

For the LCP ``0 ≤ Λ ⟂ GΛ + q ≥ 0`` (docs/theory.md §3, §9; impulse form) with few contacts,
every support
J ⊆ {1..m} whose block G_JJ is invertible gives the candidate Λ_J = −G_JJ⁻¹ q_J, Λ_F = 0,
valid when Λ_J ≥ 0 and (GΛ + q)_F ≥ 0. The inverses depend only on G, so they are computed
once per problem structure; a solve is then a few tiny matrix–vector products, and a batch
of k pre-impact velocities is one matrix product per support (vectorised over k).

A solution with linearly independent support columns exists whenever q ∈ range(G) (always
for Moreau's law, q = (1+ε)γ⁻), so skipping singular blocks loses nothing there; when no
support fits (q ∉ range(G)) the kernel says so and the caller falls back to a QP backend.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from ..base.rowwise import row_max, row_min

MAX_CONTACTS = 10
SUPPORT_TOL = 1e-12
"""Relative slack with which a support is accepted (Λ_J ≥ −tol·‖q‖/‖G‖, w_F ≥ −tol·‖q‖)."""


class ActiveSetKernel:
    """Exact small-LCP solver prepared for one Delassus matrix G (m ≤ MAX_CONTACTS).

    Parameters
    ----------
    G : (m, m) ndarray
        Symmetric positive semidefinite Delassus matrix.
    """

    def __init__(self, G: np.ndarray) -> None:
        G = np.asarray(G, dtype=float)
        m = G.shape[0]
        if m > MAX_CONTACTS:
            raise ValueError(f"the active-set kernel takes at most {MAX_CONTACTS} contacts, "
                             f"got {m}")
        self.G, self.m = G, m
        self.scale = max(np.abs(G).max(initial=0.0), 1e-300)
        # large supports first (impacts close most contacts); each support's inverse is
        # computed when it is first tried and kept, so a fresh kernel costs what it uses
        self._order = [J for size in range(m, 0, -1) for J in combinations(range(m), size)]
        self._arrays: dict[int, tuple | None] = {}
        self._last = 0

    @property
    def n_supports(self) -> int:
        """How many supports there are (2^m − 1, largest first; see :meth:`support`)."""
        return len(self._order)

    def support(self, idx: int) -> tuple | None:
        """(J, F, G_JJ⁻¹, G_FJ) of support ``idx``, or None when G_JJ is singular."""
        if idx not in self._arrays:
            J = np.array(self._order[idx])
            rows = self.G[J]
            block = rows[:, J]
            # G_JJ is symmetric positive semidefinite: its condition number is λmax/λmin
            eig = np.linalg.eigvalsh(block)
            if not eig[0] * 1e12 >= eig[-1] or not eig[0] > 0.0:
                self._arrays[idx] = None
            else:
                F = np.array([i for i in range(self.m) if i not in self._order[idx]], dtype=int)
                self._arrays[idx] = (J, F, np.linalg.inv(block), self.G[F][:, J])
        return self._arrays[idx]

    def solve(self, q: np.ndarray, tol: float = SUPPORT_TOL) -> np.ndarray | None:
        """Return Λ solving the LCP, or None when no invertible support fits."""
        qs = max(float(np.abs(q).max(initial=0.0)), 1e-300)
        if np.all(q >= 0):
            return np.zeros(self.m)
        n_sup = len(self._order)
        for k in range(n_sup):
            idx = (self._last + k) % n_sup
            found = self.support(idx)
            if found is None:
                continue
            J, F, inv, GFJ = found
            lam_J = -(inv @ q[J])
            if lam_J.min() < -tol * qs / self.scale:
                continue
            if F.size and (GFJ @ lam_J + q[F]).min() < -tol * qs:
                continue
            self._last = idx
            lam = np.zeros(self.m)
            lam[J] = np.maximum(lam_J, 0.0)
            return lam

        return None

    def solve_batch(self, Q: np.ndarray,
                    tol: float = SUPPORT_TOL) -> tuple[np.ndarray, np.ndarray]:
        """Solve k LCPs with the rows of Q (k × m) as q; return (Λ (k × m), solved mask).

        Every support is tried on all rows at once (dense products beat row gathers for the
        small m this kernel serves); a row takes the first support that fits it.
        """
        k = Q.shape[0]
        lam = np.zeros((k, self.m))
        qs = np.maximum(row_max(np.abs(Q)), 1e-300)
        done = row_min(Q) >= 0
        lam_tol, w_tol = -tol * qs / self.scale, -tol * qs
        for idx in range(len(self._order)):
            if done.all():
                break
            found = self.support(idx)
            if found is None:
                continue
            J, F, inv, GFJ = found
            full = J.size == self.m
            LJ = (Q if full else Q[:, J]) @ (-inv.T)
            ok = ~done & (row_min(LJ) >= lam_tol)
            if not full:
                ok &= row_min(LJ @ GFJ.T + Q[:, F]) >= w_tol
            if full:
                lam[ok] = LJ[ok]
            else:
                lam[np.ix_(np.flatnonzero(ok), J)] = LJ[ok]
            done |= ok
        np.maximum(lam, 0.0, out=lam)
        return lam, done
