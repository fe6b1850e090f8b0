"""Derivatives of many dense impacts of a complementarity law, in compiled code
(docs/theory.md §18–§20).

Each row is solved and certified by the compiled impact (:mod:`impactqp.kernels.impact`)
and classified; its cell (active set A) is factored once — G_AA = LLᵀ, dependent columns
dropped as in the active-set search, K_AA = G_AA⁻¹ from the factor — with what depends on A
alone: the gradients in u⁻ of the quantities bounding the cell and the relative residual
‖G_AA K_AA R_A − R_A‖ / ‖R_A‖ of its linear solves (a wrong factor shows there). Up to
:data:`CACHED_CELLS` cells of a call are kept by active set (for at most :data:`MASK_BITS`
contacts), so rows in a cell already met pay only for their classification, margin, JVP
and VJP:

    du⁺ = du⁻ − Y_A K_AA (R du⁻)_A,   ū⁻ = ū − Rᵀ_A K_AAᵀ (Yᵀū)_A,

with Y = M⁻¹W and R = (I + E)Wᵀ = ∂q/∂u⁻. The margin is the distance, relative to ‖u⁻‖,
from u⁻ to the nearest hyperplane where an active Λᵢ or an inactive wᵢ reaches zero
(docs/theory.md §20); a row with a degenerate contact is a kink (margin 0, the default
element: degenerate contacts counted as separating). The single impact's derivative
(:mod:`impactqp.kernels.local_map`) factors its cell by the same functions.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .active_set import _append, cholesky_solve
from .impact import _solve_into, _unpack, workspace
from .jit import inline_kernel, kernel

SMOOTH, KINK, UNCERTIFIED, DEPENDENT = 0, 1, 2, 3
"""Status codes: of :func:`derivative_rows`' rows (the first three) and of the single
impact's cell (DEPENDENT: G_AA is singular, Λ not unique)."""

MASK_BITS = 16
"""Most contacts for which a call keeps its cells by active set (a table of 2^m slots)."""

CACHED_CELLS = 64
"""Most cells a call keeps; further ones are factored again for each row."""


class Law(NamedTuple):
    """The compiled complementarity law: E for the solve (Frémond, Newton), ε and the
    Moreau flag, and IE = I + E (m × m) for the derivative."""

    E: np.ndarray
    eps: float
    moreau: bool
    IE: np.ndarray


class Settings(NamedTuple):
    """Tolerances and what to compute: the certificate's ``tol``, the degeneracy
    ``kink_tol`` (docs/theory.md §19), whether JVP and VJP rows are asked for, and whether
    the rows come solved and certified (U⁺ and Λ already in the outputs, from another fast
    path of the batch) so that only their derivatives are computed."""

    tol: float
    kink_tol: float
    jvp: bool
    vjp: bool
    solved: bool


class Rows(NamedTuple):
    """Outputs, one row per impact: U⁺, Λ, residuals (k × 6), JVP rows du⁺, VJP rows ū⁻,
    status codes and margins."""

    Up: np.ndarray
    Lam: np.ndarray
    Res: np.ndarray
    dUp: np.ndarray
    Ubar: np.ndarray
    status: np.ndarray
    margin: np.ndarray


class Cells(NamedTuple):
    """Factored cells, by number (the last one is scratch, refilled for every row whose
    cell is not kept): the factor's contacts ``idx[e, :size[e]]``, K_AA = G_AA⁻¹ embedded
    in ``K[e]`` (m × m, read on idx only), the inverse gradient norms ``grad[e]`` of the
    bounding quantities, the solves' relative ``residual[e]``; ``slot`` maps an active-set
    bit mask to its cell (−1: not factored yet); L and y are scratch."""

    idx: np.ndarray
    size: np.ndarray
    K: np.ndarray
    grad: np.ndarray
    residual: np.ndarray
    slot: np.ndarray
    L: np.ndarray
    y: np.ndarray


