"""The equations of the LZB model of a multiple impact, in dimensionless variables
(docs/theory.md §13).

Each closed contact i carries a compliance Fᵢ = Kᵢδᵢ^ηᵢ (Hertz: ηᵢ = 3/2, linear: ηᵢ = 1) and
an energetic restitution coefficient eᵢ (bi-stiffness: the expansion phase gives back eᵢ² of
the energy stored during compression). The state during the impact is, per contact, the
accumulated impulse Pᵢ, the stored potential energy Eᵢ and the energy Dᵢ dissipated so far;
the contact velocities follow from γ = γ⁻ + GP. This module prepares one impact for the
compiled rates and events of :mod:`impactqp.kernels.lzb` (their one definition): the units,
the scaled G in compressed rows and the per-contact constants.

Everything here is dimensionless: velocities against V = max |γ⁻ᵢ|, the Delassus matrix
against g = max Gᵢᵢ, impulses against Π = V/g, energies against VΠ, so that every state
variable is of order one and one absolute tolerance fits all of them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ...base.arrays import Matrix
from ...errors import InputError
from ...kernels.lzb_model import (
    ETA,
    EXPANSION,
    KAPPA,
    PLASTIC,
    POWER,
    Impact,
    contact_velocities,
)
from ...model.structure import ImpactStructure


def log_force_coefficient(stiffness: np.ndarray, exponent: np.ndarray) -> np.ndarray:
    """log cᵢ with Fᵢ = cᵢ Eᵢ^(ηᵢ/(ηᵢ+1)): the force of compliance Kδ^η as a function of its
    potential energy E = Kδ^(η+1)/(η+1) (docs/theory.md §13), in logarithms so that no
    stiffness overflows.

    Parameters
    ----------
    stiffness, exponent : ndarray
        K > 0 and η > 0 per contact.

    Returns
    -------
    ndarray
        log c = η/(η+1) log(η+1) + log(K)/(η+1).
    """
    return (exponent * np.log(exponent + 1.0) + np.log(stiffness)) / (exponent + 1.0)


def delassus_rows(structure: ImpactStructure) -> Matrix:
    """G = WᵀM⁻¹W as the LZB integration takes it (docs/theory.md §1, §5): a chain's is
    tridiagonal and is formed from its masses in O(N), as a sparse matrix (its diagonal is
    :attr:`~impactqp.model.structure.ImpactStructure.delassus_diagonal`; neighbouring
    contacts share the ball between them, −1/m of it); any other structure's is its
    :attr:`~impactqp.model.structure.ImpactStructure.delassus`. A chain's dense G would be
    a product of dense matrices, whose BLAS threads then keep the second core busy while
    the integration runs."""
    c = structure.chain
    if c is None:
        return structure.delassus
    lo = int(c.left_wall)
    off = -structure.inverse_masses[1 - lo:1 - lo + structure.m - 1]
    return sp.diags([off, structure.delassus_diagonal, off], [-1, 0, 1], format="csr")


@dataclass(frozen=True)
class Scales:
    """The units of the dimensionless variables: velocity V, Delassus g, impulse Π = V/g,
    energy VΠ (docs/theory.md §13)."""

    velocity: float
    delassus: float

    @property
    def impulse(self) -> float:
        return self.velocity / self.delassus


class LZBDynamics:
    """One impact of the LZB model (docs/theory.md §13) in dimensionless form, ready for the
    kernels of :mod:`impactqp.kernels.lzb`.

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
        Kᵢ > 0, ηᵢ ∈ [1, 3], eᵢ ∈ [0, 1].

    Raises
    ------
    InputError
        Stiffnesses and exponents whose scaled force coefficients κᵢ = cᵢ(VΠ)^(ηᵢ/(ηᵢ+1))
        differ by more than the floating-point range (a contact could never move).
    """

    def __init__(self, delassus: Matrix, gamma_minus: np.ndarray, stiffness: np.ndarray,
                 exponent: np.ndarray, restitution: np.ndarray) -> None:
        V = float(np.max(np.abs(gamma_minus)))
        g = float(np.max(np.asarray(delassus.diagonal())))
        self.scales = Scales(V, g)
        G = sp.csr_matrix(delassus, dtype=float) / g
        G.sum_duplicates()
        G.eliminate_zeros()
        self.indptr = G.indptr.astype(np.int64)
        self.indices = G.indices.astype(np.int64)
        self.data = np.ascontiguousarray(G.data)
        self.gamma0 = gamma_minus / V
        self.m = gamma_minus.size
        power = 1.0 / (exponent + 1.0)  # y = E^power
        # log κᵢ = log cᵢ + ηᵢ/(ηᵢ+1) log(VΠ), VΠ = V²/g, then divided by the largest
        log_energy = 2.0 * np.log(V) - np.log(g)
        log_kappa = log_force_coefficient(stiffness, exponent) + exponent * power * log_energy
        with np.errstate(under="ignore"):
            kappa = np.exp(log_kappa - log_kappa.max())
        if not np.all(kappa > 0):
            raise InputError("stiffness: the contacts' scaled force coefficients differ by "
                             f"more than 1e308 (log₁₀ ratio {np.ptp(log_kappa) / np.log(10):.0f});"
                             " such a contact never moves in this impact's units")
        expansion = np.divide(1.0, restitution ** 2, out=np.zeros(self.m),
                              where=restitution > 0)  # 1/e², unused when e = 0
        self.law = np.empty((5, self.m))
        self.law[KAPPA], self.law[ETA], self.law[POWER] = kappa, exponent, power
        self.law[EXPANSION], self.law[PLASTIC] = expansion, restitution == 0

    def gamma(self, P: np.ndarray) -> np.ndarray:
        """Contact velocities γ = γ⁻ + GP (dimensionless)."""
        out = np.empty(self.m)
        contact_velocities(self.indptr, self.indices, self.data, self.gamma0, P, out)
        return out

    @property
    def structure(self) -> Impact:
        """(indptr, indices, data, γ⁻, law): what the kernels of :mod:`impactqp.kernels.lzb`
        take about the impact, grouped."""
        return Impact(self.indptr, self.indices, self.data, self.gamma0, self.law)
