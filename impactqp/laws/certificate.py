"""Certificates that impactqp recomputes itself for every result it returns
(docs/theory.md §8).

Every certificate is one :class:`impactqp.base.checks.Certificate`; a law declares the
residuals it checks in its ``residual_names``. All residuals are dimensionless, measured
in the problem's own units: velocities against V = ‖u⁻‖ (the kinetic norm), the velocity
of contact i against sᵢV with sᵢ = sqrt(Gᵢᵢ) (|γᵢ| ≤ sᵢ‖u‖ by Cauchy–Schwarz in M),
impulse Λᵢ against V/sᵢ (the impulse that changes the velocity by V along contact i),
energies against V². The computations live in :mod:`impactqp.model.residuals` over the one
definition of :mod:`impactqp.kernels.residuals`, safe at any velocity scale; a chain's are
recomputed in one O(N) pass without a matrix.

The residuals of the impact laws:

- momentum: ‖u⁺ − u⁻ − M⁻¹WΛ‖ / V, the impact equation M(u⁺ − u⁻) = WΛ;
- impulse_sign: the largest violation of Λ ≥ 0;
- law_feasibility, complementarity: of ``0 ≤ Λ ⟂ γ⁺ + Eγ⁻ ≥ 0`` (Moreau, Newton, Frémond);
- energy_balance: Moreau's abs(‖u⁺‖² − ‖z‖² − ε²‖z⊥‖²) / V² (docs/theory.md §3), or the
  energy conservation abs(‖u⁺‖² − ‖u⁻‖²) / V² of the sector and reflection laws;
- duality_gap (Moreau): (Σᵢ Λᵢ abs(wᵢ) + momentum² V²) / V², a bound on the squared
  velocity error (:attr:`Certificate.velocity_error_bound`);
- kinematic, law_residual (sector and reflection laws): γ⁺ ≥ 0, and γ⁺ against an
  independent evaluation of the law;
- natural_map, cone, non_penetration (Coulomb's law, docs/theory.md §16).
"""

from __future__ import annotations

import numpy as np

from ..base.checks import DEFAULT_TOL, Certificate, ResidualChecks, as_residual
from ..kernels.residuals import RESIDUALS
from ..model.problem import ImpactProblem
from ..model.residuals import (
    impact_residuals,
    kinetic_norms,
    law_residuals,
    normalized_rows,
)

__all__ = ["DEFAULT_TOL", "Certificate", "ResidualChecks", "SectorLawCertificate",
           "as_residual", "certify", "impact_residuals", "kinetic_norms", "law_residuals",
           "normalized_rows"]


SectorLawCertificate = Certificate
"""The certificate of the sector and reflection laws: a :class:`Certificate` (the name is
kept for code written before the certificates became one type)."""


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
        For Moreau's law, adds the energy balance of docs/theory.md §3 and the duality gap.
    tol : float
        Tolerance of every dimensionless residual.
    """
    return Certificate(law_residuals(problem.structure, problem.u_minus, u_plus, impulses, E,
                                     eps=eps), tol, names=RESIDUALS)
