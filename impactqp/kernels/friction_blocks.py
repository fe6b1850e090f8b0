"""The contact blocks of W as the projected Gauss–Seidel reads them (docs/theory.md §15): the
diagonal blocks W_cc gathered from W's compressed rows, the step ρ_c of each contact's
projected fixed point from the extreme eigenvalues of their symmetric part (closed forms for
d = 2 and d = 3, no LAPACK call per contact), the exact solution of one contact's local
problem where a closed form holds, and the compressed rows of a dense W without its zero
entries.
"""

from __future__ import annotations

import math

import numpy as np

from .friction_planar import planar_contact, planar_sticking
from .jit import inline_kernel, kernel


@inline_kernel
def extreme_sum(S, d):
    """λ_min + λ_max of the symmetric part of the d × d block S (d = 2 or 3): the trace for
    d = 2; for d = 3 the trace less the middle eigenvalue, by the trigonometric closed form
    of a symmetric 3 × 3 matrix's eigenvalues (docs/theory.md §15)."""
    if d == 2:
        return S[0, 0] + S[1, 1]
    a01 = 0.5 * (S[0, 1] + S[1, 0])
    a02 = 0.5 * (S[0, 2] + S[2, 0])
    a12 = 0.5 * (S[1, 2] + S[2, 1])
    trace = S[0, 0] + S[1, 1] + S[2, 2]
    off = a01 * a01 + a02 * a02 + a12 * a12
    if off == 0.0:
        lo = min(S[0, 0], min(S[1, 1], S[2, 2]))
        hi = max(S[0, 0], max(S[1, 1], S[2, 2]))
        return lo + hi
    mean = trace / 3.0
    b00, b11, b22 = S[0, 0] - mean, S[1, 1] - mean, S[2, 2] - mean
    p = math.sqrt((b00 * b00 + b11 * b11 + b22 * b22 + 2.0 * off) / 6.0)
    det = (b00 * (b11 * b22 - a12 * a12) - a01 * (a01 * b22 - a12 * a02)
           + a02 * (a01 * a12 - b11 * a02))
    half = det / (2.0 * p * p * p)
    phi = math.acos(min(1.0, max(-1.0, half))) / 3.0
    hi = mean + 2.0 * p * math.cos(phi)
    lo = mean + 2.0 * p * math.cos(phi + 2.0 * math.pi / 3.0)
    return lo + hi


@kernel(interpretable=True)
def local_steps(Wcc):
    """The step ρ_c of each contact's projected fixed point in
    :func:`impactqp.kernels.friction.nsgs_rows`: 2/(λ_min + λ_max) of the symmetric part of
    W_cc (1 where that sum is not positive or W_cc not finite)."""
    m, d = Wcc.shape[0], Wcc.shape[1]
    rhos = np.ones(m)
    for c in range(m):
        finite = True
        for i in range(d):
            for j in range(d):
                finite = finite and math.isfinite(Wcc[c, i, j])
        if not finite:
            continue
        total = extreme_sum(Wcc[c], d)
        if total > 0.0:
            rhos[c] = 2.0 / total
    return rhos


@kernel(interpretable=True)
def diagonal_blocks(indptr, indices, data, m, d):
    """The m diagonal d × d blocks W_cc of W given by its compressed rows (duplicates
    summed)."""
    Wcc = np.zeros((m, d, d))
    for c in range(m):
        k = c * d
        for i in range(d):
            for p in range(indptr[k + i], indptr[k + i + 1]):
                j = indices[p] - k
                if 0 <= j < d:
                    Wcc[c, i, j] += data[p]
    return Wcc


@kernel(interpretable=True)
def nonzero_rows(W):
    """W's compressed rows (scipy's CSR arrays ``indptr``, ``indices``, ``data``) with its
    zero entries left out: a sweep then costs the entries that are there (W of contacts
    given dense is mostly zeros: 2–8 % of its entries on the FCLib problems of a few dozen
    contacts). One pass over W, the price of one dense sweep."""
    n = W.shape[0]
    indptr = np.zeros(n + 1, dtype=np.int32)  # scipy's index type: one compiled sweep
    for i in range(n):
        count = 0
        for j in range(n):
            if W[i, j] != 0.0:
                count += 1
        indptr[i + 1] = indptr[i] + count
    indices = np.empty(indptr[n], dtype=np.int32)
    data = np.empty(indptr[n])
    for i in range(n):
        p = indptr[i]
        for j in range(n):
            if W[i, j] != 0.0:
                indices[p] = j
                data[p] = W[i, j]
                p += 1
    return indptr, indices, data


