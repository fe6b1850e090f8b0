"""The certificate of the LZB model (docs/theory.md §8, §13): the impact equation, Λ ≥ 0,
the end state of the integration (every contact separating or at rest, no compression left)
and its energy balance, recomputed from u⁻, u⁺, Λ and the integration's record."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ...base.checks import Certificate
from ...model.residuals import impact_residuals, kinetic_norms, normalized_rows
from ...model.structure import ImpactStructure
from .integration import LZBRecord

LZB_RESIDUALS = ("momentum", "impulse_sign", "kinematic", "energy_balance", "potential_left")
"""The residuals of an LZB certificate (:func:`lzb_residuals`)."""

EXACT = ("momentum", "impulse_sign")
"""The residuals that hold to rounding; the integration's accuracy decides the others."""

LZBCertificate = Certificate
"""The certificate of the LZB model is a :class:`~impactqp.results.Certificate` (made by
:func:`lzb_certificate`); the name is kept for code written before there was one type."""


def lzb_certificate(residuals: Mapping[str, float], tol: float, integration_tol: float,
                    record: LZBRecord | None = None) -> Certificate:
    """The certificate of one LZB result (docs/theory.md §8, §13), dimensionless.

    Its residuals (:func:`lzb_residuals`):

    - momentum: ‖u⁺ − u⁻ − M⁻¹WΛ‖ / V, the impact equation;
    - impulse_sign: the largest violation of Λ ≥ 0 (scaled);
    - kinematic: the largest violation of γ⁺ = Wᵀu⁺ ≥ 0 (scaled): every contact
      separates or rests;
    - energy_balance: the size of ‖u⁺‖² + 2ΣEᵢ + 2ΣDᵢ − ‖u⁻‖² over V²: kinetic energy
      after, plus the potential energy Eᵢ left in the contacts, plus the energy Dᵢ
      dissipated by restitution, equals the kinetic energy before, to the integration's
      accuracy;
    - potential_left: 2ΣEᵢ / V², the integration ended with no compression left.

    Parameters
    ----------
    residuals : mapping
        The five residuals by name.
    tol : float
        Tolerance of momentum and impulse_sign (they hold to rounding).
    integration_tol : float
        Tolerance of the residuals the integration's accuracy decides (energy_balance,
        kinematic, potential_left): ``tol``, or more where the integration's own error
        estimate is larger (:func:`integration_tolerance`, docs/theory.md §13); the
        certificate's ``tols`` and its extra ``integration_tol``.
    record : LZBRecord, optional
        The integration (primary switches, steps, energies), the extra ``record``; None
        when nothing was integrated.
    """
    tols = {k: integration_tol for k in residuals if k not in EXACT}
    return Certificate(residuals, tol, tols=tols, names=LZB_RESIDUALS,
                       extras={"integration_tol": integration_tol, "record": record})


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
    """Residuals of :func:`lzb_certificate` for one impact or rows of impacts.

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
