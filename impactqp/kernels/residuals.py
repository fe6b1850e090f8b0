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

from .jit import inline_kernel, kernel

RESIDUALS = ("momentum", "impulse_sign", "law_feasibility", "complementarity",
             "energy_balance", "duality_gap")
"""The order of the residuals in every output row (the last two NaN for laws other than
Moreau's)."""

SCALE_RANGE = (1e-60, 1e60)
"""Largest entries of u⁻ whose squares need no rescaling; outside, inputs are divided by it."""


@inline_kernel
def _low(a, b):
    """min(a, b) that keeps a NaN of either."""
    return a if (a < b or a != a) else b


@inline_kernel
def _high(a, b):
    """max(a, b) that keeps a NaN of either."""
    return a if (a > b or a != a) else b


NEW_FOLD = (np.inf, np.inf, 0.0, 0.0)
"""The neutral fold of the contacts: (min Λᵢsᵢ, min wᵢ/sᵢ, max |Λᵢwᵢ|, Σ |Λᵢwᵢ|)."""


@inline_kernel
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
def finish(V, momentum_norm, acc, eps, moreau, cross, out):
    """The six residuals (order :data:`RESIDUALS`) from V, ‖u⁺ − u⁻ − M⁻¹WΛ‖, the fold of the
    contacts and, for Moreau's law (``moreau``), ε and cross = ⟨z, u⁻ − z⟩."""
    V2 = V * V
    out[0] = momentum_norm / V
    out[1] = _high(0.0, -acc[0] / V)
    out[2] = _high(0.0, -acc[1] / V)
    out[3] = acc[2] / V2
    if moreau:
        out[4] = 2.0 * eps * abs(cross) / V2
        out[5] = acc[3] / V2 + out[0] * out[0]
    else:
        out[4] = np.nan
        out[5] = np.nan


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


@inline_kernel
def velocity_unit(V2_minus, V2_plus):
    """V = ‖u⁻‖, or for u⁻ = 0 the answer's own size, at least 1 (docs/theory.md §8)."""
    if V2_minus > 0.0:
        return np.sqrt(V2_minus)
    return _high(np.sqrt(_high(V2_plus, 0.0)), 1.0)


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
    dense_step_residuals(M, Wt, MinvW, s, um, up, lam, um, E, eps, moreau, out, work)


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


@inline_kernel
def _chain_pass(um, up, lam, ur, masses, inverse, s, left_wall, right_wall, E, eps, moreau,
                f, out):
    """:func:`chain_step_residuals` with the inputs multiplied by f."""
    n = um.size
    lo = 0 if left_wall else 1  # Λ = (L_lo, L_lo+1, …)
    V2m = 0.0
    V2p = 0.0
    q = 0.0
    mt_u = 0.0
    mt_t = 0.0
    acc = NEW_FOLD
    b_left = 0.0
    g_left = 0.0
    for j in range(n):
        a = um[j] * f
        b = up[j] * f
        g = ur[j] * f  # the velocity the restitution acts on
        t = b - a
        mj = masses[j]
        V2m += mj * a * a
        V2p += mj * b * b
        r = mj * t
        mt_u += r * a
        mt_t += r * t
        k = j - lo  # the impulse left of ball j
        if 0 <= k < lam.size:
            r -= lam[k] * f
        if 0 <= k + 1 < lam.size:
            r += lam[k + 1] * f
        q += r * r * inverse[j]
        if j > 0:  # the gap left of ball j
            acc = fold_contact(acc, lam[k] * f, b - b_left + E * (g - g_left), s[k])
        elif left_wall:
            acc = fold_contact(acc, lam[0] * f, b + E * g, s[0])
        b_left = b
        g_left = g
    if right_wall:
        last = lam.size - 1
        acc = fold_contact(acc, lam[last] * f, -(b_left + E * g_left), s[last])
    V = velocity_unit(V2m, V2p)
    cross = -(mt_u + mt_t / (1.0 + eps)) / (1.0 + eps) if moreau else 0.0
    finish(V, np.sqrt(q), acc, eps, moreau, cross, out)


