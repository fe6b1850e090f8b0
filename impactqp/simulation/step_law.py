"""The impact law of one Moreau–Jean step (docs/theory.md §14):

    0 ≤ Λ ⟂ γ_{k+1} + E γ_k ≥ 0,    γ = Wᵀv,    u⁻ = v_free,    u⁺ = v_{k+1} = v_free + M⁻¹WΛ,

Newton's law at velocity level as Moreau–Jean time-stepping (and Siconos) writes it: the
restitution multiplies the contact velocity of the previous step, not the pre-impact one,
so the step is not :class:`~impactqp.laws.complementarity.Newton` applied to v_free. It is
solved and certified through :func:`impactqp.solve` like every other law.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..base.arrays import as_array
from ..base.rowwise import row_max, row_min
from ..errors import ShapeError
from ..kernels.step import step_q
from ..laws.base import Answer, ImpactLaw
from ..model.problem import ImpactProblem
from ..model.programs import impulse_program, velocity_program
from ..model.residuals import impact_residuals, normalized_rows
from ..model.structure import ChainInfo, ImpactStructure
from ..qp.program import QPSolution, QuadraticProgram

_NO_MATRIX = np.zeros((0, 0))
"""The restitution matrix argument of :func:`impactqp.kernels.step.step_q` for one
coefficient per contact."""


class _Shifted(NamedTuple):
    """What :func:`velocity_program` reads from a problem, with another u⁻."""

    structure: ImpactStructure
    u_minus: np.ndarray
    chain: ChainInfo | None


class MoreauJeanStep(ImpactLaw):
    """``0 ≤ Λ ⟂ Wᵀu⁺ + E Wᵀv_k ≥ 0`` on the impact problem (M, W, u⁻ = v_free).

    Parameters
    ----------
    E : float, (m,) or (m, m) array_like
        Restitution: ε for all contacts (Moreau), eᵢ per contact (Newton) or Frémond's matrix.
    v_previous : (n,) array_like
        v_k, the velocity at the start of the step, on the problem's degrees of freedom.

    Notes
    -----
    Impulse form: the LCP with q = Wᵀv_free + E Wᵀv_k. For one coefficient e the step is
    also a projection: with ũ = v_free + e v_k, q = Wᵀũ, so z = prox_{T_C}(ũ) in the metric M
    and u⁺ = z − e v_k (velocity form, the O(N) isotonic path on chains).
    """

    name = "moreau-jean"
    title = "the Moreau–Jean step law"

    def __init__(self, E: Any, v_previous: np.ndarray) -> None:
        self.E = as_array("E", E)
        if self.E.ndim > 2:
            raise ShapeError(f"E must be a scalar, a vector or a matrix, got shape {self.E.shape}")
        self.v_previous = as_array("v_previous", v_previous, ndim=1)
        self.forms = ("velocity", "impulse") if self.E.ndim == 0 else ("impulse",)

    def step_q(self, gamma_free: np.ndarray, gamma_previous: np.ndarray,
               ) -> tuple[np.ndarray, bool]:
        """(q, some qᵢ < 0): the step's q = γ(v_free) + Eγ_k of
        :func:`impactqp.kernels.step.step_q` from γ(v_free) = Wᵀv_free and γ_k = Wᵀv_k on
        this problem's contacts."""
        m = gamma_free.size
        if self.E.ndim == 2:
            e, E = np.zeros(0), np.ascontiguousarray(self.E, dtype=float)
        else:
            e, E = np.ascontiguousarray(np.broadcast_to(self.E, (m,)), dtype=float), _NO_MATRIX
        q = np.empty(m)
        approaching = step_q(np.ascontiguousarray(gamma_free, dtype=float),
                             np.ascontiguousarray(gamma_previous, dtype=float), e, E,
                             np.arange(m), 1, q)
        return q, bool(approaching)

    def approaching(self, gamma_free: np.ndarray, gamma_previous: np.ndarray) -> bool:
        """Some contact's step q is negative: Λ = 0 does not solve the step."""
        return self.step_q(gamma_free, gamma_previous)[1]

    @property
    def coefficients(self) -> float | np.ndarray:
        return float(self.E) if self.E.ndim == 0 else self.E

    def _restitution(self, gamma: np.ndarray) -> np.ndarray:
        """E γ for one γ or rows of γ."""
        return gamma @ self.E.T if self.E.ndim == 2 else self.E * gamma

    def program(self, problem: ImpactProblem, form: str) -> QuadraticProgram:
        st = problem.structure
        if form == "velocity":
            shifted = problem.u_minus + float(self.E) * self.v_previous
            return velocity_program(_Shifted(st, shifted, problem.chain))
        q, _ = self.step_q(problem.gamma_minus, st.Wt_times(self.v_previous))
        return impulse_program(problem, q)

    def recover(self, problem: ImpactProblem, form: str, solution: QPSolution) -> Answer:
        if form == "velocity":
            return Answer(solution.x - float(self.E) * self.v_previous, solution.y)
        lam = solution.x
        return Answer(problem.u_minus + problem.structure.impulse_velocity(lam), lam)

    def residuals(self, structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                  impulses: np.ndarray) -> dict[str, np.ndarray]:
        """Momentum, Λ ≥ 0, and the law's feasibility and complementarity with
        w = γ⁺ + Eγ_k, in the units of docs/theory.md §8."""
        U_minus, U_plus, Lam, V_prev = normalized_rows(U_minus, U_plus, impulses,
                                                       self.v_previous)
        V, out = impact_residuals(structure, U_minus, U_plus, Lam)
        s = structure.contact_scale
        w = structure.Wt_times(U_plus) + self._restitution(structure.Wt_times(V_prev))
        out["law_feasibility"] = np.maximum(0.0, -row_min(w / (s * V[..., None])))
        out["complementarity"] = row_max(np.abs(Lam * w)) / V**2
        return out

