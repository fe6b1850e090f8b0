"""The chain certificate (docs/theory.md §5, §8) of many impacts of one chain, rows side by
side: the batch kernels.

:func:`impactqp.kernels.residuals.chain_residuals` passes over one chain's balls. Here a block
of rows is passed ball by ball, each step over all the block's rows at once (struct of
arrays: one row of ``state`` per running sum, one entry per row of the batch), so the loop
over the rows has no branch and no loop-carried dependency and LLVM turns it into SIMD code.
Each step calls the one definition of the formulas (:func:`~impactqp.kernels.residuals.ball_terms`,
:func:`~impactqp.kernels.residuals.gap_velocity`,
:func:`~impactqp.kernels.residuals.fold_contact`,
:func:`~impactqp.kernels.residuals.chain_values`), in the order the single pass calls them,
so a row's residuals are those of ``chain_residuals`` bit for bit. The certificate reads u⁻,
u⁺ and Λ as the batch holds them, nothing of the solve.

The solve of a short chain's rows (:func:`chain_impact_rows`) passes blocks of rows the same
way, formula by formula; it shares no number with the certificate.
"""

from __future__ import annotations

import numpy as np

from .jit import inline_kernel, kernel, read_only
from .residuals import (
    NEW_FOLD,
    NEW_SUMS,
    ball_terms,
    chain_residuals,
    chain_values,
    fold_contact,
    gap_velocity,
    in_range,
)

BLOCK = 256
"""Rows passed together: their running sums (:data:`STATE` rows of ``BLOCK`` floats, 32 kB)
stay in the L1 cache while the block's balls are passed."""

STATE = 16
"""Rows of the block's state: the five sums of :func:`~impactqp.kernels.residuals.ball_terms`
(0–4), the four of the contact fold (5–8), u⁺ and u⁻ of the previous ball (9, 10), the
largest |u⁻ⱼ| (11), u⁻ⱼ, u⁺ⱼ and the impulse right of ball j gathered from the rows (12–14),
the impulse left of ball j (15)."""


@kernel
def chain_residual_rows(Um, Up, Lam, masses, inverse, s, left_wall, right_wall, E, eps,
                        moreau):
    """:func:`~impactqp.kernels.residuals.chain_residuals` for every row of (U⁻, U⁺, Λ): a
    (k, 6) array (a view of the residual columns of :func:`chain_residual_columns`)."""
    out = np.empty((6, Um.shape[0]))
    chain_residual_columns(Um, Up, Lam, masses, inverse, s, left_wall, right_wall, E, eps,
                           moreau, out)
    return out.T


@kernel
def chain_residual_columns(Um, Up, Lam, masses, inverse, s, left_wall, right_wall, E, eps,
                           moreau, out):
    """:func:`~impactqp.kernels.residuals.chain_residuals` for every row of (U⁻, U⁺, Λ),
    residual i of row r into ``out[i, r]`` (one contiguous column per residual: a batch
    keeps them as they are).

    Blocks of :data:`BLOCK` rows are passed with the unit 1; the rows whose largest |u⁻ⱼ|
    is outside the unit range are then passed again one by one by ``chain_residuals``, which
    rescales them."""
    k = Um.shape[0]
    state = np.empty(STATE * BLOCK)
    row = np.empty(6)
    walls = (left_wall, right_wall)
    law = (E, eps, moreau)
    for start in range(0, k, BLOCK):
        stop = min(start + BLOCK, k)
        _block(Um[start:stop], Up[start:stop], Lam[start:stop], masses, inverse, s, walls,
               law, state, out[:, start:stop])
        for i in range(stop - start):
            if not in_range(state[11 * BLOCK + i]):
                r = start + i
                # u⁻ read-only, as solve_chain passes it: one signature
                chain_residuals(read_only(Um[r]), Up[r], Lam[r], masses, inverse, s,
                                left_wall, right_wall, E, eps, moreau, row)
                for c in range(6):
                    out[c, r] = row[c]


@inline_kernel
def _sums(state, i):
    """Row i's sums of :func:`~impactqp.kernels.residuals.ball_terms` (state rows 0–4)."""
    return (state[i], state[BLOCK + i], state[2 * BLOCK + i], state[3 * BLOCK + i],
            state[4 * BLOCK + i])


@inline_kernel
def _fold(state, i):
    """Row i's contact fold (state rows 5–8)."""
    return (state[5 * BLOCK + i], state[6 * BLOCK + i], state[7 * BLOCK + i],
            state[8 * BLOCK + i])


