"""The residuals of an impact law's certificate: their one definition (docs/theory.md §8).

For the laws ``0 ≤ Λ ⟂ w = γ⁺ + Eγ⁻ ≥ 0`` with ``M(u⁺ − u⁻) = WΛ``, in the units of
docs/theory.md §8 (V = ‖u⁻‖, contact velocities against sᵢV, impulses against V/sᵢ):

=================  ==========================================
momentum           ‖u⁺ − u⁻ − M⁻¹WΛ‖ / V
impulse sign       maxᵢ (−Λᵢsᵢ)₊ / V
law feasibility    maxᵢ (−wᵢ/sᵢ)₊ / V
complementarity    maxᵢ |Λᵢwᵢ| / V²
energy balance     2ε|⟨z, u⁻ − z⟩| / V², z = (u⁺ + εu⁻)/(1 + ε)   (Moreau's law)
duality gap        Σᵢ |Λᵢwᵢ| / V² + momentum²                      (Moreau's law)
=================  ==========================================

Two steps compute them, whatever stores M and W: :func:`fold_contacts` reduces the contacts
(in any number of pieces) to four numbers, and :func:`finish` turns those, V, the momentum
norm and ⟨z, u⁻ − z⟩ into the six residuals. The operator passes that produce the inputs
are :func:`dense_residuals` (dense M, W), :func:`chain_residuals` (a 1-D chain in one O(N)
loop without a matrix) and, for sparse structures, numpy products in
:mod:`impactqp.model.residuals`. A NaN anywhere gives NaN residuals, which fail.
"""

from __future__ import annotations

import numpy as np

from .jit import inline_kernel, kernel, read_only

RESIDUALS = ("momentum", "impulse_sign", "law_feasibility", "complementarity",
             "energy_balance", "duality_gap")
"""The order of the residuals in every output row (the last two NaN for laws other than
Moreau's)."""

SCALE_RANGE = (1e-60, 1e60)
"""Largest entries of u⁻ whose squares need no rescaling; outside, inputs are divided by it."""


@kernel(internal=True)
def _low(a, b):
    """min(a, b) that keeps a NaN of either."""
    return a if (a < b or a != a) else b


@kernel(internal=True)
def _high(a, b):
    """max(a, b) that keeps a NaN of either."""
    return a if (a > b or a != a) else b


NEW_FOLD = (np.inf, np.inf, 0.0, 0.0)
"""The neutral fold of the contacts: (min Λᵢsᵢ, min wᵢ/sᵢ, max |Λᵢwᵢ|, Σ |Λᵢwᵢ|)."""


@kernel(internal=True)
def fold_contact(acc, lam, w, s):
    """``acc`` (see :data:`NEW_FOLD`) with one more contact: impulse Λ, w = γ⁺ + Eγ⁻, scale s."""
    p = abs(lam * w)
    return (_low(acc[0], lam * s), _low(acc[1], w / s), _high(acc[2], p), acc[3] + p)


@kernel
def fold_contacts(lam, w, s):
    """The fold of the contacts of the arrays Λ, w and s."""
    acc = NEW_FOLD
    for i in range(lam.size):
        acc = fold_contact(acc, lam[i], w[i], s[i])
    return acc


@inline_kernel
def residual_values(V, momentum_norm, acc, eps, moreau, cross):
    """The six residuals (order :data:`RESIDUALS`) from V, ‖u⁺ − u⁻ − M⁻¹WΛ‖, the fold of the
    contacts and, for Moreau's law (``moreau``), ε and cross = ⟨z, u⁻ − z⟩; the last two
    are NaN for other laws. One division (1/V): the others are products, which a loop over
    many impacts runs in SIMD at a fraction of a division's cost."""
    unit = 1.0 / V
    unit2 = unit * unit
    momentum = momentum_norm * unit
    sign = _high(0.0, -acc[0] * unit)
    law = _high(0.0, -acc[1] * unit)
    complementarity = acc[2] * unit2
    if moreau:
        return (momentum, sign, law, complementarity, 2.0 * eps * abs(cross) * unit2,
                acc[3] * unit2 + momentum * momentum)
    return (momentum, sign, law, complementarity, np.nan, np.nan)


