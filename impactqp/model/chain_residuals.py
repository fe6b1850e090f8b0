"""The certificate's residuals for one impact of a 1-D chain in O(N) passes, without a matrix
(docs/theory.md §5, §8).

The same quantities as :func:`impactqp.model.residuals.law_residuals`, in the same units and
with the same rescaling at extreme velocities, recomputed from (u⁻, u⁺, Λ) alone. With
t = u⁺ − u⁻ and L_j the impulse left of ball j (0 where there is no wall):

* momentum: ‖t − M⁻¹WΛ‖²_M = Σⱼ rⱼ²/mⱼ with rⱼ = mⱼtⱼ − (L_j − L_{j+1});
* w = γ⁺ + Eγ⁻ with γ = Wᵀu: differences of neighbours, u₁ and −u_N at the walls;
* energy balance: z = u⁻ + t/(1+ε) and z⊥ = −t/(1+ε), so
  ⟨z, z⊥⟩ = −(⟨t, u⁻⟩_M + ‖t‖²_M/(1+ε)) / (1+ε): two dot products with Mt, which the
  momentum needs anyway (docs/theory.md §3).
"""

from __future__ import annotations

import math

import numpy as np

from .residuals import law_residuals, normalized_rows
from .structure import ImpactStructure

SQUARE_RANGE = (1e-250, math.inf)
"""Sums of squares that keep full precision (outside, kinetic norms rescale first)."""


def _norm_from_square(q: float, structure: ImpactStructure, x: np.ndarray | None) -> float:
    """√q when q is a sum of squares in range, 0 for 0, else the rescaled kinetic norm of x."""
    if q == 0.0 or SQUARE_RANGE[0] < q < SQUARE_RANGE[1]:
        return math.sqrt(q)
    return float(structure.kinetic_norms(x))


def _excess(v: float) -> float:
    """(v)₊ that keeps NaN (a residual that cannot be evaluated must not read 0)."""
    return 0.0 if v <= 0.0 else v


def _jumps(r: np.ndarray, lam: np.ndarray, lo: int) -> None:
    """r_j −= L_j − L_{j+1} in place, where Λ = (L_lo, L_lo+1, …) and L is 0 elsewhere."""
    n, hi = r.size, lo + lam.size
    end = min(hi, n)
    r[lo:end] -= lam[:end - lo]
    j0, j1 = max(lo - 1, 0), min(hi - 1, n)
    r[j0:j1] += lam[j0 + 1 - lo:j1 + 1 - lo]


def _contact_velocities(y: np.ndarray, left: bool, right: bool, out: np.ndarray) -> np.ndarray:
    """Wᵀy of a chain into ``out``: [y₁ (left wall), y_{j+1} − y_j, −y_N (right wall)]."""
    lo = 1 if left else 0
    np.subtract(y[1:], y[:-1], out=out[lo:lo + y.size - 1])
    if left:
        out[0] = y[0]
    if right:
        out[-1] = -y[-1]
    return out


def chain_law_residuals(structure: ImpactStructure, u_minus: np.ndarray, u_plus: np.ndarray,
                        Lam: np.ndarray, E: float, *, eps: float | None = None,
                        gamma_minus: np.ndarray | None = None) -> dict[str, float]:
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
    gamma_minus : (m,) ndarray, optional
        γ⁻ = Wᵀu⁻ when already known (the problem keeps it).

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
    um = u_minus = np.asarray(u_minus, dtype=float)
    if st.m == 0 or um.shape != (st.n,) or up.shape != um.shape or lam.shape != (st.m,):
        return {k: float(v) for k, v in law_residuals(st, um, up, lam, E, eps=eps).items()}
    top = max(um.max(), -um.min())
    if not 1e-60 < top < 1e60:  # squares could leave the range: rescale as law_residuals does
        um, up, lam = normalized_rows(um, up, lam)
    m, s, n, k = c.masses, st.contact_scale, st.n, st.m
    work = np.empty((2, n + 1))  # two scratch rows: every temporary below lives in them
    a, b = work[0, :n], work[1, :n]
    V = _norm_from_square(float(np.dot(np.multiply(um, m, out=a), um)), st, um)
    if V == 0.0:  # u⁻ = 0: measure against the answer (normalized to unit entries)
        V = max(_norm_from_square(float(np.dot(np.multiply(up, m, out=a), up)), st, up), 1.0)
    V2 = V * V
    t, r = np.subtract(up, um, out=a), np.multiply(a, m, out=b)  # t = u⁺ − u⁻, r = Mt
    out: dict[str, float] = {}
    if eps is not None:
        energy = (float(np.dot(r, um)) + float(np.dot(r, t)) / (1.0 + eps)) / (1.0 + eps)
    _jumps(r, lam, 0 if c.left_wall else 1)
    np.multiply(r, r, out=r)
    q = float(np.dot(r, st.inverse_masses))
    if q == 0.0 or SQUARE_RANGE[0] < q < SQUARE_RANGE[1]:
        out["momentum"] = math.sqrt(q) / V
    else:
        out["momentum"] = float(st.kinetic_norms(t - st.impulse_velocity(lam))) / V
    scaled = work[0, :k]  # t is no longer needed
    out["impulse_sign"] = 0.0 if lam.min() >= 0.0 else \
        _excess(-float(np.multiply(lam, s, out=scaled).min()) / V)
    w = _contact_velocities(up, c.left_wall, c.right_wall, out=work[1, :k])  # over r
    if E != 0.0:  # w = γ⁺ + Eγ⁻
        if gamma_minus is None or um is not u_minus:
            gamma_minus = st.Wt_times(um)
        w += np.multiply(gamma_minus, E, out=scaled)
    out["law_feasibility"] = 0.0 if w.min() >= 0.0 else \
        _excess(-float(np.divide(w, s, out=scaled).min()) / V)
    p = np.abs(np.multiply(lam, w, out=scaled), out=scaled)
    out["complementarity"] = float(p.max()) / V2
    if eps is not None:
        out["energy_balance"] = 2.0 * eps * abs(energy) / V2
        out["duality_gap"] = float(p.sum()) / V2 + out["momentum"] ** 2
    return out