@inline_kernel
def _put(state, first, values, i):
    """Write the 4- or 5-tuple ``values`` into state rows first, first + 1, … at row i
    (element by element: a tuple indexed in a loop keeps LLVM from vectorizing)."""
    state[first * BLOCK + i] = values[0]
    state[(first + 1) * BLOCK + i] = values[1]
    state[(first + 2) * BLOCK + i] = values[2]
    state[(first + 3) * BLOCK + i] = values[3]
    if len(values) == 5:
        state[(first + 4) * BLOCK + i] = values[-1]


@inline_kernel
def _block(Um, Up, Lam, masses, inverse, s, walls, law, state, out):
    """The residuals of the rows of one block, unit 1, into ``out`` (6 × rows)."""
    rows, n = Um.shape
    m = Lam.shape[1]
    left_wall, right_wall = walls
    E, eps, moreau = law
    lo = 0 if left_wall else 1
    _start(state, Lam, left_wall, rows)
    for j in range(n):
        k = j - lo  # the impulse left of ball j
        _gather(state, Um, Up, Lam, j, k + 1, rows)
        _balls(state, masses[j], inverse[j], rows)
        if k >= 0:  # the gap (or the left wall) left of ball j
            _contacts(state, s[k], E, rows)
        _shift(state, rows)
    if right_wall:  # the wall is a ball at rest; L_N is the last impulse
        _gather(state, Um, Up, Lam, np.int64(-1), m, rows)  # not a literal: one signature
        _contacts(state, s[m - 1], E, rows)
    _values(state, eps, moreau, out, rows)


@kernel(internal=True)
def _start(state, Lam, left_wall, rows):
    """The neutral sums and fold, a previous ball at rest, L_0 (0 left of a free ball)."""
    for i in range(rows):
        _put(state, 0, NEW_SUMS, i)
        _put(state, 5, NEW_FOLD, i)
        state[9 * BLOCK + i] = 0.0
        state[10 * BLOCK + i] = 0.0
        state[11 * BLOCK + i] = 0.0
        state[15 * BLOCK + i] = Lam[i, 0] if left_wall else 0.0


@kernel(internal=True)
def _gather(state, Um, Up, Lam, j, k, rows):
    """u⁻ⱼ, u⁺ⱼ (0 for j = −1, a wall at rest) and the impulse Λ_k (0 for k past the end)
    of each row into state rows 12–14: the loops after it read columns."""
    m = Lam.shape[1]
    for i in range(rows):
        state[12 * BLOCK + i] = Um[i, j] if j >= 0 else 0.0
        state[13 * BLOCK + i] = Up[i, j] if j >= 0 else 0.0
        state[14 * BLOCK + i] = Lam[i, k] if k < m else 0.0


@kernel(internal=True)
def _balls(state, mass, inverse, rows):
    """Each row's sums with its ball j, and its largest |u⁻ⱼ| so far."""
    for i in range(rows):
        a = state[12 * BLOCK + i]
        _put(state, 0, ball_terms(_sums(state, i), a, state[13 * BLOCK + i], mass, inverse,
                                  state[15 * BLOCK + i], state[14 * BLOCK + i]), i)
        state[11 * BLOCK + i] = max(state[11 * BLOCK + i], abs(a))


@kernel(internal=True)
def _contacts(state, scale, E, rows):
    """Each row's contact fold with the contact between its previous ball (state rows 9,
    10) and its current one (12, 13) of impulse L_j (row 15): the restitution acts on u⁻."""
    for i in range(rows):
        w = gap_velocity(state[9 * BLOCK + i], state[10 * BLOCK + i], state[13 * BLOCK + i],
                         state[12 * BLOCK + i], E)
        _put(state, 5, fold_contact(_fold(state, i), state[15 * BLOCK + i], w, scale), i)


@kernel(internal=True)
def _shift(state, rows):
    """Ball j becomes the previous one, L_{j+1} its left impulse."""
    for i in range(rows):
        state[9 * BLOCK + i] = state[13 * BLOCK + i]
        state[10 * BLOCK + i] = state[12 * BLOCK + i]
        state[15 * BLOCK + i] = state[14 * BLOCK + i]


@kernel(internal=True)
def _values(state, eps, moreau, out, rows):
    """Each row's six residuals from its sums and fold, into the columns of ``out``."""
    for i in range(rows):
        values = chain_values(_sums(state, i), _fold(state, i), eps, moreau)
        out[0, i] = values[0]
        out[1, i] = values[1]
        out[2, i] = values[2]
        out[3, i] = values[3]
        out[4, i] = values[4]
        out[5, i] = values[5]


