"""The derivative of one dense impact of a complementarity law, in compiled code
(docs/theory.md §18–§20).

:func:`local_cell` forms what ``result.derivative()`` needs at the answer (u⁻, Λ) in one
call, from the structure's packed operators: the classification of the contacts and the
factored cell of :mod:`impactqp.kernels.derivative` (K_AA = G_AA⁻¹, the relative residual of
its solves measured with G itself), the cell's margin, the 1-norm condition number
‖G_AA‖₁‖K_AA‖₁, γ⁻ = Wᵀu⁻, w = GΛ + q and v = M⁻¹WΛ. :func:`jvp` and :func:`vjp` are the
map's tangent and its transpose for every input (u⁻, M, W, E) on any embedded K (this
cell's, or one the caller formed where this kernel declines: a kink, a singular G_AA, or
Coulomb's modes):

    dΛ = −K(dG Λ + dq),  dq = (I + E)(Wᵀdu⁻ + dWᵀu⁻) + dE γ⁻,
    dG Λ = dWᵀv + Yᵀ(dW Λ − dM v),  du⁺ = du⁻ + M⁻¹(dW Λ − dM v) + Y dΛ,

with Y = M⁻¹W. Inputs a direction leaves alone travel as empty arrays. The operands at the
answer travel as one flat array (:func:`point_size`; :class:`Point` views it inside the
kernels), like the structure's :func:`~impactqp.kernels.impact.pack`: numba types one
array from Python faster than a tuple of nine.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .derivative import (
    DEPENDENT,
    SMOOTH,
    Classes,
    classify_rows,
    factor_cell,
    margin_rows,
    measure_cell,
    new_cells,
)
from .impact import _unpack
from .jit import inline_kernel, kernel


class Point(NamedTuple):
    """The operands of the map at one answer: M⁻¹, Y = M⁻¹W, W, I + E, K (embedded, any
    m × m: G_AA⁻¹ on the cell, a pseudo-inverse, or Coulomb's), u⁻, Λ, v = YΛ and
    γ⁻ = Wᵀu⁻."""

    Minv: np.ndarray
    Y: np.ndarray
    W: np.ndarray
    IE: np.ndarray
    K: np.ndarray
    u: np.ndarray
    lam: np.ndarray
    v: np.ndarray
    gamma: np.ndarray


@inline_kernel
def point_size(n, m):
    """Floats of a packed :class:`Point`."""
    return n * n + 2 * n * m + 2 * m * m + 2 * n + 2 * m


def pack_point(*fields: np.ndarray) -> np.ndarray:
    """The :class:`Point` of ``fields`` (in its order) as one flat array."""
    return np.concatenate([np.ravel(f) for f in fields]).astype(float)


@kernel
def unpack_point(point, n, m):
    """The views (:class:`Point`) of a packed point."""
    a, b, c = n * n, n * n + n * m, n * n + 2 * n * m
    d, e = c + m * m, c + 2 * m * m
    f, g, h = e + n, e + n + m, e + 2 * n + m
    return Point(point[:a].reshape((n, n)), point[a:b].reshape((n, m)),
                 point[b:c].reshape((n, m)), point[c:d].reshape((m, m)),
                 point[d:e].reshape((m, m)), point[e:f], point[f:g], point[g:h],
                 point[h:h + m])


@kernel(interpretable=True)
def local_cell(packed, Minv, E, eps, um, lam, kink_tol, out):
    """Classify and factor the cell of one answer (the structure ``packed``, M⁻¹, the
    law's E — or, given as an empty array, E = εI —, u⁻, Λ). Fills ``out``: the packed
    :class:`Point` with this cell's K, then w = GΛ + q (m), the active flags (m; 1.0 or
    0.0) and (margin, residual, condition). Returns SMOOTH, or KINK (a degenerate
    contact) or DEPENDENT (G_AA singular), for which the caller forms the derivative
    itself (``out`` is then only partly filled)."""
    n, m = um.size, lam.size
    ops = _unpack(packed, n, m)
    size = point_size(n, m)
    p = unpack_point(out[:size], n, m)
    w, flags, figures = out[size:size + m], out[size + m:size + 2 * m], out[size + 2 * m:]
    IE = p.IE  # I + E, or (1 + ε)I; loops: np.eye and array expressions compile slowly
    for c in range(m):
        for b in range(m):
            diagonal = 1.0 if c == b else 0.0
            IE[c, b] = diagonal * (1.0 + eps) if E.size == 0 else diagonal + E[c, b]
    R = IE @ ops.Wt
    ints = np.empty(3, dtype=np.int64)  # the batch's classification of one row, in cell 0
    ints[1] = 0
    one = Classes(w.reshape((1, m)), np.empty((1, m), dtype=np.bool_), ints[:1], ints[1:2])
    Um, Lam, status = um.reshape((1, n)), lam.reshape((1, m)), ints[2:]
    classify_rows(ops.G, ops.s, R, ops.M, Um, Lam, kink_tol, one, status)
    if status[0] != SMOOTH:
        return status[0]
    active = one.active[0]
    cells = new_cells(m, np.int64(0))  # typed as derivative_rows' call: one signature
    k = factor_cell(ops.G, active, cells, 0)
    count = 0
    for i in range(m):
        flags[i] = 1.0 if active[i] else 0.0
        count += 1 if active[i] else 0
    if k < count:
        return DEPENDENT
    measure_cell(ops.G, R, active, cells, 0)
    idx, KA = cells.idx[0], cells.K[0]
    p.K[:] = 0.0
    gnorm, knorm = 0.0, 0.0
    for a in range(k):
        gcol, kcol = 0.0, 0.0
        for b in range(k):
            p.K[idx[b], idx[a]] = KA[idx[b], idx[a]]
            gcol += abs(ops.G[idx[b], idx[a]])
            kcol += abs(KA[idx[b], idx[a]])
        gnorm, knorm = max(gnorm, gcol), max(knorm, kcol)
    for a in range(n):  # loops: a slice copy compiles numba's shape errors
        p.u[a] = um[a]
        for b in range(n):
            p.Minv[a, b] = Minv[a, b]
        for c in range(m):
            p.Y[a, c] = ops.MinvW[a, c]
            p.W[a, c] = ops.Wt[c, a]
    for c in range(m):
        p.lam[c] = lam[c]
    for i in range(m):
        total = 0.0
        for c in range(n):
            total += ops.Wt[i, c] * um[c]
        p.gamma[i] = total
    for c in range(n):
        total = 0.0
        for i in range(m):
            total += ops.MinvW[c, i] * lam[i]
        p.v[c] = total
    margin_rows(Um, Lam, one, status, cells.grad, figures[:1], np.int64(0), np.int64(1))
    figures[1] = cells.residual[0]
    figures[2] = gnorm * knorm if k else 1.0
    return SMOOTH


@inline_kernel
def _rhs_into(p, t, r, du, s):
    """r = dG Λ + dq and du = du⁻ + M⁻¹(dW Λ − dM v), the part of du⁺ outside Y dΛ, at
    ``p`` (:class:`Point`) for the directions t = (du⁻ (n,), dM (n × n), dW (n × m),
    dE (m × m)), an empty array for an input left alone (s: n + m floats of scratch)."""
    n, m = p.Y.shape
    tdu, tdM, tdW, tdE = t
    g, f = s[:m], s[m:]
    r[:] = 0.0
    du[:] = 0.0
    g[:] = 0.0  # Wᵀdu⁻ + dWᵀu⁻, then (I + E) of it
    f[:] = 0.0  # dW Λ − dM v
    if tdu.size:
        for c in range(n):
            du[c] = tdu[c]
            for j in range(m):
                g[j] += p.W[c, j] * tdu[c]
    if tdW.size:
        for c in range(n):
            for j in range(m):
                g[j] += tdW[c, j] * p.u[c]
                r[j] += tdW[c, j] * p.v[c]
                f[c] += tdW[c, j] * p.lam[j]
    if tdM.size:
        for c in range(n):
            for d in range(n):
                f[c] -= tdM[c, d] * p.v[d]
    for i in range(m):
        total = 0.0
        for j in range(m):
            total += p.IE[i, j] * g[j]
            if tdE.size:
                total += tdE[i, j] * p.gamma[j]
        for c in range(n):
            total += p.Y[c, i] * f[c]
        r[i] += total
    for c in range(n):
        total = 0.0
        for d in range(n):
            total += p.Minv[c, d] * f[d]
        du[c] += total


@kernel
def rhs(point, n, m, du, dM, dW, dE):
    """(r, du) of :func:`_rhs_into` at the packed ``point`` for the directions."""
    r, out = np.empty(m), np.empty(n)
    _rhs_into(unpack_point(point, n, m), (du, dM, dW, dE), r, out, np.empty(n + m))
    return r, out


@kernel(interpretable=True)
def jvp(point, n, m, du, dM, dW, dE):
    """(du⁺, dΛ) at the packed ``point`` along the directions (du⁻, dM, dW, dE; empty:
    none): dΛ = −K r, du⁺ = du + Y dΛ."""
    p = unpack_point(point, n, m)
    r, out, dlam = np.empty(m), np.empty(n), np.empty(m)
    _rhs_into(p, (du, dM, dW, dE), r, out, np.empty(n + m))
    for i in range(m):
        total = 0.0
        for j in range(m):
            total -= p.K[i, j] * r[j]
        dlam[i] = total
    for c in range(n):
        total = out[c]
        for j in range(m):
            total += p.Y[c, j] * dlam[j]
        out[c] = total
    return out, dlam


class Cotangents(NamedTuple):
    """What :func:`vjp` fills for k rows: ū⁻ (k, n), M̄ (k, n, n), W̄ (k, n, m) and
    Ē (k, m, m), the cotangent of E (the law's parameter is a linear image of it)."""

    u: np.ndarray
    M: np.ndarray
    W: np.ndarray
    E: np.ndarray


@kernel(interpretable=True)
def vjp(point, ubar, lbar, u_out, M_out, W_out, E_out, trace_out):
    """The transpose of :func:`jvp` at the packed ``point`` for rows of cotangents ū
    (k, n) and Λ̄ (k, m), into the rows of ``u_out``, ``M_out``, ``W_out``, ``E_out``
    (:class:`Cotangents`; ``E_out`` of shape (k, 0, 0): Ē left out) and ``trace_out``
    (tr Ē, the cotangent of a parameter with E = value·I): with l = Λ̄ + Yᵀū, b = −Kᵀl,
    a = M⁻¹ū + Yb and ρ = (I + E)ᵀb, ū⁻ = ū + Wρ, M̄ = −a vᵀ, W̄ = aΛᵀ + v bᵀ + u⁻ρᵀ,
    Ē = b γ⁻ᵀ."""
    n, m = ubar.shape[1], lbar.shape[1]
    p = unpack_point(point, n, m)
    lt, b, rho, a = np.empty(m), np.empty(m), np.empty(m), np.empty(n)
    for row in range(ubar.shape[0]):
        ub = ubar[row]
        for i in range(m):
            total = lbar[row, i]
            for c in range(n):
                total += p.Y[c, i] * ub[c]
            lt[i] = total
        for j in range(m):
            total = 0.0
            for i in range(m):
                total -= p.K[i, j] * lt[i]
            b[j] = total
        for j in range(m):
            total = 0.0
            for i in range(m):
                total += p.IE[i, j] * b[i]
            rho[j] = total
        for c in range(n):
            total, back = 0.0, ub[c]
            for d in range(n):
                total += p.Minv[c, d] * ub[d]
            for j in range(m):
                total += p.Y[c, j] * b[j]
                back += p.W[c, j] * rho[j]
            a[c] = total
            u_out[row, c] = back
        for c in range(n):
            for d in range(n):
                M_out[row, c, d] = -a[c] * p.v[d]
            for j in range(m):
                W_out[row, c, j] = a[c] * p.lam[j] + p.v[c] * b[j] + p.u[c] * rho[j]
        trace = 0.0
        for i in range(m):
            trace += b[i] * p.gamma[i]
            for j in range(E_out.shape[2]):
                E_out[row, i, j] = b[i] * p.gamma[j]
        trace_out[row] = trace

