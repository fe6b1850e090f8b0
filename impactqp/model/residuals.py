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
from ..kernels.residuals import RESIDUALS, chain_residuals, dense_residual_rows, finish_rows
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


def restitution_matrix(E, m: int) -> np.ndarray:
    """The law's E as an (m, m) matrix: a scalar ε is εI, a vector diag(e), a matrix itself."""
    E = np.asarray(E, dtype=float)
    if E.ndim == 0:
        return np.eye(m) * float(E)
    return np.diag(E) if E.ndim == 1 else np.ascontiguousarray(E)


DENSE_CONTACTS = 2000
"""Most contacts whose residuals the dense kernel computes (it takes E as an (m, m) matrix);
more go through numpy products that apply a scalar or per-contact E without forming it."""

_EMPTY = np.zeros((0, 0))


def certificate_operand(structure: ImpactStructure) -> np.ndarray:
    """M⁻¹W of a dense structure for the certificate's impact equation
    (:attr:`~impactqp.model.structure.ImpactStructure.certificate_Minv_W`: solved from the
    given M and W by LU, once per structure).

    The solvers recover u⁺ = u⁻ + M⁻¹WΛ from an impulse-form answer with the structure's own
    M⁻¹W (from the Cholesky factor of M); measuring the impact equation with that same
    operand would certify any error in it that Wᵀ does not see (docs/theory.md §8,
    "Independence")."""
    return structure.certificate_Minv_W


def momentum_defect(structure: ImpactStructure, Um: np.ndarray, Up: np.ndarray,
                    Lam: np.ndarray) -> np.ndarray:
    """Rows of M⁻¹(M(u⁺ − u⁻) − WΛ), whose kinetic norms measure the impact equation
    (docs/theory.md §8, "Independence").

    The defect M(u⁺ − u⁻) − WΛ is formed from the given M and W; the factor of M only
    measures its size, so an error in the M⁻¹W the solver recovered u⁺ with cannot hide in
    it. A chain's rows use its ball-by-ball formula (no matrix is formed for a chain).
    """
    st = structure
    if st.chain is not None:
        return Up - Um - st.impulse_velocity(Lam)
    force = st.mass_rows(Up - Um) - np.asarray(st.W @ Lam.T).T
    return np.asarray(st.solve_mass(np.ascontiguousarray(force.T))).T


def _restitute(E: np.ndarray, gamma: np.ndarray) -> np.ndarray:
    """Eγ for every row of γ: εγ, eᵢγᵢ or the matrix product, without forming εI or diag(e)."""
    return E * gamma if E.ndim < 2 else gamma @ E.T


def law_residuals(structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                  Lam: np.ndarray, E, *, eps: float | None = None) -> dict[str, np.ndarray]:
    """Residuals of the certificate for one impact (1-D arrays) or k impacts (rows).

    The formulas are those of :mod:`impactqp.kernels.residuals` (docs/theory.md §8), fed by
    the structure's operators: compiled dense products for dense M and W (with M⁻¹W of
    :func:`certificate_operand`, not the solvers' own), numpy products otherwise. Returns a
    dict with the keys of :attr:`Certificate.residuals`: floats for one impact, (k,) arrays
    for k; ``energy_balance`` and ``duality_gap`` only with Moreau's
    ``eps``, where u⁺ = z − εz⊥ and the energy balance is −2ε⟨z, z⊥⟩ (docs/theory.md §3).
    """
    st = structure
    one = np.ndim(U_minus) == 1
    if one and st.chain is not None and np.ndim(E) == 0 and st.m:
        return _chain_residuals(st, U_minus, U_plus, Lam, float(E), eps)
    Um, Up, L = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (U_minus, U_plus, Lam))
    moreau = eps is not None
    e = 0.0 if eps is None else float(eps)
    E = np.asarray(E, dtype=float)
    if not st.sparse and st.chain is None and st.m <= DENSE_CONTACTS:
        # the kernel forms εI itself for Moreau's law (an empty E), any other E as a matrix
        Em = _EMPTY if moreau else restitution_matrix(E, st.m)
        table = dense_residual_rows(st.dense_mass, st.dense_Wt, certificate_operand(st),
                                    st.contact_scale, Um, Up, L, Em, e, moreau)
    else:
        with np.errstate(over="ignore", invalid="ignore"):
            Um, Up, L = normalized_rows(Um, Up, L)
            V, _ = impact_residuals(st, Um, Up, L)
            norms = kinetic_norms(st, momentum_defect(st, Um, Up, L))
            W = st.Wt_times(Up) + _restitute(E, st.Wt_times(Um)) if st.m else \
                np.zeros_like(L)
            z = (Up + e * Um) / (1.0 + e)
            cross = row_sum(st.mass_rows(z) * (Um - z)) if moreau else np.zeros(V.size)
        table = finish_rows(V, norms, np.ascontiguousarray(L), np.ascontiguousarray(W),
                            st.contact_scale, e, moreau, cross)
    names = RESIDUALS if moreau else RESIDUALS[:4]
    return {name: (float(table[0, i]) if one else table[:, i]) for i, name in enumerate(names)}


def _chain_residuals(st: ImpactStructure, u_minus, u_plus, Lam, E: float,
                     eps: float | None) -> dict[str, float]:
    """The residuals of one chain impact by the compiled O(N) loop (docs/theory.md §5, §8);
    inputs that do not have the chain's shapes give NaN (they fail)."""
    c = st.chain
    um, up, lam = (np.ascontiguousarray(a, dtype=float) for a in (u_minus, u_plus, Lam))
    names = RESIDUALS if eps is not None else RESIDUALS[:4]
    if um.shape != (st.n,) or up.shape != um.shape or lam.shape != (st.m,):
        return dict.fromkeys(names, float("nan"))
    out = np.empty(len(RESIDUALS))
    chain_residuals(um, up, lam, c.masses, st.inverse_masses, st.contact_scale,
                    bool(c.left_wall), bool(c.right_wall), E, 0.0 if eps is None else float(eps),
                    eps is not None, out)
    return {name: float(out[i]) for i, name in enumerate(names)}
