"""Moreau's law (docs/theory.md §3) for many impacts of one short chain, column by column.

For a chain of a few balls, one column of a chunk of rows (one ball's velocities, one
contact's impulses) is a contiguous array, and the whole impact is a fixed sequence of
elementwise operations on columns: the weighted isotonic regression by its min–max formula
and the impulses by anchored sums (docs/theory.md §5), then every residual of Moreau's
certificate recomputed from the returned u⁺ and Λ (docs/theory.md §8). There is no per-row
Python work and no data-dependent loop, so a chunk costs a few dozen array operations
whatever its content.

The residuals are those of every chain certificate, computed in compiled code for blocks of
rows side by side by the steps of :func:`impactqp.kernels.residuals.chain_residuals`
(:func:`impactqp.kernels.chain_batch.chain_residual_columns`, which passes the rows at
extreme velocities again one by one, rescaled).
"""

from __future__ import annotations

from functools import reduce

import numpy as np

from ..kernels.chain_batch import chain_residual_columns
from ..model.problem import ImpactProblem
from ..model.structure import ImpactStructure
from .base import MOREAU_FAMILY, ImpactLaw

MAX_BALLS = 6
"""Longest chain served: the min–max formula takes about N³/6 comparisons per row."""


def suits(problem: ImpactProblem, law: ImpactLaw) -> bool:
    """Whether :class:`ChainRows` serves ``law`` on ``problem``: a law of Moreau's family
    (``law.family``, its ``eps``) on a chain of at most :data:`MAX_BALLS` balls with at least
    one contact."""
    return (law.family == MOREAU_FAMILY and problem.chain is not None
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
        self.masses = np.ascontiguousarray(chain.masses, dtype=float)
        self.inverse = 1.0 / self.masses
        self.left, self.right = bool(chain.left_wall), bool(chain.right_wall)
        self.scale = np.ascontiguousarray(structure.contact_scale, dtype=float)
        self.eps = float(eps)
        self.mass_list = self.masses.tolist()  # Python floats: cheaper in column products
        n = len(self.mass_list)
        self.weight = {(a, b): float(sum(self.mass_list[a:b + 1]))
                       for a in range(n) for b in range(a + 1, n)}

    def projection(self, u: list[np.ndarray]) -> list[np.ndarray]:
        """Columns of z, the M-projection of u⁻ onto T_C: the weighted isotonic regression
        zⱼ = max_{a≤j} min_{b≥j} mean(u⁻_a..u⁻_b) (weights m), clipped at 0 on a wall side."""
        n, m = len(u), self.mass_list
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
        n, m = len(u), self.mass_list
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

    def residuals(self, U: np.ndarray, Up: np.ndarray, Lam: np.ndarray,
                  out: np.ndarray | None = None) -> np.ndarray:
        """Moreau's residuals (docs/theory.md §8) of the rows, a (6, k) array, one column per
        residual in the order of :data:`impactqp.kernels.residuals.RESIDUALS` (written into
        ``out`` when given), by the one definition of the chain certificate
        (the steps of :func:`impactqp.kernels.residuals.chain_residuals`, rows side by side)."""
        if out is None:
            out = np.empty((6, U.shape[0]))
        chain_residual_columns(U, Up, Lam, self.masses, self.inverse, self.scale, self.left,
                               self.right, self.eps, self.eps, True, out)
        return out