@inline_kernel
def finish(V, momentum_norm, acc, eps, moreau, cross, out):
    """:func:`residual_values` written into ``out``."""
    values = residual_values(V, momentum_norm, acc, eps, moreau, cross)
    for i in range(6):
        out[i] = values[i]


@kernel(internal=True)
def _largest(x):
    """max |xᵢ| (NaN kept), 0 for no entries."""
    c = 0.0
    for i in range(x.size):
        c = _high(c, abs(x[i]))
    return c


@kernel
def unit_of(um, up, lam):
    """The divisor of docs/theory.md §8: 1 when the largest entry of u⁻ is within
    :data:`SCALE_RANGE`, else that entry (for u⁻ = 0 the largest entry of u⁺ and Λ, or 1)."""
    c = _largest(um)
    if SCALE_RANGE[0] < c < SCALE_RANGE[1]:
        return 1.0
    if c == 0.0:
        c = _high(_largest(up), _largest(lam))
    return c if c > 0.0 else 1.0


@kernel(internal=True)
def velocity_unit(V2_minus, V2_plus):
    """V = ‖u⁻‖, or for u⁻ = 0 the answer's own size, at least 1 (docs/theory.md §8); one
    square root, of the one square it returns."""
    V = np.sqrt(V2_minus if V2_minus > 0.0 else _high(V2_plus, 0.0))
    return V if V2_minus > 0.0 else _high(V, 1.0)


@inline_kernel
def _scaled_quadratic(M, x, y, f):
    """(fx)ᵀM(fy), scaled before the products so that nothing leaves the float range."""
    total = 0.0
    for i in range(x.size):
        row = 0.0
        for j in range(y.size):
            row += M[i, j] * (y[j] * f)
        total += (x[i] * f) * row
    return total


@inline_kernel
def dense_momentum(M, MinvW, um, up, lam, f, d):
    """(V, ‖u⁺ − u⁻ − M⁻¹WΛ‖) of the inputs multiplied by f, with dense M and M⁻¹W (the
    momentum residual is their ratio, docs/theory.md §8); ``d`` is scratch of n floats."""
    for i in range(um.size):  # u⁺ − u⁻ − M⁻¹WΛ
        total = (up[i] - um[i]) * f
        for j in range(lam.size):
            total -= MinvW[i, j] * (lam[j] * f)
        d[i] = total
    V = velocity_unit(_scaled_quadratic(M, um, um, f), _scaled_quadratic(M, up, up, f))
    return V, np.sqrt(_high(_scaled_quadratic(M, d, d, 1.0), 0.0))


@kernel(interpretable=True)
def dense_residuals(M, Wt, MinvW, s, um, up, lam, E, eps, moreau, out, work):
    """The residuals of one impact with dense M (n × n), Wᵀ (m × n), M⁻¹W (n × m), the
    contact scales s and the law's E (m × m; for Moreau's law, ``moreau``, E = εI is used and
    E may be empty) into ``out`` (order :data:`RESIDUALS`); ``work`` is scratch of at least
    2n + 2m floats (a loop over impacts allocates nothing)."""
    # inputs read-only: one compiled signature for these callers and the Moreau–Jean loop's
    dense_step_residuals(read_only(M), read_only(Wt), read_only(MinvW), read_only(s),
                         read_only(um), read_only(up), read_only(lam), read_only(um),
                         read_only(E), eps, moreau, out, work)


