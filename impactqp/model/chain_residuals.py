"""The certificate's residuals for one impact of a 1-D chain in one O(N) pass, without a
matrix (docs/theory.md §5, §8): the compiled loop
:func:`impactqp.kernels.residuals.chain_residuals` over the balls, with the formulas of every
other certificate."""

from __future__ import annotations

import numpy as np

from ..kernels.residuals import RESIDUALS, chain_residuals
from .residuals import law_residuals
from .structure import ImpactStructure


def chain_law_residuals(structure: ImpactStructure, u_minus: np.ndarray, u_plus: np.ndarray,
                        Lam: np.ndarray, E: float, *, eps: float | None = None,
                        ) -> dict[str, float]:
    """Residuals of ``0 ≤ Λ ⟂ γ⁺ + Eγ⁻ ≥ 0`` and ``M(u⁺ − u⁻) = WΛ`` for one chain impact
    with a scalar restitution E (and, for Moreau's law, ``eps``: the energy balance and the
    duality gap), equal to :func:`~impactqp.model.residuals.law_residuals` up to rounding
    (docs/theory.md §8).

    Parameters
    ----------
    structure : ImpactStructure
        A chain's (``structure.chain`` set).
    u_minus, u_plus : (N,) ndarray
        Pre-impact velocity and the candidate post-impact velocity.
    Lam : (m,) ndarray
        Candidate impulses, in the chain's contact order.
    E : float
        The scalar restitution of w = γ⁺ + Eγ⁻.
    eps : float, optional
        Moreau's ε: adds ``energy_balance`` and ``duality_gap``.

    Returns
    -------
    dict
        The keys of :attr:`impactqp.laws.certificate.Certificate.residuals`, as floats
        (NaN where an input is not finite). Inputs that do not have the chain's shapes are
        handed to the general computation.
    """
    st = structure
    c = st.chain
    up, lam = np.asarray(u_plus, dtype=float), np.asarray(Lam, dtype=float)
    um = np.asarray(u_minus, dtype=float)
    if st.m == 0 or um.shape != (st.n,) or up.shape != um.shape or lam.shape != (st.m,):
        return {k: float(v) for k, v in law_residuals(st, um, up, lam, E, eps=eps).items()}
    out = np.empty(len(RESIDUALS))
    chain_residuals(um, up, lam, c.masses, st.inverse_masses, st.contact_scale, bool(c.left_wall),
                    bool(c.right_wall), float(E), 0.0 if eps is None else float(eps),
                    eps is not None, out)
    names = RESIDUALS if eps is not None else RESIDUALS[:4]
    return {name: float(out[i]) for i, name in enumerate(names)}
