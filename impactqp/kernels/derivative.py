"""Derivatives of many dense impacts of a complementarity law, in compiled code
(docs/theory.md §18–§20).

The rows come solved and certified (by the compiled impacts of
:func:`impactqp.kernels.impact.solve_impact_rows`, or a batch's chain path): each is
classified; its cell (active set A) is factored once — G_AA = LLᵀ, dependent columns
dropped as in the active-set search, K_AA = G_AA⁻¹ from the factor — with what depends on A
alone: the gradients in u⁻ of the quantities bounding the cell and the relative residual
‖G_AA K_AA R_A − R_A‖ / ‖R_A‖ of its linear solves (a wrong factor shows there). Up to
:data:`CACHED_CELLS` + 1 cells of a call are kept by active set (for at most
:data:`MASK_BITS` contacts; when all are in use, the rows met so far are finished and the
cells start again), so rows in a cell already met pay only for their classification,
margin, JVP and VJP:

    du⁺ = du⁻ − Y_A K_AA (R du⁻)_A,   ū⁻ = ū − Rᵀ_A K_AAᵀ (Yᵀū)_A,

with Y = M⁻¹W and R = (I + E)Wᵀ = ∂q/∂u⁻. The margin is the distance, relative to ‖u⁻‖,
from u⁻ to the nearest hyperplane where an active Λᵢ or an inactive wᵢ reaches zero
(docs/theory.md §20); a row with a degenerate contact is a kink (margin 0, the default
element: degenerate contacts counted as separating). The single impact's derivative
(:mod:`impactqp.kernels.local_map`) classifies, factors and measures its cell by the same
functions, as a batch of one row.

Each step runs over a range of rows in one call (:func:`classify_rows`,
:func:`finish_rows`), never as a compiled call per row: such a call takes a reference to
each of its array arguments and gives it back (two atomic operations per array), which for
three balls cost four times the row's arithmetic.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .active_set import _append, cholesky_solve
from .impact import _unpack
from .jit import inline_kernel, kernel

SMOOTH, KINK, UNCERTIFIED, DEPENDENT = 0, 1, 2, 3
"""Status codes: of :func:`derivative_rows`' rows (the first three) and of the single
impact's cell (DEPENDENT: G_AA is singular, Λ not unique)."""

MASK_BITS = 16
"""Most contacts for which a call keeps its cells by active set (a table of 2^m slots)."""

CACHED_CELLS = 64
"""Cells a call keeps beside the one it always has (more: the rows met so far are finished
and the cells refilled)."""


class Settings(NamedTuple):
    """Tolerances and what to compute: the tolerance ``tol`` of a cell's linear solves,
    the degeneracy ``kink_tol`` (docs/theory.md §19) and whether JVP and VJP rows are
    asked for."""

    tol: float
    kink_tol: float
    jvp: bool
    vjp: bool


class Rows(NamedTuple):
    """One row per impact: U⁺ and Λ (inputs, the rows' certified answers), then the
    outputs: JVP rows du⁺, VJP rows ū⁻, status codes and margins."""

    Up: np.ndarray
    Lam: np.ndarray
    dUp: np.ndarray
    Ubar: np.ndarray
    status: np.ndarray
    margin: np.ndarray


class Cells(NamedTuple):
    """Factored cells, by number: the factor's contacts ``idx[e, :size[e]]``,
    K_AA = G_AA⁻¹ embedded in ``K[e]`` (m × m, read on idx only), the inverse gradient norms
    ``grad[e]`` of the bounding quantities, the solves' relative ``residual[e]``; ``slot``
    maps an active-set bit mask to its cell (−1: none) and ``key[e]`` is cell e's mask;
    L and y are scratch."""

    idx: np.ndarray
    size: np.ndarray
    K: np.ndarray
    grad: np.ndarray
    residual: np.ndarray
    slot: np.ndarray
    key: np.ndarray
    L: np.ndarray
    y: np.ndarray


class Classes(NamedTuple):
    """The classification of k rows: w = GΛ + q (k × m), the active flags (k × m), the
    active sets' bit masks (k) and each row's cell number (k; −1: none, the row is
    uncertified)."""

    w: np.ndarray
    active: np.ndarray
    keys: np.ndarray
    cell: np.ndarray


