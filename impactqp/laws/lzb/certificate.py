"""The certificate of the LZB model (docs/theory.md §8, §13): the impact equation, Λ ≥ 0,
the end state of the integration (every contact separating or at rest, no compression left)
and its energy balance, recomputed from u⁻, u⁺, Λ and the integration's record."""

from __future__ import annotations

import math
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
        Tolerance of the momentum and impulse-sign residuals (they hold to rounding).
    integration_tol : float
        Tolerance of the residuals the integration's accuracy decides (energy_balance,
        kinematic, potential_left): ``tol``, or more where the integration's own error
        estimate is larger (:func:`!integration_tolerance`, docs/theory.md §13).
    record : LZBRecord or None
        The integration (primary switches, steps, energies); None when nothing was integrated.
    """

    momentum: float
    impulse_sign: float
    kinematic: float
    energy_balance: float
    potential_left: float
    tol: float
    integration_tol: float
    record: LZBRecord | None = field(default=None, repr=False, compare=False)

    @property
    def ok(self) -> bool:
        """Every residual finite and within its tolerance."""
        res = self.residuals
        exact = ("momentum", "impulse_sign")
        return all(math.isfinite(v) and v <= (self.tol if k in exact else self.integration_tol)
                   for k, v in res.items())

    def summary(self) -> str:
        """One line: the verdict, both tolerances and every residual."""
        parts = ", ".join(f"{k}={v:.1e}" for k, v in self.residuals.items())
        return (f"{'ok' if self.ok else 'FAILED'} (tol {self.tol:.0e}, integration "
                f"{self.integration_tol:.0e}): {parts}")

    @property
    def residuals(self) -> dict[str, float]:
        return {"momentum": self.momentum, "impulse_sign": self.impulse_sign,
                "kinematic": self.kinematic, "energy_balance": self.energy_balance,
                "potential_left": self.potential_left}


ERROR_FACTOR = 10.0
"""How many times the integration's summed local error estimate the residuals it decides
may reach (docs/theory.md §13)."""


def integration_tolerance(tol: float, record: LZBRecord) -> float:
    """The tolerance of the residuals an integration decides: ``tol``, or ERROR_FACTOR times
    the integration's own error estimate (:attr:`LZBRecord.error_estimate`, summed over its
    steps) when that is larger: a fixed step or a loose ``rtol`` is held to the accuracy it
    can reach, never to less than ``tol``."""
    return max(tol, ERROR_FACTOR * record.error_estimate)


def lzb_residuals(structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                  Lam: np.ndarray, *, stored: np.ndarray | float = 0.0,
                  left: np.ndarray | float = 0.0, energy_unit: tuple = (1.0, 1.0),
                  elastic: bool = True) -> dict[str, np.ndarray]:
    """Residuals of :class:`LZBCertificate` for one impact or rows of impacts.

    Parameters
    ----------
    structure : ImpactStructure
        M and W.
    U_minus, U_plus, Lam : ndarray
        u⁻, u⁺ and Λ of one impact (1-D) or of k impacts (rows).
    stored : float or (k,) ndarray
        Energy the integration left in the contacts plus what it dissipated, in units of
        ``energy_unit``. Without it (batches) the balance is checked as conservation when
        ``elastic`` and as "no energy gained" otherwise.
    left : float or (k,) ndarray
        The part of ``stored`` left in the contacts (same units).
    energy_unit : (V, g)
        Energies are in units of V²/g (the integration's VΠ, :mod:`.dynamics`); (1, 1):
        physical units. Never formed, so no scale overflows.
    elastic : bool
        Every contact has eᵢ = 1.

    Returns
    -------
    dict
        ``momentum``, ``impulse_sign``, ``energy_balance``, ``kinematic`` and
        ``potential_left``, floats for one impact or (k,) arrays.
    """
    st = structure
    U_minus, U_plus, Lam, scale = normalized_rows(U_minus, U_plus, Lam,
                                                  np.ones(U_minus.shape[:-1] + (1,)))
    V, out = impact_residuals(st, U_minus, U_plus, Lam)
    c = scale[..., 0]  # 1 / the factor normalized_rows divided by
    unit = (energy_unit[0] * c) ** 2 / energy_unit[1]  # V²/g in the normalized units
    stored = np.asarray(stored, dtype=float) * unit
    gain = kinetic_norms(st, U_plus) ** 2 + 2.0 * stored - kinetic_norms(st, U_minus) ** 2
    out["energy_balance"] = (np.abs(gain) if elastic else np.maximum(gain, 0.0)) / V**2
    if st.m:
        gamma = st.Wt_times(U_plus)
        out["kinematic"] = 0.0 + np.maximum(0.0, -np.min(gamma / (st.contact_scale
                                                                  * V[..., None]), axis=-1))
    else:
        out["kinematic"] = np.zeros(U_minus.shape[:-1])
    out["potential_left"] = 2.0 * np.asarray(left, dtype=float) * unit / V**2 \
        + np.zeros(U_minus.shape[:-1])
    return out