@kernel
def dense_step_residuals(M, Wt, MinvW, s, um, up, lam, ur, E, eps, moreau, out, work):
    """:func:`dense_residuals` with the restitution acting on the contact velocities of
    ``ur`` instead of u⁻: w = γ⁺ + E Wᵀur. An impact has ur = u⁻; a Moreau–Jean step has
    u⁻ = v_free and ur = v_k (``0 ≤ Λ ⟂ γ_{k+1} + Eγ_k``, docs/theory.md §14)."""
    n, m = um.size, lam.size
    f = 1.0 / unit_of(um, up, lam)
    g = work[n:n + m]
    w = work[n + m:n + 2 * m]
    z = work[n + 2 * m:2 * n + 2 * m]
    V, momentum = dense_momentum(M, MinvW, um, up, lam, f, work[:n])
    for i in range(m):  # γ⁻ (of ur) and γ⁺
        gm = 0.0
        gp = 0.0
        for j in range(n):
            gm += Wt[i, j] * (ur[j] * f)
            gp += Wt[i, j] * (up[j] * f)
        g[i] = gm
        w[i] = gp
    acc = NEW_FOLD
    for i in range(m):  # w = γ⁺ + Eγ⁻
        if moreau:
            w[i] += eps * g[i]
        else:
            for j in range(m):
                w[i] += E[i, j] * g[j]
        acc = fold_contact(acc, lam[i] * f, w[i], s[i])
    cross = 0.0
    if moreau:  # ⟨z, u⁻ − z⟩ with z = (u⁺ + εu⁻)/(1 + ε)
        for i in range(n):
            z[i] = (up[i] + eps * um[i]) * f / (1.0 + eps)
        for i in range(n):
            row = 0.0
            for j in range(n):
                row += M[i, j] * (um[j] * f - z[j])
            cross += z[i] * row
    finish(V, momentum, acc, eps, moreau, cross, out)


@kernel
def dense_residual_rows(M, Wt, MinvW, s, Um, Up, Lam, E, eps, moreau):
    """:func:`dense_residuals` for every row of (U⁻, U⁺, Λ): a (k, 6) array."""
    out = np.empty((Um.shape[0], 6))
    work = np.empty(2 * Um.shape[1] + 2 * Lam.shape[1])
    for r in range(Um.shape[0]):
        dense_residuals(M, Wt, MinvW, s, Um[r], Up[r], Lam[r], E, eps, moreau, out[r], work)
    return out


NEW_SUMS = (0.0, 0.0, 0.0, 0.0, 0.0)
"""The neutral sums of a chain's balls (see :func:`ball_terms`)."""


@inline_kernel
def ball_terms(sums, a, b, mass, inverse, lam_in, lam_out):
    """``sums`` = (‖u⁻‖²_M, ‖u⁺‖²_M, Σ rⱼ²/mⱼ, ⟨t, u⁻⟩_M, ‖t‖²_M) of a chain with one more
    ball: u⁻ⱼ = a, u⁺ⱼ = b, its mass and 1/mass, the impulses left (L_j) and right
    (L_{j+1}) of it, 0 at a free end; t = b − a, rⱼ = mⱼtⱼ − (L_j − L_{j+1})."""
    V2m, V2p, q, mt_u, mt_t = sums
    t = b - a
    r = mass * t
    V2m += mass * a * a
    V2p += mass * b * b
    mt_u += r * a
    mt_t += r * t
    r = r - lam_in + lam_out
    q += r * r * inverse
    return (V2m, V2p, q, mt_u, mt_t)


@inline_kernel
def gap_velocity(b_left, g_left, b, g, E):
    """w = γ⁺ + Eγ⁻ of the contact between a ball with (u⁺, restituted velocity) =
    (b_left, g_left) and the next one's (b, g); a wall is a ball at rest (0, 0)."""
    return b - b_left + E * (g - g_left)


@inline_kernel
def chain_values(sums, acc, eps, moreau):
    """The six residuals of a chain from its :func:`ball_terms` sums and contact fold, with
    ⟨z, u⁻ − z⟩ = −(⟨t, u⁻⟩ + ‖t‖²/(1+ε))/(1+ε) in the kinetic metric."""
    V2m, V2p, q, mt_u, mt_t = sums
    h = 1.0 / (1.0 + eps)  # the same for every row of a batch: computed once
    cross = -(mt_u + mt_t * h) * h if moreau else 0.0
    return residual_values(velocity_unit(V2m, V2p), np.sqrt(q), acc, eps, moreau, cross)


