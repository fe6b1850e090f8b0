"""Moreau's law (docs/theory.md §3) for many impacts of one short chain, in compiled passes
over blocks of rows.

For a chain of a few balls the whole impact is a fixed sequence of elementwise operations on
the columns of a block of rows (one ball's velocities, one contact's impulses): the weighted
isotonic regression by its min–max formula and the impulses by anchored sums
(docs/theory.md §5), written straight into the batch's u⁺ and Λ; then every residual of
Moreau's certificate is recomputed from the returned u⁺ and Λ (docs/theory.md §8) in a pass
of its own. There is no per-row Python work and no data-dependent loop.

The residuals are those of every chain certificate, computed in compiled code for blocks of
rows side by side by the steps of :func:`impactqp.kernels.residuals.chain_residuals`
(:func:`impactqp.kernels.chain_batch.chain_residual_columns`, which passes the rows at
extreme velocities again one by one, rescaled).
"""

from __future__ import annotations

import numpy as np

from ..kernels.chain_batch import chain_impact_rows, chain_residual_columns
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
        masses, n = self.masses.tolist(), len(self.masses)
        self.weight = np.array([[float(sum(masses[a:b + 1])) for b in range(n)]
                                for a in range(n)])  # m_a + … + m_b, summed in order

    def solve(self, U: np.ndarray, Up: np.ndarray, Lam: np.ndarray) -> None:
        """u⁺ = (1+ε)z − εu⁻ and Λ = (1+ε)Λ_z of the rows of U (z the M-projection of u⁻
        onto T_C: the weighted isotonic regression by its min–max formula, the impulses by
        anchored sums, docs/theory.md §5) into the rows of ``Up`` and ``Lam``, in compiled
        passes over blocks of rows (:func:`impactqp.kernels.chain_batch.chain_impact_rows`)."""
        chain_impact_rows(U, self.masses, self.weight, self.left, self.right, self.eps, Up,
                          Lam)

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