@kernel
def new_cells(m, cached):
    """Room for ``cached`` + 1 cells, with the table of active sets when ``cached`` > 0
    (then m ≤ :data:`MASK_BITS`)."""
    slots = (1 << m) if cached > 0 else 1
    return Cells(np.empty((cached + 1, m), dtype=np.int64),
                 np.zeros(cached + 1, dtype=np.int64), np.zeros((cached + 1, m, m)),
                 np.zeros((cached + 1, m)), np.zeros(cached + 1),
                 np.full(slots, -1, dtype=np.int64), np.zeros(cached + 1, dtype=np.int64),
                 np.empty((m, m)), np.empty(2 * m))


@kernel(internal=True)
def classify_rows(G, s, R, M, Um, Lam, kink_tol, classes, codes):
    """For every row (u⁻, Λ): w = GΛ + Ru⁻ (= GΛ + q) and the classification
    (docs/theory.md §19): a contact is degenerate when its scaled Λᵢsᵢ and wᵢ/sᵢ
    (sᵢ = √Gᵢᵢ) are both at most ``kink_tol``·‖u⁻‖_M, else active when Λᵢsᵢ ≥ wᵢ/sᵢ.
    Fills ``classes`` (:class:`Classes`; bit mask 0 beyond :data:`MASK_BITS` contacts, cell
    left alone) and ``codes`` (SMOOTH, or KINK for a row with a degenerate contact)."""
    m, n = R.shape
    W, active, keys = classes.w, classes.active, classes.keys
    for r in range(Um.shape[0]):
        V = 0.0
        for i in range(n):
            for j in range(n):
                V += Um[r, i] * M[i, j] * Um[r, j]
        scale = 1.0 / np.sqrt(V) if V > 0.0 else 1.0
        degenerate, key = False, 0
        for i in range(m):
            total = 0.0
            for c in range(n):
                total += R[i, c] * Um[r, c]
            for j in range(m):
                total += G[i, j] * Lam[r, j]
            W[r, i] = total
            a, b = Lam[r, i] * s[i] * scale, total / s[i] * scale
            flat = max(a, b) <= kink_tol
            on = a >= b and not flat
            active[r, i] = on
            degenerate |= flat
            key |= np.int64(on) << i  # no branch on the row's data
        codes[r] = KINK if degenerate else SMOOTH
        keys[r] = key if m <= MASK_BITS else 0


@inline_kernel
def factor_cell(G, active, cells, e):
    """Factor the cell of ``active`` into cell number ``e`` of ``cells``: G_AA = LLᵀ (a
    dependent contact is dropped, as in the active-set search) and K_AA = G_AA⁻¹ from it.
    Returns the factor's size."""
    idx, K, L, y = cells.idx[e], cells.K[e], cells.L, cells.y
    k = np.int64(0)  # not a literal: _append compiles for int64 only (one signature)
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


@kernel(internal=True)
def margin_rows(Um, Lam, classes, codes, grad, margin, start, stop):
    """For the rows start..stop with a cell: the cell's radius relative to ‖u⁻‖
    (docs/theory.md §20), min over contacts of the value (Λᵢ active, wᵢ inactive) times
    the inverse norm of its gradient in u⁻ (``grad[cell]``; 0 for a zero gradient, as of a
    dropped dependent contact: it bounds nothing); 0 at a kink."""
    W, active, cell = classes.w, classes.active, classes.cell
    for r in range(start, stop):
        e = cell[r]
        if e < 0:
            continue
        best, unorm = np.inf, 0.0
        for c in range(Um.shape[1]):
            unorm += Um[r, c] * Um[r, c]
        for i in range(Lam.shape[1]):
            if grad[e, i] > 0.0:
                best = min(best, (Lam[r, i] if active[r, i] else W[r, i]) * grad[e, i])
        margin[r] = 0.0 if codes[r] == KINK or not unorm > 0.0 else best / np.sqrt(unorm)


