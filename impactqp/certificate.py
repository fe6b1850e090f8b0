"""Certificates that impactqp recomputes itself for every result it returns.

All residuals are dimensionless, measured in the problem's own units (§1): velocities
against V = ‖u⁻‖ (the kinetic norm), the velocity of contact i against sᵢV with
sᵢ = sqrt(Gᵢᵢ) (|γᵢ| ≤ sᵢ‖u‖ by Cauchy–Schwarz in M), impulse Λᵢ against V/sᵢ (the
impulse that changes the velocity by V along contact i), energies against V².
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .problem import ImpactProblem, ImpactStructure

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


def _rows_norm(M, X: np.ndarray) -> np.ndarray:
    """Kinetic norms of the rows of X."""
    return np.sqrt(np.maximum(np.einsum("ij,ij->i", np.asarray((M @ X.T).T), X), 0.0))


def law_residuals(structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                  Lam: np.ndarray, E, *, eps: float | None = None) -> dict[str, np.ndarray]:
    """Residuals of the certificate for k impacts at once (rows of the (k, ·) arrays).

    Returns a dict of (k,) arrays with the keys of :attr:`Certificate.residuals`.
    """
    st = structure
    V = _rows_norm(st.M, U_minus)
    V[V == 0] = 1.0
    du = U_plus - U_minus - np.asarray(st.Minv_W @ Lam.T).T
    out = {"momentum": _rows_norm(st.M, du) / V}
    if st.m:
        s = np.sqrt(st.delassus_diagonal)
        g_minus = np.asarray(st.W.T @ U_minus.T).T
        E = np.asarray(E, dtype=float)
        w = np.asarray(st.W.T @ U_plus.T).T + (E * g_minus if E.ndim <= 1 else g_minus @ E.T)
        out["impulse_sign"] = np.maximum(0.0, -(Lam * s / V[:, None]).min(axis=1))
        out["law_feasibility"] = np.maximum(0.0, -(w / (s * V[:, None])).min(axis=1))
        out["complementarity"] = np.abs(Lam * w).max(axis=1) / V**2
    else:
        zero = np.zeros(U_minus.shape[0])
        out.update(impulse_sign=zero, law_feasibility=zero, complementarity=zero)
    if eps is not None:
        z = (U_plus + eps * U_minus) / (1.0 + eps)
        out["energy_balance"] = np.abs(_rows_norm(st.M, U_plus) ** 2 - _rows_norm(st.M, z) ** 2
                                       - eps**2 * _rows_norm(st.M, U_minus - z) ** 2) / V**2
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
    res = law_residuals(problem.structure, problem.u_minus[None, :], u_plus[None, :],
                        impulses[None, :], E, eps=eps)
    r = {k: float(v[0]) for k, v in res.items()}
    return Certificate(momentum=r["momentum"], impulse_sign=r["impulse_sign"],
                       law_feasibility=r["law_feasibility"], complementarity=r["complementarity"],
                       energy_balance=r.get("energy_balance"), tol=tol)
