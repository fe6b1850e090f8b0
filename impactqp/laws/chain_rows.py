"""Moreau's law (docs/theory.md §3) for many impacts of one short chain, column by column.

For a chain of a few balls, one column of a chunk of rows (one ball's velocities, one
contact's impulses) is a contiguous array, and the whole impact is a fixed sequence of
elementwise operations on columns: the weighted isotonic regression by its min–max formula
and the impulses by anchored sums (docs/theory.md §5), then every residual of Moreau's
certificate recomputed from the returned u⁺ and Λ (docs/theory.md §8). There is no per-row
Python work and no data-dependent loop, so a chunk costs a few dozen array operations
whatever its content.

Rows whose scale lies outside the plain floating-point range of the residuals (where
:func:`impactqp.model.residuals.normalized_rows` would rescale them) are reported so that the
caller recomputes their residuals with the law's general routine.
"""

from __future__ import annotations

from functools import reduce

import numpy as np

from ..model.problem import ImpactProblem
from ..model.structure import ImpactStructure
from .base import ImpactLaw
from .moreau import Moreau

MAX_BALLS = 6
"""Longest chain served: the min–max formula takes about N³/6 comparisons per row."""

RESIDUALS = ("momentum", "impulse_sign", "law_feasibility", "complementarity",
             "energy_balance", "duality_gap")
"""The keys of Moreau's certificate, in the order of :func:`law_residuals`."""


def suits(problem: ImpactProblem, law: ImpactLaw) -> bool:
    """Whether :class:`ChainRows` serves ``law`` on ``problem``: Moreau's law on a chain of
    at most :data:`MAX_BALLS` balls with at least one contact."""
    return (type(law) is Moreau and problem.chain is not None
            and 0 < problem.n_contacts and problem.n_dof <= MAX_BALLS)