@kernel(internal=True)
def apply_rows(P, Q, cells, cell, transpose, X, out, start, stop):
    """For the rows start..stop with a cell: out = x − Q_Aᵀ K_AA P_A x (K_AAᵀ with
    ``transpose``) on the row's cell; with P = R, Q = Yᵀ the JVP of u⁻, with P = Yᵀ,
    Q = R and ``transpose`` its VJP (docs/theory.md §18)."""
    m, n = P.shape
    idx, K, size, y, z = cells.idx, cells.K, cells.size, cells.y[:m], cells.y[m:]
    for r in range(start, stop):
        e = cell[r]
        if e < 0:
            continue
        k = size[e]
        for a in range(k):
            total = 0.0
            for c in range(n):
                total += P[idx[e, a], c] * X[r, c]
            y[a] = total
        for a in range(k):
            total = 0.0
            for b in range(k):
                i, j = (idx[e, b], idx[e, a]) if transpose else (idx[e, a], idx[e, b])
                total += K[e, i, j] * y[b]
            z[a] = total
        for c in range(n):
            total = X[r, c]
            for a in range(k):
                total -= Q[idx[e, a], c] * z[a]
            out[r, c] = total


@kernel
def finish_rows(Um, Lam, classes, cells, R, YT, dU, Ubar, settings, out, start, stop):
    """Margins, JVP and VJP rows of the rows start..stop that have a cell."""
    margin_rows(Um, Lam, classes, out.status, cells.grad, out.margin, start, stop)
    # run-time flags (np.bool_): one compiled apply_rows for both directions
    if settings.jvp:
        apply_rows(R, YT, cells, classes.cell, np.bool_(False), dU, out.dUp, start, stop)
    if settings.vjp:
        apply_rows(YT, R, cells, classes.cell, np.bool_(True), Ubar, out.Ubar, start,
                   stop)


@kernel
def derivative_rows(packed, Um, dU, Ubar, IE, settings, solved, out):
    """Differentiate every row of U⁻ whose answer (U⁺, Λ in ``out``, :class:`Rows`) the
    caller has certified (``solved``, one flag per row) into ``out``, with IE = I + E
    (m × m) of the law; the other rows, and rows whose cell's linear solves miss the
    tolerance, get status UNCERTIFIED (the caller answers them on its own). Solving the
    rows is left to :func:`impactqp.kernels.impact.solve_impact_rows`, so that this
    kernel's compile holds no second copy of the solve."""
    k_rows, n = Um.shape
    m = IE.shape[0]
    ops = _unpack(packed, n, m)
    R = IE @ ops.Wt  # ∂q/∂u⁻ and Yᵀ, the same for every row
    YT = np.ascontiguousarray(ops.MinvW.T)
    # contiguous copies of the packed views: the row loops index them faster
    G, s, M = ops.G.copy(), ops.s.copy(), ops.M.copy()
    Lam, codes, margin = out.Lam, out.status, out.margin
    classes = Classes(np.empty((k_rows, m)), np.empty((k_rows, m), dtype=np.bool_),
                      np.empty(k_rows, dtype=np.int64), np.full(k_rows, -1, dtype=np.int64))
    classify_rows(G, s, R, M, Um, Lam, settings.kink_tol, classes, codes)
    lookup = m <= MASK_BITS
    cells = new_cells(m, CACHED_CELLS if lookup else 0)
    slot, owner, residual = cells.slot, cells.key, cells.residual
    active, keys, cell = classes.active, classes.keys, classes.cell
    used, start = 0, np.int64(0)  # start not a literal: finish_rows compiles once
    for r in range(k_rows):
        if not solved[r]:
            codes[r], margin[r] = UNCERTIFIED, np.nan
            continue
        e = slot[keys[r]] if lookup else -1
        if e < 0:
            if used == residual.size:  # every cell in use: finish the rows met, refill
                finish_rows(Um, Lam, classes, cells, R, YT, dU, Ubar, settings, out,
                            start, r)
                start, used = r, 0
                if lookup:
                    for f in range(residual.size):
                        slot[owner[f]] = -1
            e, used = used, used + 1
            factor_cell(G, active[r], cells, e)
            measure_cell(G, R, active[r], cells, e)
            if lookup:
                slot[keys[r]], owner[e] = e, keys[r]
        if not residual[e] <= settings.tol:  # NaN fails
            codes[r], margin[r] = UNCERTIFIED, np.nan
            continue
        cell[r] = e
    finish_rows(Um, Lam, classes, cells, R, YT, dU, Ubar, settings, out, start, k_rows)
