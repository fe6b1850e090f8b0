"""Certificates that impactqp recomputes itself for every result it returns.

All residuals are dimensionless, measured in the problem's own units (§1): velocities
against V = ‖u⁻‖ (the kinetic norm), the velocity of contact i against sᵢV with
sᵢ = sqrt(Gᵢᵢ) (|γᵢ| ≤ sᵢ‖u‖ by Cauchy–Schwarz in M), impulse Λᵢ against V/sᵢ (the
impulse that changes the velocity by V along contact i), energies against V².
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .problem import ImpactProblem

DEFAULT_TOL = 1e-9


@dataclass(frozen=True)
class Certificate:
    """Recomputed checks of a complementarity impact law ``0 ≤ Λ ⟂ γ⁺ + Eγ⁻ ≥ 0`` (§3).

    Attributes
    ----------
    momentum : float
        ‖u⁺ − u⁻ − M⁻¹WΛ‖ / V: the impact equation M(u⁺ − u⁻) = WΛ.
    impulse_sign : float
        Largest violation of Λ ≥ 0 (scaled).
    law_feasibility : float
        Largest violation of γ⁺ + Eγ⁻ ≥ 0 (scaled).
    complementarity : float
        max |Λᵢ (γ⁺ + Eγ⁻)ᵢ| / V².
    energy_balance : float or None
        For Moreau's law: |‖u⁺‖² − ‖z‖² − ε²‖z⊥‖²| / V² (§3), else None.
    tol : float
        Tolerance every residual must meet.
    """

    momentum: float
    impulse_sign: float
    law_feasibility: float
    complementarity: float
    energy_balance: float | None
    tol: float
    details: dict = field(default_factory=dict, compare=False)

    @property
    def residuals(self) -> dict[str, float]:
        out = {"momentum": self.momentum, "impulse_sign": self.impulse_sign,
               "law_feasibility": self.law_feasibility, "complementarity": self.complementarity}
        if self.energy_balance is not None:
            out["energy_balance"] = self.energy_balance
        return out

    @property
    def ok(self) -> bool:
        """True when every residual is within ``tol``."""
        return all(np.isfinite(v) and v <= self.tol for v in self.residuals.values())

    @property
    def worst(self) -> tuple[str, float]:
        name = max(self.residuals, key=lambda k: self.residuals[k])
        return name, self.residuals[name]

    def __bool__(self) -> bool:
        return self.ok

    def summary(self) -> str:
        parts = ", ".join(f"{k}={v:.1e}" for k, v in self.residuals.items())
        return f"{'ok' if self.ok else 'FAILED'} (tol {self.tol:.0e}): {parts}"


def law_rhs(problem: ImpactProblem, E: np.ndarray) -> np.ndarray:
    """Eγ⁻ for E given as a scalar, a vector (diagonal) or a matrix."""
    g = problem.gamma_minus
    E = np.asarray(E, dtype=float)
    return E * g if E.ndim <= 1 else E @ g


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
        For Moreau's law, adds the energy balance of §3.
    tol : float
        Tolerance of every dimensionless residual.
    """
    st = problem.structure
    V = problem.velocity_scale
    s = np.sqrt(st.delassus_diagonal) if st.m else np.zeros(0)
    du = u_plus - problem.u_minus - st.solve_mass(st.W_times(impulses))
    momentum = problem.norm(du) / V
    w = st.Wt_times(u_plus) + law_rhs(problem, E)
    impulse_sign = float(max(0.0, -np.min(impulses * s / V, initial=0.0)))
    law_feas = float(max(0.0, -np.min(w / (s * V), initial=0.0)))
    compl = float(np.max(np.abs(impulses * w), initial=0.0) / V**2)
    balance = None
    if eps is not None:
        z = (u_plus + eps * problem.u_minus) / (1.0 + eps)
        zp = problem.u_minus - z
        lhs = problem.norm(u_plus) ** 2
        balance = abs(lhs - problem.norm(z) ** 2 - eps**2 * problem.norm(zp) ** 2) / V**2
    return Certificate(momentum=momentum, impulse_sign=impulse_sign, law_feasibility=law_feas,
                       complementarity=compl, energy_balance=balance, tol=tol)
