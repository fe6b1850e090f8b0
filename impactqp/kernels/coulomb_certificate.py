"""The residuals of Coulomb's law with restitution for one frictional impact with dense M and
W, in one compiled pass (docs/theory.md §8, §15, §16).

The same residuals, the same meaning and the same formulas as the reference computation of
:meth:`impactqp.Coulomb.residuals` (numpy products and
:func:`impactqp.model.friction.certify_friction`), gathered so that a certificate costs one
call: the momentum by :func:`impactqp.kernels.residuals.dense_momentum` with the
certificate's own M⁻¹W, the natural map by :func:`impactqp.kernels.friction.natural_map`,
the cone and complementarity by
:func:`impactqp.kernels.coulomb_conditions.coulomb_violation_sums`. Everything is recomputed
from (M, W, u⁻, u⁺, Λ) and the local problem the law posed from them; nothing reads the
solver's velocity or reaction.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .coulomb_conditions import coulomb_violation_sums
from .friction import natural_map
from .jit import inline_kernel, kernel
from .residuals import SCALE_RANGE, dense_momentum

COULOMB_RESIDUALS = ("momentum", "natural_map", "cone", "complementarity", "non_penetration")
"""The order of :func:`coulomb_residuals`' output."""


class FrictionalSystem(NamedTuple):
    """A frictional impact's operators, dense, and its law's coefficients.

    Attributes
    ----------
    M : (n, n) ndarray
    Wt : (d·m, n) ndarray
        Wᵀ.
    MinvW : (n, d·m) ndarray
        M⁻¹W solved for the certificate (:func:`impactqp.model.residuals.certificate_operand`).
    G : (d·m, d·m) ndarray
        The Delassus matrix in contact units, G̃ = DWᵀM⁻¹WD, D = diag(1/s).
    s : (d·m,) ndarray
        The unit s_c of the contact of each entry.
    mu, e : (m,) ndarray
        Friction and restitution coefficients per contact.
    d : int
        Entries per contact (2 or 3).
    """

    M: np.ndarray
    Wt: np.ndarray
    MinvW: np.ndarray
    G: np.ndarray
    s: np.ndarray
    mu: np.ndarray
    e: np.ndarray
    d: int


class LocalFreeVelocity(NamedTuple):
    """The local problem's free velocity as the law posed it from u⁻.

    Attributes
    ----------
    q : (d·m,) ndarray
        q̃ = D(Wᵀu⁻ + e∘γ⁻_n), in contact units.
    q_unit : (d·m,) ndarray
        q̂ = 2⁻ᵏq̃, the scale-first form the friction certificate judges.
    k : int
        The scale-first exponent.
    """

    q: np.ndarray
    q_unit: np.ndarray
    k: int


class FrictionalAnswer(NamedTuple):
    """An answer (u⁻, u⁺, Λ) to judge, with scratch of n + 2·d·m floats."""

    u_minus: np.ndarray
    u_plus: np.ndarray
    impulses: np.ndarray
    work: np.ndarray


@inline_kernel
def certificate_ratio(num, den):
    """num/den as the friction certificate reports it: 0 when num is 0, +inf for a NaN or a
    non-positive den; :mod:`impactqp.model.friction` calls it as plain Python."""
    if num == 0.0:
        return 0.0
    v = num / den if den > 0.0 else np.inf
    return v if v == v else np.inf


@inline_kernel
def _norm(x):
    """‖x‖₂ = √(x·x)."""
    total = 0.0
    for i in range(x.size):
        total += x[i] * x[i]
    return np.sqrt(total)


FRICTION_FIGURES = ("natural_map", "velocity", "cone", "dual_cone", "complementarity",
                    "siconos_error", "penetration")
"""The order of :func:`friction_figures`' output: the five residuals of a local problem's
certificate, then the two figures it reports beside them."""


