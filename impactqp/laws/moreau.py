"""Moreau's impact law with a global restitution ε (docs/theory.md §3).

u⁺ = z − εz⊥ with z = prox_{T_C}(u⁻) in the metric M; equivalently
``0 ≤ Λ ⟂ GΛ + (1+ε)γ⁻ ≥ 0``. The velocity form stays well posed for any W (redundant
contacts); the impulse form is smaller when m < n.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..base.arrays import as_real
from ..derivatives.complementarity import ComplementarityMap, scalar_times_identity
from ..errors import RestitutionError
from ..kernels.residuals import RESIDUALS
from ..model.problem import ImpactProblem
from ..model.programs import impulse_program, velocity_program
from ..model.structure import ImpactStructure
from ..qp.program import QPSolution, QuadraticProgram
from .base import MOREAU_FAMILY, Answer, ImpactLaw
from .certificate import law_residuals


def check_eps(value: Any) -> float:
    """Validate Moreau's global restitution ε ∈ [0, 1].

    Raises
    ------
    RestitutionError
        Not one real number in [0, 1] (NaN, strings, booleans, arrays included).
    """
    if type(value) is float and 0.0 <= value <= 1.0:  # the common case, without conversions
        return value
    try:
        e = as_real("eps", value)
    except ValueError as exc:
        raise RestitutionError(f"eps must be one number in [0, 1]: {exc}") from None
    if not 0.0 <= e <= 1.0:
        raise RestitutionError(f"eps must lie in [0, 1], got {value!r}")
    return e


class Moreau(ImpactLaw):
    """Moreau's law: the M-projection of u⁻ onto the tangent cone, with restitution ε.

    Parameters
    ----------
    eps : float
        Restitution ε ∈ [0, 1]; 0 dissipates the most (u⁺ = z), 1 conserves kinetic energy.

    Raises
    ------
    RestitutionError
        ε outside [0, 1] or not a number.
    """

    name = "moreau"
    title = "Moreau's law"
    forms = ("velocity", "impulse")
    always_solvable = True
    homogeneous = True
    by_name = True
    coefficient_key = "eps"
    coefficient_symbol = "ε"
    family = MOREAU_FAMILY
    restitution_per_contact = True
    residual_names = RESIDUALS

    def __init__(self, eps: float = 0.0) -> None:
        self.eps = check_eps(eps)

    @property
    def coefficients(self) -> float:
        return self.eps

    def projection(self, problem: ImpactProblem, u_plus: np.ndarray) -> np.ndarray:
        """z = (u⁺ + εu⁻)/(1 + ε) of this law's answer u⁺ (docs/theory.md §3)."""
        return (u_plus + self.eps * problem.u_minus) / (1.0 + self.eps)

    def step_restitution(self, contacts: np.ndarray) -> float:
        return self.eps

    def restitution(self, m: int) -> np.ndarray:
        """The diagonal of the law's E = εI for m contacts, an (m,) array (docs/theory.md §3)."""
        return np.full(m, self.eps)

    def program(self, problem: ImpactProblem, form: str) -> QuadraticProgram:
        if form == "velocity":
            return velocity_program(problem)
        return impulse_program(problem, (1.0 + self.eps) * problem.gamma_minus, 1.0 + self.eps)

    def recover(self, problem: ImpactProblem, form: str, solution: QPSolution) -> Answer:
        e, u_m = self.eps, problem.u_minus
        if form == "velocity":
            z = solution.x
            if e == 0.0:
                return Answer(z.copy(), solution.y, z)
            u_plus = np.subtract(z, u_m)  # u⁺ = z − εz⊥, z⊥ = u⁻ − z, in one array
            u_plus *= e
            u_plus += z
            return Answer(u_plus, (1.0 + e) * solution.y, z)
        u = u_m + problem.structure.impulse_velocity(solution.x)
        return Answer(u, solution.x, self.projection(problem, u))

    def derivative(self, problem: ImpactProblem, answer: Any, *,
                   kink_tol: float) -> ComplementarityMap:
        """The LCP's local map with E = εI, differentiable in ``"eps"`` (docs/theory.md §18):
        ∂u⁺/∂u⁻ = I − (1 + ε)P_A, ∂u⁺/∂ε = z − u⁻."""
        return ComplementarityMap.at(problem, answer.impulses,
                                     scalar_times_identity("eps", self.eps, problem.n_contacts),
                                     kink_tol=kink_tol)

    def linear_terms(self, problem: ImpactProblem, U_minus: np.ndarray,
                     form: str) -> np.ndarray:
        st = problem.structure
        if form == "velocity":
            return -st.mass_rows(U_minus)
        return (1.0 + self.eps) * st.Wt_times(U_minus)

    def recover_rows(self, problem: ImpactProblem, form: str, U_minus: np.ndarray,
                     X: np.ndarray, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        e = self.eps
        if form == "velocity":
            return (1.0 + e) * X - e * U_minus, (1.0 + e) * Y
        return U_minus + problem.structure.impulse_velocity(X), X

    def residuals(self, structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                  impulses: np.ndarray) -> dict[str, np.ndarray]:
        return law_residuals(structure, U_minus, U_plus, impulses, self.eps, eps=self.eps)