@inline_kernel(interpretable=True)
def chain_residuals(um, up, lam, masses, inverse, s, left_wall, right_wall, E, eps, moreau,
                    out):
    """The residuals of one impact of a 1-D chain (docs/theory.md §5, §8) in one O(N) loop.

    ``inverse`` holds 1/mⱼ (a product is cheaper than a division in the loop). Contacts are
    the gaps between neighbours, with a wall contact first (γ = u₁) and last
    (γ = −u_N) where there are walls; E is the scalar restitution. With t = u⁺ − u⁻ and L_j
    the impulse left of ball j, the momentum is Σⱼ rⱼ²/mⱼ with rⱼ = mⱼtⱼ − (L_j − L_{j+1}),
    and ⟨z, u⁻ − z⟩ = −(⟨t, u⁻⟩ + ‖t‖²/(1+ε))/(1+ε) in the kinetic metric. Inputs are
    divided by :func:`unit_of` only when max|u⁻ⱼ| is outside :data:`SCALE_RANGE`.
    """
    chain_step_residuals(um, up, lam, um, masses, inverse, s, left_wall, right_wall, E, eps,
                         moreau, out)


@inline_kernel
def in_unit_range(um):
    """Whether the largest entry of u⁻ lies within :data:`SCALE_RANGE` (then the residuals
    are computed on the inputs as they are: :func:`unit_of` is 1)."""
    top = 0.0
    for j in range(um.size):
        top = max(top, abs(um[j]))
    return SCALE_RANGE[0] < top < SCALE_RANGE[1]


@inline_kernel
def chain_step_residuals(um, up, lam, ur, masses, inverse, s, left_wall, right_wall, E, eps,
                         moreau, out):
    """:func:`chain_residuals` with the restitution acting on the contact velocities of
    ``ur`` instead of u⁻ (a Moreau–Jean step: ur = v_k, docs/theory.md §14)."""
    f = 1.0 if in_unit_range(um) else 1.0 / unit_of(um, up, lam)
    _chain_pass(um, up, lam, ur, masses, inverse, s, left_wall, right_wall, E, eps, moreau,
                f, out)


@kernel
def chain_residual_rows(Um, Up, Lam, masses, inverse, s, left_wall, right_wall, E, eps,
                        moreau):
    """:func:`chain_residuals` for every row of (U⁻, U⁺, Λ): a (k, 6) array (a view of the
    residual columns of :func:`chain_residual_columns`)."""
    out = np.empty((6, Um.shape[0]))
    chain_residual_columns(Um, Up, Lam, masses, inverse, s, left_wall, right_wall, E, eps,
                           moreau, out)
    return out.T


@kernel
def chain_residual_columns(Um, Up, Lam, masses, inverse, s, left_wall, right_wall, E, eps,
                           moreau, out):
    """:func:`chain_residuals` for every row of (U⁻, U⁺, Λ), residual i of row r into
    ``out[i, r]`` (one contiguous column per residual: a batch keeps them as they are).

    The rows within :data:`SCALE_RANGE` are passed first with the unit 1, the others after
    them with their :func:`unit_of`: a loop that may call the rescaling at every row costs
    twice as much per row on short chains (measured on 3 balls: ~120 → ~55 ns)."""
    k = Um.shape[0]
    row = np.empty(6)
    plain = np.empty(k, dtype=np.bool_)
    for r in range(k):
        plain[r] = in_unit_range(Um[r])
    for r in range(k):
        if plain[r]:
            _chain_pass(Um[r], Up[r], Lam[r], Um[r], masses, inverse, s, left_wall,
                        right_wall, E, eps, moreau, 1.0, row)
            for i in range(6):
                out[i, r] = row[i]
    for r in range(k):
        if not plain[r]:
            chain_residuals(Um[r], Up[r], Lam[r], masses, inverse, s, left_wall, right_wall,
                            E, eps, moreau, row)
            for i in range(6):
                out[i, r] = row[i]


@kernel
def finish_rows(V, momentum_norms, Lam, Wc, s, eps, moreau, cross):
    """:func:`fold_contacts` and :func:`finish` for rows whose products were formed outside
    (sparse structures): V, the momentum norms and ``cross`` per row, Λ and w as (k, m)."""
    out = np.empty((V.size, 6))
    for r in range(V.size):
        acc = fold_contacts(Lam[r], Wc[r], s)
        finish(V[r], momentum_norms[r], acc, eps, moreau, cross[r], out[r])
    return out
