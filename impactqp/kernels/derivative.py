"""Derivatives of many dense impacts of a complementarity law, in compiled code
(docs/theory.md §18–§20).

Each row is solved and certified by the compiled impact (:mod:`impactqp.kernels.impact`);
on the row's active set A, G_AA is factored (G_AA = LLᵀ, dependent columns dropped as in
the active-set search) and reused for the row's JVP, VJP and cell margin:

    du⁺ = du⁻ − Y_A G_AA⁻¹ (R du⁻)_A,   ū⁻ = ū − Rᵀ_A G_AA⁻¹ (Yᵀū)_A,

with Y = M⁻¹W and R = (I + E)Wᵀ = ∂q/∂u⁻. The margin is the distance, relative to ‖u⁻‖,
from u⁻ to the nearest hyperplane where an active Λᵢ or an inactive wᵢ reaches zero
(docs/theory.md §20); a row with a degenerate contact is a kink (margin 0, the default
element: degenerate contacts counted as separating).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .active_set import _append, solve_factored_into
from .impact import _solve_into, _unpack, workspace
from .jit import kernel

SMOOTH, KINK, UNCERTIFIED = 0, 1, 2
"""Row status codes of :func:`derivative_rows`."""


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


@kernel
def _active_factor(G, IE, Wt, M, um, lam, kink_tol, L, idx, w, active, gamma):
    """w = GΛ + q for the row, the factor of G_AA on the active contacts (in L, idx) and
    the row's status. Returns (k, status)."""
    m, n = Wt.shape
    V = 0.0
    for i in range(n):
        for j in range(n):
            V += um[i] * M[i, j] * um[j]
    V = np.sqrt(V) if V > 0.0 else 1.0
    for j in range(m):
        g = 0.0
        for c in range(n):
            g += Wt[j, c] * um[c]
        gamma[j] = g
    for i in range(m):
        total = 0.0
        for j in range(m):
            total += IE[i, j] * gamma[j] + G[i, j] * lam[j]
        w[i] = total
    k, status = 0, SMOOTH
    for i in range(m):
        s = np.sqrt(G[i, i])
        a, b = lam[i] * s / V, w[i] / (s * V)
        active[i] = False
        if max(a, b) <= kink_tol:
            status = KINK
        elif a >= b:
            active[i] = True
            if _append(L, idx, k, G, i):
                k += 1
    return k, status


@kernel
def _margin(G, IE, Wt, um, lam, w, L, idx, k, active, buf):
    """The cell's radius relative to ‖u⁻‖ (docs/theory.md §20): min over contacts of the
    value (Λᵢ active, wᵢ inactive) over the norm of its gradient in u⁻."""
    m, n = Wt.shape
    R, dlam, grad = buf[:m], buf[m:2 * m], buf[2 * m:3 * m]
    grad[:] = 0.0
    unorm = 0.0
    for c in range(n):
        unorm += um[c] * um[c]
        for i in range(m):
            total = 0.0
            for j in range(m):
                total += IE[i, j] * Wt[j, c]
            R[i] = total
            dlam[i] = 0.0
        solve_factored_into(L, idx, k, R, dlam, buf[4 * m:5 * m])
        for i in range(m):
            if active[i]:  # an active contact dropped as dependent keeps a zero gradient
                grad[i] += dlam[i] * dlam[i]
            else:
                total = R[i]
                for a in range(k):
                    total -= G[i, idx[a]] * dlam[idx[a]]
                grad[i] += total * total
    best = np.inf
    for i in range(m):
        value = lam[i] if active[i] else w[i]
        if grad[i] > 0.0 and value / np.sqrt(grad[i]) < best:
            best = value / np.sqrt(grad[i])
    return best / np.sqrt(unorm) if unorm > 0.0 else 0.0


@kernel
def _jvp_vjp(IE, Wt, MinvW, L, idx, k, du, ubar, dup, uout, settings, buf):
    """The row's JVP du⁺ and VJP ū⁻ on the factored active set."""
    m, n = Wt.shape
    r, x = buf[:m], buf[m:2 * m]
    if settings.jvp:
        for i in range(m):
            total = 0.0
            for j in range(m):
                g = 0.0
                for c in range(n):
                    g += Wt[j, c] * du[c]
                total += IE[i, j] * g
            r[i] = total
            x[i] = 0.0
        solve_factored_into(L, idx, k, r, x, buf[4 * m:5 * m])
        for c in range(n):
            total = du[c]
            for a in range(k):
                total -= MinvW[c, idx[a]] * x[idx[a]]
            dup[c] = total
    if settings.vjp:
        for i in range(m):
            total = 0.0
            for c in range(n):
                total += MinvW[c, i] * ubar[c]
            r[i] = total
            x[i] = 0.0
        solve_factored_into(L, idx, k, r, x, buf[4 * m:5 * m])
        for c in range(n):
            total = ubar[c]
            for i in range(m):
                g = 0.0
                for j in range(m):
                    g += IE[j, i] * x[j]
                total -= Wt[i, c] * g
            uout[c] = total


@kernel
def derivative_rows(packed, Um, dU, Ubar, law, settings, passive, out):
    """Solve, certify and differentiate every row of U⁻ into ``out`` (:class:`Rows`); a
    row that the compiled solve does not certify gets status UNCERTIFIED (the caller
    answers it on its own)."""
    k_rows, n = Um.shape
    m = passive.size
    ops = _unpack(packed, n, m)
    M, Wt, MinvW, G = ops.M, ops.Wt, ops.MinvW, ops.G
    work = workspace(n, m)
    L, idx = np.empty((m, m)), np.empty(m, dtype=np.int64)
    w, buf, active = np.empty(m), np.empty(5 * m), np.empty(m, dtype=np.bool_)
    for r in range(k_rows):
        if not settings.solved and not _solve_into(
                ops, Um[r], law.E, law.eps, law.moreau, settings.tol, passive, out.Up[r],
                out.Lam[r], out.Res[r], work):
            out.status[r] = UNCERTIFIED
            out.margin[r] = np.nan
            continue
        k, status = _active_factor(G, law.IE, Wt, M, Um[r], out.Lam[r], settings.kink_tol,
                                   L, idx, w, active, buf[3 * m:])
        out.status[r] = status
        out.margin[r] = 0.0 if status == KINK else _margin(
            G, law.IE, Wt, Um[r], out.Lam[r], w, L, idx, k, active, buf)
        a = r if settings.jvp else 0  # rows not asked for are one placeholder row
        b = r if settings.vjp else 0
        _jvp_vjp(law.IE, Wt, MinvW, L, idx, k, dU[a], Ubar[b], out.dUp[a], out.Ubar[b],
                 settings, buf)
