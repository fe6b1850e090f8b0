"""Certificates that impactqp recomputes itself for every result it returns
(docs/theory.md §8).

All residuals are dimensionless, measured in the problem's own units: velocities
against V = ‖u⁻‖ (the kinetic norm), the velocity of contact i against sᵢV with
sᵢ = sqrt(Gᵢᵢ) (|γᵢ| ≤ sᵢ‖u‖ by Cauchy–Schwarz in M), impulse Λᵢ against V/sᵢ (the
impulse that changes the velocity by V along contact i), energies against V². The
computations live in
:mod:`impactqp.model.residuals` over the one definition of :mod:`impactqp.kernels.residuals`,
safe at any velocity scale; a chain's are recomputed in one O(N) pass without a matrix.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..base.checks import DEFAULT_TOL, ResidualChecks
from ..model.problem import ImpactProblem
from ..model.residuals import (
    impact_residuals,
    kinetic_norms,
    law_residuals,
    normalized_rows,
)

__all__ = ["DEFAULT_TOL", "RESIDUAL_NAMES", "Certificate", "ResidualChecks",
           "SectorLawCertificate", "as_residual", "certify", "impact_residuals", "kinetic_norms",
           "law_residuals", "normalized_rows"]


RESIDUAL_NAMES = ("momentum", "impulse_sign", "law_feasibility", "complementarity",
                  "energy_balance", "duality_gap", "kinematic", "law_residual",
                  "natural_map", "cone", "non_penetration")
"""Residuals a certificate may carry, readable as attributes (None when a law has not got
one): the complementarity laws' six of :mod:`impactqp.kernels.residuals`, γ⁺ ≥ 0 and the
agreement with a closed form (``kinematic``, ``law_residual``) of the sector and reflection
laws, and the friction checks of Coulomb's law (``natural_map``, ``cone``,
``non_penetration``, docs/theory.md §16)."""


@dataclass(frozen=True)
class Certificate(ResidualChecks):
    """The recomputed residuals of one answer of an impact law (docs/theory.md §8).

    Every law's certificate is one of these, built by :meth:`ImpactLaw.certificate` from the
    law's :meth:`~impactqp.ImpactLaw.residuals`. The residuals are dimensionless, measured in
    the problem's own units: velocities against V = ‖u⁻‖ (the kinetic norm), the velocity of
    contact i against sᵢV with sᵢ = √Gᵢᵢ, impulse Λᵢ against V/sᵢ, energies against V².
    Each is readable as an attribute (``cert.momentum``; None for a residual the law does
    not have):

    - momentum: ‖u⁺ − u⁻ − M⁻¹WΛ‖ / V, the impact equation M(u⁺ − u⁻) = WΛ;
    - impulse_sign: the largest violation of Λ ≥ 0;
    - law_feasibility, complementarity: of ``0 ≤ Λ ⟂ γ⁺ + Eγ⁻ ≥ 0`` (Moreau, Newton,
      Frémond);
    - energy_balance: Moreau's abs(‖u⁺‖² − ‖z‖² − ε²‖z⊥‖²) / V² (docs/theory.md §3), or
      the energy conservation abs(‖u⁺‖² − ‖u⁻‖²) / V² of the sector and reflection laws;
    - duality_gap (Moreau): (Σᵢ Λᵢ abs(wᵢ) + momentum² V²) / V², a bound on the squared velocity
      error (see :attr:`velocity_error_bound`); small complementarity residuals alone do
      not bound the velocities of ill-conditioned impacts, this does;
    - kinematic, law_residual (sector and reflection laws): γ⁺ ≥ 0, and γ⁺ against an
      independent evaluation of the law;
    - natural_map, cone, non_penetration (Coulomb's law, docs/theory.md §16): the
      natural-map error of the local problem recomputed from Λ, Λ in the friction cones,
      and the Newton-shifted normal velocities of u⁺ ≥ 0, each against ‖q‖.

    Parameters
    ----------
    values : mapping of str to float
        The residuals by name (NaN is stored as +inf, so it fails).
    tol : float
        Tolerance every residual must meet.
    extras : mapping, optional
        What a law reports beside its residuals (e.g. an integration's record).
    """

    values: Mapping[str, float]
    tol: float
    extras: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "values", {k: as_residual(v) for k, v in self.values.items()})

    def __getattr__(self, name: str) -> Any:
        if name in RESIDUAL_NAMES:
            return self.__dict__["values"].get(name)
        extras = self.__dict__.get("extras", {})
        if name in extras:
            return extras[name]
        raise AttributeError(f"{type(self).__name__} has no attribute {name!r}")

    @property
    def residuals(self) -> dict[str, float]:
        return dict(self.values)

    @property
    def velocity_error_bound(self) -> float | None:
        """Bound on ‖u⁺ − u⁺_exact‖ / ‖u⁻‖ from the duality gap (Moreau's law only):
        the error is at most ‖r‖ + √(Σ Λᵢ|wᵢ|) (r the momentum residual, docs/theory.md §3),
        and (x + y)² ≤ 2(x² + y²) turns the gap into √(2 · duality_gap)."""
        gap = self.values.get("duality_gap")
        return None if gap is None else float(np.sqrt(2.0 * gap))


SectorLawCertificate = Certificate
"""The certificate of the sector and reflection laws: a :class:`Certificate` (the name is
kept for code written before the certificates became one type)."""


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
        For Moreau's law, adds the energy balance of docs/theory.md §3 and the duality gap.
    tol : float
        Tolerance of every dimensionless residual.
    """
    return Certificate(law_residuals(problem.structure, problem.u_minus, u_plus, impulses, E,
                                     eps=eps), tol)
