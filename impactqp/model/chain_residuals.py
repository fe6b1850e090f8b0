"""The certificate's residuals for one impact of a 1-D chain in O(N) passes, without a matrix
(docs/theory.md §5, §8).

The same quantities as :func:`impactqp.model.residuals.law_residuals`, in the same units and
with the same rescaling at extreme velocities, recomputed from (u⁻, u⁺, Λ) alone. With
t = u⁺ − u⁻ and L_j the impulse left of ball j (0 where there is no wall):

* momentum: ‖t − M⁻¹WΛ‖²_M = Σⱼ rⱼ²/mⱼ with rⱼ = mⱼtⱼ − (L_j − L_{j+1});
* w = γ⁺ + Eγ⁻ with γ = Wᵀu: differences of neighbours, u₁ and −u_N at the walls;
* energy balance: z = u⁻ + t/(1+ε) and z⊥ = −t/(1+ε), so
  ⟨z, z⊥⟩ = −(⟨t, u⁻⟩_M + ‖t‖²_M/(1+ε)) / (1+ε): two dot products with Mt, which the
  momentum needs anyway (docs/theory.md §3); its rounding is a few ulps of V², not of
  Σ|mᵢzᵢz⊥ᵢ|, still far below any tolerance.

The balls are taken in chunks of :data:`CHUNK`: every temporary lives in two rows of one chunk
(in cache, and no scratch of N pages to fault in), and each input is read once.
"""

from __future__ import annotations

import math

import numpy as np

from .residuals import law_residuals, normalized_rows
from .structure import ImpactStructure

CHUNK = 2**16
"""Balls per chunk: the temporaries of a chunk stay in cache and no scratch of N is made."""

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


def _chunked_dot(a: np.ndarray, m: np.ndarray, b: np.ndarray) -> float:
    """Σ aᵢmᵢbᵢ chunk by chunk (a scratch of one chunk, not of N)."""
    work = np.empty(min(a.size, CHUNK))
    return math.fsum(float(np.dot(np.multiply(a[i:i + CHUNK], m[i:i + CHUNK],
                                              out=work[:min(CHUNK, a.size - i)]),
                                  b[i:i + CHUNK]))
                     for i in range(0, a.size, CHUNK))


class _Sums:
    """The reductions of the residuals, accumulated chunk by chunk."""

    def __init__(self) -> None:
        self.mt_u = self.mt_t = self.q = 0.0  # ⟨t, u⁻⟩_M, ‖t‖²_M, momentum²·V²
        self.feasibility = math.inf  # min wᵢ/sᵢ
        self.product_max = self.product_sum = 0.0  # max and sum of |Λᵢwᵢ|

    def add(self, w: np.ndarray, lam: np.ndarray, s: np.ndarray, spare: np.ndarray) -> None:
        """Fold in the contacts with w = γ⁺ + Eγ⁻ (``spare``: scratch of the same size)."""
        if not w.min() >= 0.0:  # NaN included (np.minimum and np.maximum keep it)
            self.feasibility = float(np.minimum(self.feasibility,
                                                np.divide(w, s, out=spare).min()))
        p = np.multiply(lam, w, out=spare)
        if not p.min() >= 0.0:
            np.abs(p, out=p)
        self.product_max = float(np.maximum(self.product_max, p.max()))
        self.product_sum += float(p.sum())


@np.errstate(invalid="ignore", over="ignore")  # non-finite inputs give NaN residuals: they fail
def chain_law_residuals(structure: ImpactStructure, u_minus: np.ndarray, u_plus: np.ndarray,
                        Lam: np.ndarray, E: float, *, eps: float | None = None,
                        V: float | None = None) -> dict[str, float]:
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
    V : float, optional
        ‖u⁻‖ when already known (the problem keeps it).

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
    m, s, inv, n = c.masses, st.contact_scale, st.inverse_masses, st.n
    lo = 0 if c.left_wall else 1  # Λ = (L_lo, L_lo+1, …), L_j the impulse left of ball j
    hi = lo + lam.size
    if V is None or um is not u_minus:
        V = _norm_from_square(_chunked_dot(um, m, um), st, um)
    if V == 0.0:  # u⁻ = 0: measure against the answer (normalized to unit entries)
        V = max(_norm_from_square(_chunked_dot(up, m, up), st, up), 1.0)
    acc = _Sums()
    work = np.empty((2, min(n, CHUNK)))  # every temporary lives in these two rows
    for i0 in range(0, n, CHUNK):
        i1 = min(i0 + CHUNK, n)
        t, r = work[0, :i1 - i0], work[1, :i1 - i0]
        np.subtract(up[i0:i1], um[i0:i1], out=t)  # t = u⁺ − u⁻, r = Mt − (L_j − L_{j+1})
        np.multiply(t, m[i0:i1], out=r)
        if eps:  # the energy balance is 2ε|⟨z, z⊥⟩|/V²: exactly 0 at ε = 0
            acc.mt_u += float(np.dot(r, um[i0:i1]))
            acc.mt_t += float(np.dot(r, t))
        j0, j1 = max(i0, lo), min(i1, hi)
        r[j0 - i0:j1 - i0] -= lam[j0 - lo:j1 - lo]
        j0, j1 = max(i0, lo - 1), min(i1, hi - 1)
        r[j0 - i0:j1 - i0] += lam[j0 + 1 - lo:j1 + 1 - lo]
        acc.q += float(np.dot(np.multiply(r, r, out=r), inv[i0:i1]))
        j0, j1 = max(i0, 1), min(i1, n)  # the gaps left of balls j0 … j1 − 1
        if j1 > j0:  # w = γ⁺ + Eγ⁻, γ⁻ from the chunk of u⁻ at hand
            w, spare = t[:j1 - j0], r[:j1 - j0]
            np.subtract(up[j0:j1], up[j0 - 1:j1 - 1], out=w)
            if E != 0.0:
                w += np.multiply(np.subtract(um[j0:j1], um[j0 - 1:j1 - 1], out=spare), E,
                                 out=spare)
            acc.add(w, lam[j0 - lo:j1 - lo], s[j0 - lo:j1 - lo], spare)
    if c.left_wall:  # γ = u₁
        acc.add(up[:1] + E * um[:1], lam[:1], s[:1], np.empty(1))
    if c.right_wall:  # γ = −u_N
        acc.add(-up[-1:] + E * -um[-1:], lam[-1:], s[-1:], np.empty(1))
    out: dict[str, float] = {}
    q = acc.q
    if q == 0.0 or SQUARE_RANGE[0] < q < SQUARE_RANGE[1]:
        out["momentum"] = math.sqrt(q) / V
    else:
        out["momentum"] = float(st.kinetic_norms(up - um - st.impulse_velocity(lam))) / V
    out["impulse_sign"] = 0.0 if lam.min() >= 0.0 else _excess(-float((lam * s).min()) / V)
    out["law_feasibility"] = _excess(-acc.feasibility / V)
    V2 = V * V
    out["complementarity"] = acc.product_max / V2
    if eps is not None:
        energy = (acc.mt_u + acc.mt_t / (1.0 + eps)) / (1.0 + eps)
        out["energy_balance"] = 2.0 * eps * abs(energy) / V2
        out["duality_gap"] = acc.product_sum / V2 + out["momentum"] ** 2
    return out
