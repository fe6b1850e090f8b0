"""The equations of the LZB model of a multiple impact, in dimensionless variables
(docs/theory.md §13).

Each closed contact i carries a compliance Fᵢ = Kᵢδᵢ^ηᵢ (Hertz: ηᵢ = 3/2, linear: ηᵢ = 1) and
an energetic restitution coefficient eᵢ (bi-stiffness: the expansion phase gives back eᵢ² of
the energy stored during compression). The state during the impact is, per contact, the
accumulated impulse Pᵢ, the stored potential energy Eᵢ and the energy Dᵢ dissipated so far;
the contact velocities follow from γ = γ⁻ + GP. This module holds the rates of that state,
once against time and once against the impulse of the primary contact, on which
:mod:`impactqp.laws.lzb.integration` builds the integration.

Everything here is dimensionless: velocities against V = max |γ⁻ᵢ|, the Delassus matrix
against g = max Gᵢᵢ, impulses against Π = V/g, energies against VΠ, so that every state
variable is of order one and one absolute tolerance fits all of them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...base.arrays import Matrix, as_dense

TINY = 1e-30
"""Floor of the primary contact's dimensionless force: its energy is zero only at the event
that ends a piece, and trial steps beyond that event must stay finite."""


def force_coefficient(stiffness: np.ndarray, exponent: np.ndarray) -> np.ndarray:
    """cᵢ with Fᵢ = cᵢ Eᵢ^(ηᵢ/(ηᵢ+1)): the force of compliance Kδ^η as a function of its
    potential energy E = Kδ^(η+1)/(η+1) (docs/theory.md §13).

    Parameters
    ----------
    stiffness, exponent : ndarray
        K > 0 and η > 0 per contact.

    Returns
    -------
    ndarray
        c = (η+1)^(η/(η+1)) K^(1/(η+1)).
    """
    return (exponent + 1.0) ** (exponent / (exponent + 1.0)) * stiffness ** (1.0 / (exponent + 1.0))


@dataclass(frozen=True)
class Scales:
    """The units of the dimensionless variables: velocity V, Delassus g, impulse Π = V/g,
    energy VΠ (docs/theory.md §13)."""

    velocity: float
    delassus: float

    @property
    def impulse(self) -> float:
        return self.velocity / self.delassus

    @property
    def energy(self) -> float:
        return self.velocity * self.impulse


class LZBDynamics:
    """Rates of the LZB state (docs/theory.md §13) for one impact, dimensionless.

    The integrated variable of contact i is yᵢ = Eᵢ^(1/(ηᵢ+1)), proportional to its
    indentation: against time its rate −sᵢγᵢκᵢ/(ηᵢ+1) is regular where the energy's is not
    (sᵢ = 1 in compression, 1/eᵢ² in expansion). Against the primary impulse the primary
    contact k carries Eₖ itself (rate −sₖγₖ, regular up to its end) and the others yᵢ.

    Parameters
    ----------
    delassus : (m, m) matrix
        G = WᵀM⁻¹W, dense or sparse.
    gamma_minus : (m,) ndarray
        Pre-impact contact velocities; at least one negative.
    stiffness, exponent, restitution : (m,) ndarray
        Kᵢ > 0, ηᵢ > 0, eᵢ ∈ [0, 1].
    """

    def __init__(self, delassus: Matrix, gamma_minus: np.ndarray, stiffness: np.ndarray,
                 exponent: np.ndarray, restitution: np.ndarray) -> None:
        G = as_dense(delassus) if delassus.shape[0] <= 400 else delassus
        self.scales = Scales(float(np.max(np.abs(gamma_minus))),
                             float(np.max(np.asarray(delassus.diagonal()))))
        self.G = G / self.scales.delassus
        self.gamma0 = gamma_minus / self.scales.velocity
        self.m = gamma_minus.size
        self.eta = exponent
        self.restitution = restitution
        self.power = 1.0 / (exponent + 1.0)  # y = E^power
        c = force_coefficient(stiffness, exponent) * self.scales.energy ** (exponent * self.power)
        self.kappa = c / c.max()  # F = κ y^η in units of Π per unit of dimensionless time
        self.expansion = np.divide(1.0, restitution ** 2, out=np.zeros(self.m),
                                   where=restitution > 0)  # 1/e², unused when e = 0
        self.plastic = restitution == 0

    def gamma(self, P: np.ndarray) -> np.ndarray:
        """Contact velocities γ = γ⁻ + GP."""
        return self.gamma0 + self.G @ P

    def energy(self, y: np.ndarray) -> np.ndarray:
        """Potential energies Eᵢ = yᵢ^(ηᵢ+1) (zero where yᵢ ≤ 0)."""
        return np.maximum(y, 0.0) ** (self.eta + 1.0)

    def time_rates(self, y: np.ndarray, P: np.ndarray, frozen: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(ẏ, Ṗ, Ḋ, γ) against dimensionless time.

        ``frozen`` marks the contacts that are open (yᵢ = 0, γᵢ ≥ 0) for the whole piece
        being integrated: they keep yᵢ = 0 until an event reopens the question. The others
        follow ẏᵢ = −sᵢγᵢκᵢ/(ηᵢ+1), also past yᵢ = 0 (the event that ends the piece there
        needs a smooth right-hand side). Compression stores −γᵢ dPᵢ, expansion releases
        γᵢ dPᵢ/eᵢ², and (1/eᵢ² − 1)γᵢ dPᵢ is dissipated; a plastic contact (eᵢ = 0) is
        emptied by an event instead, so its rate in expansion is zero.
        """
        gamma = self.gamma(P)
        force = self.kappa * np.maximum(y, 0.0) ** self.eta
        compressing = gamma < 0
        factor = np.where(compressing, 1.0, self.expansion)
        ydot = np.where(frozen, 0.0, -factor * gamma * self.kappa * self.power)
        expanding = ~frozen & ~compressing & ~self.plastic
        ddot = np.where(expanding, (self.expansion - 1.0) * gamma * force, 0.0)
        return ydot, force, ddot, gamma

    def impulse_rates(self, z: np.ndarray, P: np.ndarray, k: int, frozen: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(ż, Ṗ, Ḋ) against the impulse Pₖ of the primary contact k, whose slot zₖ holds
        its energy Eₖ (the other slots hold yᵢ): the distributing law dPᵢ/dPₖ = Fᵢ/Fₖ."""
        y = z.copy()
        y[k] = max(z[k], 0.0) ** self.power[k]
        ydot, force, ddot, gamma = self.time_rates(y, P, frozen)
        fk = max(force[k], TINY)
        zdot, pdot, ddot = ydot / fk, force / fk, ddot / fk
        pdot[k] = 1.0
        g = gamma[k]
        if g < 0:
            zdot[k], ddot[k] = -g, 0.0
        elif self.plastic[k]:
            zdot[k], ddot[k] = 0.0, 0.0
        else:
            zdot[k], ddot[k] = -self.expansion[k] * g, (self.expansion[k] - 1.0) * g
        return zdot, pdot, ddot