@inline_kernel
def in_range(top):
    """Whether a largest entry |u⁻ⱼ| lies within :data:`SCALE_RANGE` (the residuals are then
    computed on the inputs as they are: :func:`unit_of` is 1)."""
    return SCALE_RANGE[0] < top < SCALE_RANGE[1]


@kernel(internal=True)
def _chain_pass(um, up, lam, ur, masses, inverse, s, left_wall, right_wall, E, eps, moreau,
                f, out):
    """:func:`chain_step_residuals` with the inputs multiplied by f; returns whether
    max|u⁻ⱼ| (of the inputs as given) is within :data:`SCALE_RANGE`."""
    n = um.size
    lo = 0 if left_wall else 1  # Λ = (L_lo, L_lo+1, …)
    sums = NEW_SUMS
    acc = NEW_FOLD
    b_left = 0.0
    g_left = 0.0
    top = 0.0
    for j in range(n):
        top = max(top, abs(um[j]))
        a = um[j] * f
        b = up[j] * f
        g = ur[j] * f  # the velocity the restitution acts on
        k = j - lo  # the impulse left of ball j
        lam_in = lam[k] * f if k >= 0 else 0.0
        lam_out = lam[k + 1] * f if k + 1 < lam.size else 0.0
        sums = ball_terms(sums, a, b, masses[j], inverse[j], lam_in, lam_out)
        if k >= 0:  # the gap (or the left wall) left of ball j
            acc = fold_contact(acc, lam_in, gap_velocity(b_left, g_left, b, g, E), s[k])
        b_left = b
        g_left = g
    if right_wall:
        last = lam.size - 1
        acc = fold_contact(acc, lam[last] * f, gap_velocity(b_left, g_left, 0.0, 0.0, E),
                           s[last])
    values = chain_values(sums, acc, eps, moreau)
    for i in range(6):
        out[i] = values[i]
    return in_range(top)


@kernel(interpretable=True)
def chain_residuals(um, up, lam, masses, inverse, s, left_wall, right_wall, E, eps, moreau,
                    out):
    """The residuals of one impact of a 1-D chain (docs/theory.md §5, §8) in one O(N) loop.

    ``inverse`` holds 1/mⱼ (a product is cheaper than a division in the loop). Contacts are
    the gaps between neighbours, with a wall contact first (γ = u₁) and last
    (γ = −u_N) where there are walls; E is the scalar restitution. Each ball adds its
    :func:`ball_terms`, each contact its :func:`fold_contact`, and :func:`chain_values`
    makes the residuals. Inputs are divided by :func:`unit_of` only when max|u⁻ⱼ| is
    outside :data:`SCALE_RANGE` (the pass is then made again).
    """
    # inputs read-only: one compiled signature for these callers and the Moreau–Jean loop's
    chain_step_residuals(read_only(um), read_only(up), read_only(lam), read_only(um),
                         read_only(masses), read_only(inverse), read_only(s), left_wall,
                         right_wall, E, eps, moreau, out)


@kernel
def chain_step_residuals(um, up, lam, ur, masses, inverse, s, left_wall, right_wall, E, eps,
                         moreau, out):
    """:func:`chain_residuals` with the restitution acting on the contact velocities of
    ``ur`` instead of u⁻ (a Moreau–Jean step: ur = v_k, docs/theory.md §14)."""
    if not _chain_pass(um, up, lam, ur, masses, inverse, s, left_wall, right_wall, E, eps,
                       moreau, 1.0, out):
        _chain_pass(um, up, lam, ur, masses, inverse, s, left_wall, right_wall, E, eps,
                    moreau, 1.0 / unit_of(um, up, lam), out)


@kernel
def finish_rows(V, momentum_norms, Lam, Wc, s, eps, moreau, cross):
    """:func:`fold_contacts` and :func:`finish` for rows whose products were formed outside
    (sparse structures): V, the momentum norms and ``cross`` per row, Λ and w as (k, m)."""
    out = np.empty((V.size, 6))
    for r in range(V.size):
        acc = fold_contacts(Lam[r], Wc[r], s)
        finish(V[r], momentum_norms[r], acc, eps, moreau, cross[r], out[r])
    return out