@kernel(interpretable=True)
def friction_figures(r, u, q, mu, d, residual, out):
    """The figures of a local frictional problem's certificate in contact units
    (:data:`FRICTION_FIGURES`, defined in :func:`impactqp.model.friction.certify_friction`,
    docs/theory.md §15) into ``out``, from the reaction r̂, the velocity û = W̃r̂ + q̂
    recomputed by the caller, q̂, μ, d and ``residual`` = (‖F‖, ‖û_given − û‖): the norm of
    the natural map F(r̂, û) (:func:`impactqp.kernels.friction.natural_map`, which the caller
    evaluates: the solvers share it, the figures computed here do not) and the mismatch of a
    given velocity (0 when none was given)."""
    f_norm, mismatch = residual
    q_norm = _norm(q)
    q_scale = q_norm if q_norm > 0.0 else 1.0
    r_norm = _norm(r)
    cone, dual, comp = coulomb_violation_sums(r, u, mu, d)
    penetration = 0.0
    for c in range(mu.size):
        below = 0.0 if u[c * d] >= 0.0 else u[c * d]  # keeps a NaN
        penetration += below * below
    out[0] = certificate_ratio(f_norm, q_scale)
    out[1] = certificate_ratio(mismatch, q_scale)
    out[2] = certificate_ratio(np.sqrt(cone), max(q_scale, r_norm))
    out[3] = certificate_ratio(np.sqrt(dual), q_scale)
    out[4] = certificate_ratio(np.sqrt(comp), q_scale)
    out[5] = certificate_ratio(f_norm, max(q_norm, r_norm, _norm(u)))
    out[6] = certificate_ratio(np.sqrt(penetration), q_scale)


@kernel(interpretable=True)
def coulomb_residuals(system, local, answer, out):
    """The five residuals of :data:`COULOMB_RESIDUALS` into ``out``; False (``out``
    untouched) when max|u⁻ᵢ| lies outside :data:`~impactqp.kernels.residuals.SCALE_RANGE`,
    where the caller rescales first (docs/theory.md §8).

    - momentum ‖u⁺ − u⁻ − M⁻¹WΛ‖/V;
    - natural_map ‖r̂ − P_K(r̂ − ũ)‖/‖q̂‖, cone and complementarity of the local problem in
      contact units (as :func:`impactqp.model.friction.certify_friction` defines them) at
      r̂ = 2⁻ᵏ s∘Λ, û = G̃r̂ + q̂;
    - non_penetration ‖(−U_n/s)₊‖/‖q̃‖, U_n = (Wᵀu⁺)_n + e(Wᵀu⁻)_n, of u⁺ itself.
    """
    um, up, lam, work = answer
    top = 0.0
    for i in range(um.size):
        top = max(top, abs(um[i]))
    if not SCALE_RANGE[0] < top < SCALE_RANGE[1]:
        return False
    n, size, d = um.size, lam.size, system.d
    V, momentum = dense_momentum(system.M, system.MinvW, um, up, lam, 1.0, work[:n])
    r = work[n:n + size]
    u = work[n + size:n + 2 * size]
    for i in range(size):
        r[i] = math.ldexp(system.s[i] * lam[i], -local.k)
    for i in range(size):
        total = local.q_unit[i]
        for j in range(size):
            total += system.G[i, j] * r[j]
        u[i] = total
    q_norm = _norm(local.q_unit)
    q_scale = q_norm if q_norm > 0.0 else 1.0
    F = natural_map(r, u, system.mu, d)
    cone, _, comp = coulomb_violation_sums(r, u, system.mu, d)
    penetration = 0.0
    for c in range(system.mu.size):
        k = c * d
        after = 0.0
        before = 0.0
        for j in range(n):
            after += system.Wt[k, j] * up[j]
            before += system.Wt[k, j] * um[j]
        shifted = (after + system.e[c] * before) / system.s[k]
        below = 0.0 if shifted >= 0.0 else shifted  # keeps a NaN
        penetration += below * below
    posed = _norm(local.q)
    out[0] = momentum / V
    out[1] = certificate_ratio(_norm(F), q_scale)
    out[2] = certificate_ratio(np.sqrt(cone), max(q_scale, _norm(r)))
    out[3] = certificate_ratio(np.sqrt(comp), q_scale)
    out[4] = np.sqrt(penetration) / (posed if posed > 0.0 else 1.0)
    return True