@kernel
def new_cells(m, cached):
    """Room for ``cached`` kept cells and the scratch one (``cached`` = 0: scratch only)."""
    slots = (1 << m) if cached > 0 else 1
    return Cells(np.empty((cached + 1, m), dtype=np.int64),
                 np.zeros(cached + 1, dtype=np.int64), np.zeros((cached + 1, m, m)),
                 np.zeros((cached + 1, m)), np.zeros(cached + 1),
                 np.full(slots, -1, dtype=np.int64), np.empty((m, m)), np.empty(2 * m))


@inline_kernel
def classify_row(G, s, R, M, um, lam, kink_tol, w, active):
    """w = GΛ + Ru⁻ (= GΛ + q) for the row and its classification (docs/theory.md §19): a
    contact is degenerate when its scaled Λᵢsᵢ and wᵢ/sᵢ (sᵢ = √Gᵢᵢ) are both at most
    ``kink_tol``·‖u⁻‖_M, else active when Λᵢsᵢ ≥ wᵢ/sᵢ. Returns (status, the active set's
    bit mask; 0 beyond :data:`MASK_BITS` contacts)."""
    m, n = R.shape
    V = 0.0
    for i in range(n):
        for j in range(n):
            V += um[i] * M[i, j] * um[j]
    scale = 1.0 / np.sqrt(V) if V > 0.0 else 1.0
    degenerate, key = False, 0
    for i in range(m):
        total = 0.0
        for c in range(n):
            total += R[i, c] * um[c]
        for j in range(m):
            total += G[i, j] * lam[j]
        w[i] = total
        a, b = lam[i] * s[i] * scale, total / s[i] * scale
        flat = max(a, b) <= kink_tol
        on = a >= b and not flat
        active[i] = on
        degenerate |= flat
        key |= np.int64(on) << i  # no branch on the row's data
    return (KINK if degenerate else SMOOTH), (key if m <= MASK_BITS else 0)


@inline_kernel
def factor_cell(G, active, cells, e):
    """Factor the cell of ``active`` into cell number ``e`` of ``cells``: G_AA = LLᵀ (a
    dependent contact is dropped, as in the active-set search) and K_AA = G_AA⁻¹ from it.
    Returns the factor's size."""
    idx, K, L, y = cells.idx[e], cells.K[e], cells.L, cells.y
    k = 0
    for i in range(active.size):
        if active[i] and _append(L, idx, k, G, i):
            k += 1
    for a in range(k):
        for b in range(k):
            y[b] = 1.0 if a == b else 0.0
        cholesky_solve(L, k, y)
        for b in range(k):
            K[idx[b], idx[a]] = y[b]
    cells.size[e] = k
    return k


@inline_kernel
def measure_cell(G, R, active, cells, e):
    """What cell ``e`` of ``cells`` depends on alone (docs/theory.md §20), from X =
    K_AA R_A: the inverse norms of the gradients in u⁻ of Λᵢ (active: −Xᵢ) and wᵢ
    (inactive: (R − G X)ᵢ; 0 for a zero gradient), and the relative residual
    ‖G_AA X − R_A‖ / ‖R_A‖ (Frobenius), measured with G itself: a wrong K shows here."""
    m, n = R.shape
    idx, K, k, grad, x = cells.idx[e], cells.K[e], cells.size[e], cells.grad[e], cells.y[m:]
    grad[:] = 0.0
    res, scale = 0.0, 0.0
    for c in range(n):
        for a in range(k):
            total = 0.0
            for b in range(k):
                total += K[idx[a], idx[b]] * R[idx[b], c]
            x[a] = total
            grad[idx[a]] += total * total
        for i in range(m):
            if active[i]:
                continue
            z = -R[i, c]
            for b in range(k):
                z += G[i, idx[b]] * x[b]
            grad[i] += z * z
        for a in range(k):
            z = -R[idx[a], c]
            for b in range(k):
                z += G[idx[a], idx[b]] * x[b]
            res += z * z
            scale += R[idx[a], c] * R[idx[a], c]
    for i in range(m):
        grad[i] = 1.0 / np.sqrt(grad[i]) if grad[i] > 0.0 else 0.0
    cells.residual[e] = np.sqrt(res) / (np.sqrt(scale) if scale > 0.0 else 1.0)


