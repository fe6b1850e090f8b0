"""W by contacts, as the projected Gauss–Seidel reads it (docs/theory.md §15): each contact's
rows as a list of the other contacts it touches with their d × d blocks W_cj, contiguous, and
its diagonal block W_cc apart. A contact's free velocity b_c = q_c + Σ_{j≠c} W_cj r_j is then
a short loop over whole blocks, each reading r_j once, with d independent sums, where W's
compressed rows give one long dependent sum per row (measured on FC2D-00727, 367 planar
contacts, 6306 entries: the products of one sweep 3.8 µs by blocks, 20–25 µs by rows).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .jit import inline_kernel, kernel


class ContactRows(NamedTuple):
    """W by contacts (:func:`contact_rows`).

    Attributes
    ----------
    start : (m + 1,) int64 array
        Contact c's blocks are ``start[c]:start[c + 1]``.
    other : int64 array
        The contact j of each block.
    block : (blocks, d, d) float array
        W_cj of each block.
    diagonal : (m, d, d) float array
        W_cc.
    """

    start: np.ndarray
    other: np.ndarray
    block: np.ndarray
    diagonal: np.ndarray


@kernel(interpretable=True)
def contact_rows(indptr, indices, data, m, d):
    """W of m contacts (d rows each) given by its compressed rows (scipy's CSR ``indptr``,
    ``indices``, ``data``; duplicates summed) as a :class:`ContactRows`: two passes over W's
    entries, the contacts a contact touches in the order its rows first name them."""
    owner = np.empty(m * d, dtype=np.int64)
    for c in range(m):
        for i in range(d):
            owner[c * d + i] = c
    seen = np.full(m, -1, dtype=np.int64)
    start = np.zeros(m + 1, dtype=np.int64)
    for c in range(m):
        count = 0
        for p in range(indptr[c * d], indptr[c * d + d]):
            j = owner[indices[p]]
            if j != c and seen[j] != c:
                seen[j] = c
                count += 1
        start[c + 1] = start[c] + count
    other = np.empty(start[m], dtype=np.int64)
    block = np.zeros((start[m], d, d))
    diagonal = np.zeros((m, d, d))
    where = np.empty(m, dtype=np.int64)
    seen[:] = -1
    for c in range(m):
        at = start[c]
        for i in range(d):
            for p in range(indptr[c * d + i], indptr[c * d + i + 1]):
                j = owner[indices[p]]
                e = indices[p] - j * d
                if j == c:
                    diagonal[c, i, e] += data[p]
                    continue
                if seen[j] != c:
                    seen[j] = c
                    where[j] = at
                    other[at] = j
                    at += 1
                block[where[j], i, e] += data[p]
    return ContactRows(start, other, block, diagonal)


@inline_kernel
def off_diagonal(start, other, block, q, r, c, d):
    """b_c = q_c + Σ_{j≠c} W_cj r_j, the velocity of contact c with its own reaction left
    out, from W by contacts (:class:`ContactRows`' ``start``, ``other``, ``block``, taken out
    of the tuple once by the caller: an array read from a tuple at each contact costs more
    than the block's arithmetic). Returns its d = 2 or 3 entries, then 0 for d = 2."""
    k = c * d
    b0, b1 = q[k], q[k + 1]
    b2 = q[k + 2] if d == 3 else 0.0
    for p in range(start[c], start[c + 1]):
        j = d * other[p]
        r0, r1 = r[j], r[j + 1]
        if d == 2:
            b0 += block[p, 0, 0] * r0 + block[p, 0, 1] * r1
            b1 += block[p, 1, 0] * r0 + block[p, 1, 1] * r1
        else:
            r2 = r[j + 2]
            b0 += block[p, 0, 0] * r0 + block[p, 0, 1] * r1 + block[p, 0, 2] * r2
            b1 += block[p, 1, 0] * r0 + block[p, 1, 1] * r1 + block[p, 1, 2] * r2
            b2 += block[p, 2, 0] * r0 + block[p, 2, 1] * r1 + block[p, 2, 2] * r2
    return b0, b1, b2


@inline_kernel
def velocity_into(rows, q, r, d, u):
    """``u`` = W r + q from W by contacts ``rows``: b_c (:func:`off_diagonal`) plus
    W_cc r_c, contact by contact (d = 2 or 3)."""
    start, other, block, diagonal = rows
    for c in range(diagonal.shape[0]):
        k = c * d
        b0, b1, b2 = off_diagonal(start, other, block, q, r, c, d)
        u[k], u[k + 1] = b0, b1
        if d == 3:
            u[k + 2] = b2
        for i in range(d):
            for e in range(d):
                u[k + i] += diagonal[c, i, e] * r[k + e]


__all__ = ["ContactRows", "contact_rows", "off_diagonal", "velocity_into"]