@kernel
def chain_impact_rows(Um, masses, weight, left_wall, right_wall, eps, Up, Lam):
    """Moreau's impact with restitution ε (docs/theory.md §3, §5) for every row of U⁻ of a
    short chain, u⁺ into the rows of ``Up`` and Λ into those of ``Lam`` (nothing certified
    here: the batch recomputes the certificate by :func:`chain_residual_columns`).

    ``weight[a, b]`` is m_a + … + m_b (a < b). Blocks of :data:`BLOCK` rows are passed
    formula by formula, each step over the block's rows at once (:func:`_impacts`)."""
    k, n = Um.shape
    mean = np.empty((n, n, BLOCK))
    z = np.empty((n, BLOCK))
    run = np.empty((2, BLOCK))
    for start in range(0, k, BLOCK):
        stop = min(start + BLOCK, k)
        _impacts(Um[start:stop], masses, weight, (left_wall, right_wall), eps, Up[start:stop],
                 Lam[start:stop], mean, z, run)


@inline_kernel
def _impacts(Um, m, weight, walls, eps, Up, Lam, mean, z, run):
    """The impacts of one block's rows: z by the min–max formula of the weighted isotonic
    regression, zⱼ = max_{a≤j} min_{b≥j} mean(u⁻_a..u⁻_b) (weights m; ``mean[a, b]``),
    clipped at 0 on a wall side (both walls: z = 0); the impulses Λ_z by anchored sums of
    dⱼ = mⱼ(zⱼ − u⁻ⱼ) (Λ = 0 exactly at the anchors); then u⁺ = (1+ε)z − εu⁻, Λ = (1+ε)Λ_z."""
    rows, n = Um.shape
    left, right = walls
    if left and right:
        z[:, :rows] = 0.0
    else:
        _projection(Um, m, weight, left, right, mean, z, run)
    d = mean[0]  # the means are used up: dⱼ in their place
    for j in range(n):
        for i in range(rows):
            d[j, i] = (z[j, i] - Um[i, j]) * m[j]
    if left and right:  # z = 0: Λ_min = max_i Cᵢ − Cⱼ with C₀ = 0
        run[:, :rows] = 0.0
        for j in range(n):
            for i in range(rows):
                c = run[0, i] + d[j, i]
                run[0, i] = c
                run[1, i] = max(run[1, i], c)
        for i in range(rows):
            run[0, i] = 0.0
            Lam[i, 0] = run[1, i]
        for j in range(n):
            for i in range(rows):
                c = run[0, i] + d[j, i]
                run[0, i] = c
                Lam[i, j + 1] = run[1, i] - c
    elif left:  # from the right: L_N = 0, Lⱼ = L_{j+1} + dⱼ unless j is an anchor
        for j in range(n - 1, -1, -1):
            for i in range(rows):
                value = d[j, i] if j == n - 1 else run[0, i] + d[j, i]
                anchor = z[j, i] > z[j - 1, i] if j else z[0, i] > 0.0
                run[0, i] = 0.0 if anchor else value
                Lam[i, j] = run[0, i]
    else:  # from the left: L₀ = 0, L_{j+1} = Lⱼ − dⱼ unless an anchor
        for j in range(1, n + right):
            for i in range(rows):
                value = -d[0, i] if j == 1 else run[0, i] - d[j - 1, i]
                anchor = z[j, i] > z[j - 1, i] if j < n else z[n - 1, i] < 0.0
                run[0, i] = 0.0 if anchor else value
                Lam[i, j - 1] = run[0, i]
    if eps == 0.0:
        for j in range(n):
            for i in range(rows):
                Up[i, j] = z[j, i]
        return
    for j in range(n):
        for i in range(rows):
            Up[i, j] = (1.0 + eps) * z[j, i] - eps * Um[i, j]
    for c in range(Lam.shape[1]):
        for i in range(rows):
            Lam[i, c] = (1.0 + eps) * Lam[i, c]


@inline_kernel
def _projection(Um, m, weight, left, right, mean, z, run):
    """z of one block's rows (at most one wall) by the min–max formula (:func:`_impacts`)."""
    rows, n = Um.shape
    for a in range(n):
        for i in range(rows):
            mean[a, a, i] = Um[i, a]
    for a in range(n - 1):
        for i in range(rows):
            run[0, i] = Um[i, a] * m[a]
        for b in range(a + 1, n):
            for i in range(rows):
                total = run[0, i] + Um[i, b] * m[b]
                run[0, i] = total
                mean[a, b, i] = total / weight[a, b]
    for j in range(n):
        for a in range(j + 1):
            for i in range(rows):
                low = mean[a, j, i]
                for b in range(j + 1, n):
                    low = min(low, mean[a, b, i])
                z[j, i] = low if a == 0 else max(z[j, i], low)
        if left:
            for i in range(rows):
                z[j, i] = max(z[j, i], 0.0)
        elif right:
            for i in range(rows):
                z[j, i] = min(z[j, i], 0.0)
