"""Certificates that impactqp recomputes itself for every result it returns
(docs/theory.md §8).

All residuals are dimensionless, measured in the problem's own units: velocities
against V = ‖u⁻‖ (the kinetic norm), the velocity of contact i against sᵢV with
sᵢ = sqrt(Gᵢᵢ) (|γᵢ| ≤ sᵢ‖u‖ by Cauchy–Schwarz in M), impulse Λᵢ against V/sᵢ (the
impulse that changes the velocity by V along contact i), energies against V². The
computations live in
:mod:`impactqp.model.residuals`, which makes them safe at any velocity scale; a chain's are
recomputed in one O(N) pass without a matrix by :mod:`impactqp.model.chain_residuals`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..base.checks import DEFAULT_TOL, ResidualChecks
from ..model.chain_residuals import chain_law_residuals
from ..model.problem import ImpactProblem
from ..model.residuals import (
    impact_residuals,
    kinetic_norms,
    law_residuals,
    normalized_rows,
)

__all__ = ["DEFAULT_TOL", "Certificate", "ResidualChecks", "certify", "impact_residuals",
           "kinetic_norms", "law_residuals", "normalized_rows"]


@dataclass(frozen=True)
class Certificate(ResidualChecks):
    """Recomputed checks of a complementarity impact law ``0 ≤ Λ ⟂ γ⁺ + Eγ⁻ ≥ 0``
    (docs/theory.md §3).

    Attributes
    ----------
    momentum : float
        ‖u⁺ − u⁻ − M⁻¹WΛ‖ / V: the impact equation M(u⁺ − u⁻) = WΛ.
    impulse_sign : float
        Largest violation of Λ ≥ 0 (scaled).
    law_feasibility : float
        Largest violation of γ⁺ + Eγ⁻ ≥ 0 (scaled).
    complementarity : float
        max abs(Λᵢ (γ⁺ + Eγ⁻)ᵢ) / V².
    energy_balance : float or None
        For Moreau's law: abs(‖u⁺‖² − ‖z‖² − ε²‖z⊥‖²) / V² (docs/theory.md §3), else None.
    duality_gap : float or None
        For Moreau's law: (Σᵢ Λᵢ|wᵢ| + ‖u⁺ − u⁻ − M⁻¹WΛ‖²) / V² with w = γ⁺ + εγ⁻, a bound on
        the squared velocity error ‖u⁺ − u⁺_exact‖² / V² (docs/theory.md §3): with Λ* the
        exact impulses,
        ‖z̃ − z‖² = (Λ̃ − Λ*)ᵀ(γ(z̃) − γ(z)) ≤ Λ̃ᵀγ(z̃) + Λ*ᵀγ(z̃)₋, and Λ stands in for Λ* in
        the second term (exact when γ⁺ + εγ⁻ ≥ 0). Small complementarity residuals alone do
        not bound the velocities on ill-conditioned impacts (long chains, large mass
        ratios: each contact's residual is tiny, their sum is not); this does.
    tol : float
        Tolerance every residual must meet.
    """

    momentum: float
    impulse_sign: float
    law_feasibility: float
    complementarity: float
    energy_balance: float | None
    tol: float
    duality_gap: float | None = None

    @property
    def residuals(self) -> dict[str, float]:
        out = {"momentum": self.momentum, "impulse_sign": self.impulse_sign,
               "law_feasibility": self.law_feasibility, "complementarity": self.complementarity}
        if self.energy_balance is not None:
            out["energy_balance"] = self.energy_balance
        if self.duality_gap is not None:
            out["duality_gap"] = self.duality_gap
        return out

    @property
    def velocity_error_bound(self) -> float | None:
        """Bound on ‖u⁺ − u⁺_exact‖ / ‖u⁻‖ from the duality gap (Moreau's law only):
        the error is at most ‖r‖ + √(Σ Λᵢ|wᵢ|) (r the momentum residual, docs/theory.md §3),
        and (x + y)² ≤ 2(x² + y²) turns the gap into √(2 · duality_gap)."""
        return None if self.duality_gap is None else float(np.sqrt(2.0 * self.duality_gap))


def as_residual(value) -> float:
    """A residual as a float; NaN becomes +inf so that it fails every comparison."""
    v = float(value)
    return v if v == v else float("inf")


def certify(problem: ImpactProblem, u_plus: np.ndarray, impulses: np.ndarray, E,
            *, eps: float | None = None, tol: float = DEFAULT_TOL) -> Certificate:
    """Recompute the checks of ``0 ≤ Λ ⟂ γ⁺ + Eγ⁻ ≥ 0`` and ``M(u⁺ − u⁻) = WΛ``.

    Parameters
    ----------
    problem : ImpactProblem
    u_plus, impulses : ndarray
        The candidate answer.
    E : float, (m,) or (m, m) array
        Restitution: ε (Moreau), eᵢ (local Newton) or Frémond's matrix.
    eps : float, optional
        For Moreau's law, adds the energy balance of docs/theory.md §3.
    tol : float
        Tolerance of every dimensionless residual.
    """
    st = problem.structure
    if st.chain is not None and np.ndim(E) == 0:  # O(N), no matrix (docs/theory.md §5)
        raw = chain_law_residuals(st, problem.u_minus, u_plus, impulses, float(E), eps=eps)
    else:
        raw = law_residuals(st, problem.u_minus, u_plus, impulses, E, eps=eps)
    r = {k: as_residual(v) for k, v in raw.items()}
    return Certificate(momentum=r["momentum"], impulse_sign=r["impulse_sign"],
                       law_feasibility=r["law_feasibility"], complementarity=r["complementarity"],
                       energy_balance=r.get("energy_balance"), tol=tol,
                       duality_gap=r.get("duality_gap"))
