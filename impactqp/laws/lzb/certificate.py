"""The certificate of the LZB model (docs/theory.md §8, §13): the impact equation, Λ ≥ 0,
the end state of the integration (every contact separating or at rest, no compression left)
and its energy balance, recomputed from u⁻, u⁺, Λ and the integration's record."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...base.checks import ResidualChecks
from ...model.residuals import impact_residuals, kinetic_norms, normalized_rows
from ...model.structure import ImpactStructure
from .integration import LZBRecord


@dataclass(frozen=True)
class LZBCertificate(ResidualChecks):
    """Recomputed checks of one LZB result (docs/theory.md §8, §13), dimensionless.

    Attributes
    ----------
    momentum : float
        ‖u⁺ − u⁻ − M⁻¹WΛ‖ / V: the impact equation.
    impulse_sign : float
        Largest violation of Λ ≥ 0 (scaled).
    kinematic : float
        Largest violation of γ⁺ = Wᵀu⁺ ≥ 0 (scaled): every contact separates or rests.
    energy_balance : float
        The size of ‖u⁺‖² + 2ΣEᵢ + 2ΣDᵢ − ‖u⁻‖² over V²: kinetic energy after, plus the
        potential energy Eᵢ left in the contacts, plus the energy Dᵢ dissipated by
        restitution, equals the kinetic energy before, to the integration's accuracy.
    potential_left : float
        2ΣEᵢ / V²: the integration ended with no compression left.
    tol : float
        Tolerance every residual must meet.
    record : LZBRecord or None
        The integration (primary switches, steps, energies); None when nothing was integrated.
    """

    momentum: float
    impulse_sign: float
    kinematic: float
    energy_balance: float
    potential_left: float
    tol: float
    record: LZBRecord | None = field(default=None, repr=False, compare=False)

    @property
    def residuals(self) -> dict[str, float]:
        return {"momentum": self.momentum, "impulse_sign": self.impulse_sign,
                "kinematic": self.kinematic, "energy_balance": self.energy_balance,
                "potential_left": self.potential_left}


def lzb_residuals(structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                  Lam: np.ndarray, *, stored: np.ndarray | float = 0.0,
                  elastic: bool = True) -> dict[str, np.ndarray]:
    """Residuals of :class:`LZBCertificate` for one impact or rows of impacts.

    Parameters
    ----------
    structure : ImpactStructure
        M and W.
    U_minus, U_plus, Lam : ndarray
        u⁻, u⁺ and Λ of one impact (1-D) or of k impacts (rows).
    stored : float or (k,) ndarray
        Energy the integration left in the contacts plus what it dissipated (physical
        units). Without it (batches) the balance is checked as conservation when
        ``elastic`` and as "no energy gained" otherwise.
    elastic : bool
        Every contact has eᵢ = 1.

    Returns
    -------
    dict
        ``momentum``, ``impulse_sign``, ``energy_balance``, ``kinematic`` and
        ``potential_left`` (zero here; :meth:`LZB.certificate` fills it from the record),
        floats for one impact or (k,) arrays.
    """
    st = structure
    U_minus, U_plus, Lam, scale = normalized_rows(U_minus, U_plus, Lam,
                                                  np.ones(U_minus.shape[:-1] + (1,)))
    V, out = impact_residuals(st, U_minus, U_plus, Lam)
    c = scale[..., 0]  # the factor normalized_rows divided by
    stored = np.asarray(stored, dtype=float) * c**2
    gain = kinetic_norms(st, U_plus) ** 2 + 2.0 * stored - kinetic_norms(st, U_minus) ** 2
    out["energy_balance"] = (np.abs(gain) if elastic else np.maximum(gain, 0.0)) / V**2
    if st.m:
        gamma = st.Wt_times(U_plus)
        out["kinematic"] = 0.0 + np.maximum(0.0, -np.min(gamma / (st.contact_scale
                                                                  * V[..., None]), axis=-1))
    else:
        out["kinematic"] = np.zeros(U_minus.shape[:-1])
    out["potential_left"] = np.zeros(U_minus.shape[:-1])
    return out
