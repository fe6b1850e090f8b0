"""Residuals of an answer (u⁺, Λ) to an impact, one impact or rows of impacts
(docs/theory.md §8): the computations behind every certificate, in dimensionless units.

Velocities are measured against V = ‖u⁻‖ (kinetic norm), the velocity of contact i against
sᵢV with sᵢ = sqrt(Gᵢᵢ), impulses Λᵢ against V/sᵢ, energies against V². Every row is first
divided by the largest entry of its u⁻, so no square overflows or underflows at any velocity
scale; u⁻ = 0 is measured against the answer's own size (any non-zero u⁺ then fails).
"""

from __future__ import annotations

import numpy as np

from ..base.rowwise import row_max, row_min, row_sum
from .structure import ImpactStructure


def kinetic_norms(structure: ImpactStructure, X: np.ndarray) -> np.ndarray:
    """‖x‖ = sqrt(xᵀMx) of a vector or of every row of X (no overflow or underflow)."""
    return structure.kinetic_norms(X)


def normalized_rows(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """Divide (u⁻, u⁺, Λ, …), one impact or rows, by the largest entry of each row of u⁻ (the
    first array); where u⁻ = 0, by the largest entry of the others (1 when all are 0).
    The residuals of docs/theory.md §8 are invariant under this scaling, so rows whose
    scale is between 1e-60 and 1e60 are left as they are."""
    first = arrays[0]
    c = row_max(np.abs(first))
    if np.all((c > 1e-60) & (c < 1e60)):  # squares in range: the units need no change
        return arrays
    if np.any(c == 0):
        rest = np.max([row_max(np.abs(a)) if a.shape[-1] else np.zeros(first.shape[:-1])
                       for a in arrays[1:]], axis=0)
        c = np.where(c == 0, np.where(rest > 0, rest, 1.0), c)
    c = c[..., None] if first.ndim == 2 else c
    with np.errstate(over="ignore", invalid="ignore"):
        return tuple(a / c for a in arrays)


def impact_residuals(structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                     Lam: np.ndarray) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Velocity scale V and the residuals every impact law shares (one impact or rows):
    the impact equation M(u⁺ − u⁻) = WΛ (docs/theory.md §1) and Λ ≥ 0. The arrays must
    already be normalized (:func:`normalized_rows`)."""
    st = structure
    V = kinetic_norms(st, U_minus)
    if np.any(V == 0):  # u⁻ = 0: measure against the answer (normalized to unit entries)
        V = np.where(V == 0, np.maximum(kinetic_norms(st, U_plus), 1.0), V)
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
    ‖u⁺‖² − ‖z‖² − ε²‖z⊥‖² equals −2ε⟨z, z⊥⟩ (docs/theory.md §3), which is what is evaluated.
    """
    st = structure
    U_minus, U_plus, Lam = normalized_rows(U_minus, U_plus, Lam)
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