@inline_kernel
def row_margin(um, lam, w, active, inverse):
    """The cell's radius relative to ‖u⁻‖ (docs/theory.md §20): min over contacts of the
    value (Λᵢ active, wᵢ inactive) times the inverse norm of its gradient in u⁻ (0 for a
    zero gradient, as of a dropped dependent contact: it bounds nothing)."""
    best, unorm = np.inf, 0.0
    for c in range(um.size):
        unorm += um[c] * um[c]
    for i in range(lam.size):
        if inverse[i] > 0.0:
            best = min(best, (lam[i] if active[i] else w[i]) * inverse[i])
    return best / np.sqrt(unorm) if unorm > 0.0 else 0.0


@inline_kernel
def apply_cell(P, Q, cells, e, transpose, x, out):
    """out = x − Q_Aᵀ K_AA P_A x (K_AAᵀ with ``transpose``): with P = R, Q = Yᵀ the JVP of
    u⁻, with P = Yᵀ, Q = R and ``transpose`` its VJP (docs/theory.md §18)."""
    m, n = P.shape
    idx, K, k, y = cells.idx[e], cells.K[e], cells.size[e], cells.y
    for a in range(k):
        total = 0.0
        for c in range(n):
            total += P[idx[a], c] * x[c]
        y[a] = total
    z = y[m:]
    for a in range(k):
        total = 0.0
        for b in range(k):
            total += (K[idx[b], idx[a]] if transpose else K[idx[a], idx[b]]) * y[b]
        z[a] = total
    for c in range(n):
        total = x[c]
        for a in range(k):
            total -= Q[idx[a], c] * z[a]
        out[c] = total


@kernel
def derivative_rows(packed, Um, dU, Ubar, law, settings, passive, out):
    """Solve, certify and differentiate every row of U⁻ into ``out`` (:class:`Rows`); a
    row that the compiled solve does not certify, or whose cell's linear solves miss the
    tolerance, gets status UNCERTIFIED (the caller answers it on its own)."""
    k_rows, n = Um.shape
    m = passive.size
    ops = _unpack(packed, n, m)
    R = law.IE @ ops.Wt  # ∂q/∂u⁻ and Yᵀ, the same for every row
    YT = np.ascontiguousarray(ops.MinvW.T)
    # contiguous copies of the packed views: the row loop indexes them faster
    G, s, M = ops.G.copy(), ops.s.copy(), ops.M.copy()
    kept = CACHED_CELLS if m <= MASK_BITS else 0
    cells = new_cells(m, kept)
    work = workspace(n, m)
    w, active = np.empty(m), np.empty(m, dtype=np.bool_)
    used = 0
    for r in range(k_rows):
        um, lam = Um[r], out.Lam[r]
        if not settings.solved and not _solve_into(
                ops, um, law.E, law.eps, law.moreau, settings.tol, passive, out.Up[r], lam,
                out.Res[r], work):
            out.status[r], out.margin[r] = UNCERTIFIED, np.nan
            continue
        status, key = classify_row(G, s, R, M, um, lam, settings.kink_tol, w, active)
        e = cells.slot[key] if kept else -1
        if e < 0:
            e = used if used < kept else kept
            factor_cell(G, active, cells, e)
            measure_cell(G, R, active, cells, e)
            if e < kept:
                cells.slot[key] = e
                used += 1
        if not cells.residual[e] <= settings.tol:  # NaN fails
            out.status[r], out.margin[r] = UNCERTIFIED, np.nan
            continue
        out.status[r] = status
        out.margin[r] = 0.0 if status == KINK else row_margin(um, lam, w, active,
                                                             cells.grad[e])
        if settings.jvp:
            apply_cell(R, YT, cells, e, False, dU[r], out.dUp[r])
        if settings.vjp:
            apply_cell(YT, R, cells, e, True, Ubar[r], out.Ubar[r])
