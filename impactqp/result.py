"""The result of one impact law on one impact problem."""

from __future__ import annotations

from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from .certificate import Certificate
from .problem import ImpactProblem

if TYPE_CHECKING:
    from .admissible import Membership
    from .classify import Classification


class ImpactResult:
    """Post-impact state computed by a law, with its recomputed certificate.

    A result is only returned when ``certificate.ok``; physical admissibility (u⁺ ∈ S) is a
    separate verdict in :attr:`admissible`, which a law may legitimately fail.

    Attributes
    ----------
    problem : ImpactProblem
    law : str
        ``"moreau"``, ``"newton"``, ``"fremond"`` or ``"sector"``.
    coefficients : float or ndarray
        ε, the eᵢ, or Frémond's matrix E.
    u_plus : (n,) ndarray
        Post-impact velocity.
    impulses : (m,) ndarray
        Impulsive contact forces Λ ≥ 0 with M(u⁺ − u⁻) = WΛ.
    backend : str
        What produced the numbers (e.g. ``"nnls"``, ``"clarabel"``, ``"exact"``).
    certificate : Certificate
        Recomputed residuals of the law that was solved.
    """

    def __init__(self, problem: ImpactProblem, law: str, coefficients, u_plus: np.ndarray,
                 impulses: np.ndarray, backend: str, certificate: Certificate, *,
                 form: str | None = None, z: np.ndarray | None = None,
                 attempts: list[str] | None = None) -> None:
        self.problem = problem
        self.law = law
        self.coefficients = coefficients
        self.u_plus = u_plus
        self.impulses = impulses
        self.backend = backend
        self.certificate = certificate
        self.form = form
        self.attempts = attempts or []
        self._z = z

    success = True
    status = "solved"

    @cached_property
    def gamma_plus(self) -> np.ndarray:
        """Post-impact contact velocities γ⁺ = Wᵀu⁺."""
        return self.problem.structure.Wt_times(self.u_plus)

    @property
    def z(self) -> np.ndarray:
        """z = prox_{T_C}(u⁻), the least-energy point of S (§3)."""
        return self._z if self._z is not None else self.problem.moreau_split[0]

    @property
    def z_perp(self) -> np.ndarray:
        """z⊥ = u⁻ − z (in −N)."""
        return self.problem.u_minus - self.z

    @property
    def energy_before(self) -> float:
        return self.problem.kinetic_energy()

    @property
    def energy_after(self) -> float:
        return self.problem.kinetic_energy(self.u_plus)

    @cached_property
    def admissible(self) -> Membership:
        """Whether u⁺ ∈ S (exact test, §2), with its residuals."""
        return self.problem.admissible_set().contains(self.u_plus)

    @cached_property
    def classification(self) -> Classification:
        """Intensity, topology, angle α and dissipation of u⁺ (§4)."""
        from .classify import classify

        return classify(self.problem, self.u_plus)

    def __repr__(self) -> str:
        return (f"ImpactResult(law={self.law!r}, backend={self.backend!r}, "
                f"u_plus={np.array2string(self.u_plus, precision=6)}, "
                f"certificate={self.certificate.summary()})")