@inline_kernel
def sticking(Wc, base, mu, d, out):
    """Whether the contact sticks: r = −W_cc⁻¹b (u = 0) lies in K_μ; r is then written into
    ``out[0:d]`` (Cramer's rule, d = 2 or 3)."""
    if d == 2:
        stuck, rn, r1 = planar_sticking(Wc[0, 0], Wc[0, 1], Wc[1, 0], Wc[1, 1], base[0],
                                        base[1], mu)
        if stuck:
            out[0] = rn
            out[1] = r1
        return stuck
    c00 = Wc[1, 1] * Wc[2, 2] - Wc[1, 2] * Wc[2, 1]
    c01 = Wc[1, 2] * Wc[2, 0] - Wc[1, 0] * Wc[2, 2]
    c02 = Wc[1, 0] * Wc[2, 1] - Wc[1, 1] * Wc[2, 0]
    det = Wc[0, 0] * c00 + Wc[0, 1] * c01 + Wc[0, 2] * c02
    if det == 0.0:
        return False
    c10 = Wc[0, 2] * Wc[2, 1] - Wc[0, 1] * Wc[2, 2]
    c11 = Wc[0, 0] * Wc[2, 2] - Wc[0, 2] * Wc[2, 0]
    c12 = Wc[0, 1] * Wc[2, 0] - Wc[0, 0] * Wc[2, 1]
    c20 = Wc[0, 1] * Wc[1, 2] - Wc[0, 2] * Wc[1, 1]
    c21 = Wc[0, 2] * Wc[1, 0] - Wc[0, 0] * Wc[1, 2]
    c22 = Wc[0, 0] * Wc[1, 1] - Wc[0, 1] * Wc[1, 0]
    rn = -(c00 * base[0] + c10 * base[1] + c20 * base[2]) / det
    r1 = -(c01 * base[0] + c11 * base[1] + c21 * base[2]) / det
    r2 = -(c02 * base[0] + c12 * base[1] + c22 * base[2]) / det
    if not (rn >= 0.0 and np.sqrt(r1 * r1 + r2 * r2) <= mu * rn):
        return False
    out[0] = rn
    out[1] = r1
    out[2] = r2
    return True


@inline_kernel
def exact_contact(Wc, base, mu, d, out):
    """One contact's local problem solved exactly where a closed form holds, the other
    contacts held: u = W_cc r + b, K_μ ∋ r ⟂ ũ ∈ K*_μ (docs/theory.md §15). Its cases —
    apart (r = 0, where b_n ≥ 0), sticking (u = 0, :func:`sticking`) and, for a planar
    contact (d = 2), sliding either way (u_n = 0, r_t = ∓μ r_n, where r_n ≥ 0 and u_t has the
    sliding sign) — are tried in turn; r is written into ``out[0:d]`` for the first that
    holds. Returns False (``out`` untouched) where none does in floats: a sliding 3-D
    contact, left to the caller's projected fixed point."""
    if d == 2:  # the planar cases, in scalars
        solved, rn, rt = planar_contact(Wc[0, 0], Wc[0, 1], Wc[1, 0], Wc[1, 1], base[0],
                                        base[1], mu)
        if solved:
            out[0] = rn
            out[1] = rt
        return solved
    if base[0] >= 0.0:
        for j in range(d):
            out[j] = 0.0
        return True
    return sticking(Wc, base, mu, d, out)

__all__ = ["diagonal_blocks", "extreme_sum", "local_steps", "exact_contact", "nonzero_rows",
           "sticking"]


@kernel(internal=True)
def densified(rows, size):
    """(W, its diagonal) as dense arrays from W's nonzero compressed ``rows`` (indptr,
    indices, data) of ``size`` rows: for a Newton step on the dense W of a few contacts."""
    indptr, indices, data = rows
    dense = np.zeros((size, size))
    diagonal = np.empty(size)
    for i in range(size):
        for p in range(indptr[i], indptr[i + 1]):
            dense[i, indices[p]] += data[p]
        diagonal[i] = dense[i, i]
    return dense, diagonal