class ChainRows:
    """Moreau's law with restitution ε on rows of one short chain (docs/theory.md §3, §5).

    Parameters
    ----------
    structure : ImpactStructure
        A chain (``structure.chain`` set).
    eps : float
        Restitution ε ∈ [0, 1].
    """

    def __init__(self, structure: ImpactStructure, eps: float) -> None:
        chain = structure.chain
        self.masses = [float(x) for x in chain.masses]
        self.left, self.right = bool(chain.left_wall), bool(chain.right_wall)
        self.scale = [float(x) for x in structure.contact_scale]
        self.eps = float(eps)
        n = len(self.masses)
        self.weight = {(a, b): float(sum(self.masses[a:b + 1]))
                       for a in range(n) for b in range(a + 1, n)}
        # V² = Σ mⱼuⱼ² inside (lo, hi) implies 1e-60 < max|uⱼ| < 1e60 (with a factor 2 for
        # rounding) and 1e-250 < V² < inf: normalized_rows and kinetic_norms then leave the
        # row as it is, and the plain formulas below are the general ones (docs/theory.md §8).
        self.plain = (max(2e-120 * sum(self.masses), 1e-250), 0.5e120 * min(self.masses))

    def projection(self, u: list[np.ndarray]) -> list[np.ndarray]:
        """Columns of z, the M-projection of u⁻ onto T_C: the weighted isotonic regression
        zⱼ = max_{a≤j} min_{b≥j} mean(u⁻_a..u⁻_b) (weights m), clipped at 0 on a wall side."""
        n, m = len(u), self.masses
        if self.left and self.right:
            return [np.zeros_like(u[0]) for _ in range(n)]
        mean = {(a, a): u[a] for a in range(n)}
        for a in range(n - 1):
            total = u[a] * m[a]
            for b in range(a + 1, n):
                total = total + u[b] * m[b]
                mean[a, b] = total / self.weight[a, b]
        z = []
        for j in range(n):
            lows = [reduce(np.minimum, [mean[a, b] for b in range(j, n)]) for a in range(j + 1)]
            z.append(reduce(np.maximum, lows))
        if self.left:
            z = [np.maximum(c, 0.0) for c in z]
        elif self.right:
            z = [np.minimum(c, 0.0) for c in z]
        return z

    def impulses(self, u: list[np.ndarray], z: list[np.ndarray]) -> list[np.ndarray]:
        """Columns of Λ_z with M(z − u⁻) = WΛ_z, in the order [left wall, gaps, right wall]:
        Lⱼ − L_{j+1} = mⱼ(zⱼ − u⁻ⱼ) summed from the previous anchor (the next one when a left
        wall is present), Λ = 0 exactly at anchors (docs/theory.md §5)."""
        n, m = len(u), self.masses
        d = [(z[j] - u[j]) * m[j] for j in range(n)]
        if self.left and self.right:  # z = 0: Λ_min = max_i Cᵢ − Cⱼ, C₀ = 0
            c = [np.zeros_like(u[0])]
            for j in range(n):
                c.append(c[-1] + d[j])
            top = reduce(np.maximum, c)
            return [top - cj for cj in c]
        if self.left:  # from the right: L_N = 0, Lⱼ = L_{j+1} + dⱼ unless j is an anchor
            lam, L = [], None
            for j in range(n - 1, -1, -1):
                L = d[j].copy() if L is None else L + d[j]
                np.copyto(L, 0.0, where=(z[j] > z[j - 1]) if j else (z[0] > 0.0))
                lam.append(L)
            return lam[::-1]
        lam, L = [], None  # from the left: L₀ = 0, L_{j+1} = Lⱼ − dⱼ unless an anchor
        for j in range(1, n + self.right):
            L = -d[0] if L is None else L - d[j - 1]
            np.copyto(L, 0.0, where=(z[j] > z[j - 1]) if j < n else (z[-1] < 0.0))
            lam.append(L)
        return lam

    def solve(self, u: list[np.ndarray]) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """Columns of u⁺ = (1+ε)z − εu⁻ and of Λ = (1+ε)Λ_z for the columns u of u⁻."""
        e = self.eps
        with np.errstate(all="ignore"):  # a row that overflows fails its certificate
            z = self.projection(u)
            lam = self.impulses(u, z)
            if e == 0.0:
                return z, lam
            return ([(1.0 + e) * zj - e * uj for zj, uj in zip(z, u)],
                    [(1.0 + e) * col for col in lam])

    def _contact_velocities(self, v: list[np.ndarray]) -> list[np.ndarray]:
        """Columns of γ = Wᵀv (docs/theory.md §5)."""
        gaps = [v[j + 1] - v[j] for j in range(len(v) - 1)]
        return ([v[0]] if self.left else []) + gaps + ([-v[-1]] if self.right else [])

    def residuals(self, u: list[np.ndarray], up: list[np.ndarray], lam: list[np.ndarray],
                  out: dict[str, np.ndarray]) -> np.ndarray:
        """Write Moreau's residuals (docs/theory.md §8) of the rows into ``out`` (arrays of the
        chunk's length, keys :data:`RESIDUALS`); return the mask of rows in the plain range,
        whose values are final (the others need the general routine)."""
        with np.errstate(all="ignore"):  # rows outside the plain range are redone
            return self._residuals(u, up, lam, out)

    def _residuals(self, u: list[np.ndarray], up: list[np.ndarray], lam: list[np.ndarray],
                   out: dict[str, np.ndarray]) -> np.ndarray:
        n, m, s, e = len(u), self.masses, self.scale, self.eps
        q = reduce(np.add, [u[j] * u[j] * m[j] for j in range(n)])
        fast = (q > self.plain[0]) & (q < self.plain[1])
        V = np.sqrt(q)
        # impact equation: u⁺ − u⁻ − M⁻¹WΛ, ball j getting (L_j − L_{j+1})/mⱼ
        L = ([lam[0]] if self.left else [None]) + lam[self.left:len(lam) - self.right] \
            + ([lam[-1]] if self.right else [None])
        du_sq = None
        for j in range(n):
            du = up[j] - u[j]
            if L[j] is None:  # −(L_{j+1}/mⱼ), exactly as (0 − L_{j+1})/mⱼ
                du += L[j + 1] / m[j]
            else:
                du -= (L[j] if L[j + 1] is None else L[j] - L[j + 1]) / m[j]
            du *= du
            du *= m[j]
            du_sq = du if du_sq is None else np.add(du_sq, du, out=du_sq)
        momentum = np.sqrt(du_sq, out=out["momentum"])
        momentum /= V
        low = reduce(np.minimum, [col * sc for col, sc in zip(lam, s)])
        np.divide(low, V, out=low)
        np.negative(low, out=low)
        np.maximum(low, 0.0, out=out["impulse_sign"])
        out["impulse_sign"] += 0.0  # no −0.0
        w = self._contact_velocities(up)
        if e != 0.0:
            w = [wi + e * gi for wi, gi in zip(w, self._contact_velocities(u))]
        low = reduce(np.minimum, [wi / (V * si) for wi, si in zip(w, s)])
        np.negative(low, out=low)
        np.maximum(low, 0.0, out=out["law_feasibility"])
        V2 = np.multiply(V, V, out=V)
        prods = [np.abs(li * wi) for li, wi in zip(lam, w)]
        np.divide(reduce(np.maximum, prods), V2, out=out["complementarity"])
        gap = np.divide(reduce(np.add, prods), V2, out=out["duality_gap"])
        gap += momentum * momentum
        if e == 0.0:  # 2ε⟨z̃, u⁻ − z̃⟩ with ε = 0
            out["energy_balance"].fill(0.0)
        else:
            zt = [(up[j] + e * u[j]) / (1.0 + e) for j in range(n)]
            inner = reduce(np.add, [zt[j] * m[j] * (u[j] - zt[j]) for j in range(n)])
            np.abs(inner, out=inner)
            inner *= 2.0 * e
            np.divide(inner, V2, out=out["energy_balance"])
        return fast
