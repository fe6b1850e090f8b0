"""Certificates that impactqp recomputes itself for every result it returns.

All residuals are dimensionless, measured in the problem's own units (§1): velocities
against V = ‖u⁻‖ (the kinetic norm), the velocity of contact i against sᵢV with
sᵢ = sqrt(Gᵢᵢ) (|γᵢ| ≤ sᵢ‖u‖ by Cauchy–Schwarz in M), impulse Λᵢ against V/sᵢ (the
impulse that changes the velocity by V along contact i), energies against V².
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from .problem import ImpactProblem, ImpactStructure
from .rowwise import row_max, row_min, row_sum

DEFAULT_TOL = 1e-9


class ResidualChecks(ABC):
    """Verdict shared by every certificate: each residual in :attr:`residuals` ≤ ``tol``."""

    tol: float

    @property
    @abstractmethod
    def residuals(self) -> dict[str, float]:
        """The named dimensionless residuals of this certificate."""

    @property
    def ok(self) -> bool:
        """True when every residual is within ``tol``."""
        return all(v <= self.tol for v in self.residuals.values())  # NaN fails too

    @property
    def worst(self) -> tuple[str, float]:
        """The largest residual and its name."""
        res = self.residuals
        name = max(res, key=lambda k: res[k])
        return name, res[name]

    def __bool__(self) -> bool:
        return self.ok

    def summary(self) -> str:
        parts = ", ".join(f"{k}={v:.1e}" for k, v in self.residuals.items())
        return f"{'ok' if self.ok else 'FAILED'} (tol {self.tol:.0e}): {parts}"


@dataclass(frozen=True)
class Certificate(ResidualChecks):
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
    duality_gap : float or None
        For Moreau's law: (Σᵢ Λᵢ|wᵢ| + ‖u⁺ − u⁻ − M⁻¹WΛ‖²) / V² with w = γ⁺ + εγ⁻, a bound on
        the squared velocity error ‖u⁺ − u⁺_exact‖² / V² (§3): with Λ* the exact impulses,
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
        """Bound on ‖u⁺ − u⁺_exact‖ / ‖u⁻‖ from the duality gap (Moreau's law only)."""
        return None if self.duality_gap is None else float(np.sqrt(self.duality_gap))


def kinetic_norms(structure: ImpactStructure, X: np.ndarray) -> np.ndarray:
    """‖x‖ = sqrt(xᵀMx) of a vector or of every row of X."""
    return np.sqrt(np.maximum(row_sum(structure.mass_rows(X) * X), 0.0))


def impact_residuals(structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                     Lam: np.ndarray) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Velocity scale V and the residuals every impact law shares (one impact or rows):
    the impact equation M(u⁺ − u⁻) = WΛ (§1) and Λ ≥ 0."""
    st = structure
    V = kinetic_norms(st, U_minus)
    V = np.where(V == 0, 1.0, V)
    du = U_plus - U_minus - st.impulse_velocity(Lam)
    out = {"momentum": kinetic_norms(st, du) / V}
    if st.m:
        out["impulse_sign"] = 0.0 + np.maximum(0.0, -row_min(Lam * st.contact_scale
                                                             / V[..., None]))
    else:
        out["impulse_sign"] = np.zeros(U_minus.shape[:-1])
    return V, out


def law_residuals(structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                  Lam: np.ndarray, E, *, eps: float | None = None) -> dict[str, np.ndarray]:
    """Residuals of the certificate for one impact (1-D arrays) or k impacts (rows).

    Returns a dict with the keys of :attr:`Certificate.residuals`: floats for one impact,
    (k,) arrays for k. For Moreau's law, with u⁺ = z − εz⊥ the energy balance
    ‖u⁺‖² − ‖z‖² − ε²‖z⊥‖² equals −2ε⟨z, z⊥⟩ (§3), which is what is evaluated.
    """
    st = structure
    V, out = impact_residuals(st, U_minus, U_plus, Lam)
    gap = np.zeros(U_minus.shape[:-1])
    if st.m:
        s = st.contact_scale
        g_minus = st.Wt_times(U_minus)
        E = np.asarray(E, dtype=float)
        w = st.Wt_times(U_plus) + (E * g_minus if E.ndim <= 1 else g_minus @ E.T)
        out["law_feasibility"] = np.maximum(0.0, -row_min(w / (s * V[..., None])))
        out["complementarity"] = row_max(np.abs(Lam * w)) / V**2
        gap = row_sum(np.abs(Lam * w)) / V**2
    else:
        out["law_feasibility"] = out["complementarity"] = np.zeros(U_minus.shape[:-1])
    if eps is not None:
        z = (U_plus + eps * U_minus) / (1.0 + eps)
        out["energy_balance"] = 2.0 * eps * np.abs(row_sum(st.mass_rows(z) * (U_minus - z))) / V**2
        out["duality_gap"] = gap + out["momentum"] ** 2
    return out


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
    r = {k: float(v) for k, v in law_residuals(problem.structure, problem.u_minus, u_plus,
                                                impulses, E, eps=eps).items()}
    return Certificate(momentum=r["momentum"], impulse_sign=r["impulse_sign"],
                       law_feasibility=r["law_feasibility"], complementarity=r["complementarity"],
                       energy_balance=r.get("energy_balance"), tol=tol,
                       duality_gap=r.get("duality_gap"))
