"""A local frictional problem of a few contacts packed once and solved in one compiled call
(docs/theory.md §15).

:func:`pack` poses a problem as given (W dense or compressed) in its contacts' units
(:func:`impactqp.kernels.friction_tiny.posed_rows`) and packs it with what its sweeps read;
:func:`solve_packed` solves and certifies it, and a caller solving the same problem again
keeps the pack and calls :func:`solve_packed` alone. They are two calls from Python, not
one kernel calling both: numba links the code of every kernel a kernel calls into the
caller and optimises it again there, and a kernel over :func:`solve_packed` cost 6–10 s of
CPU of ``impactqp compile`` for the ~1 µs of a call it saved on a first solve. The certificate is
recomputed from r as given by :func:`impactqp.kernels.friction_tiny.judged`.
"""

from __future__ import annotations

import numpy as np

from .friction_blocks import densified, diagonal_blocks, local_steps
from .friction_newton import ROUND_OFF, scales, solve_small, sweeps_on
from .friction_sweep import sweep_once
from .friction_tiny import (
    CERTIFIED,
    FRICTION_FIGURES,
    NEEDS_SCALING,
    NOT_CERTIFIED,
    judged,
    posed_rows,
    row_products,
)
from .jit import inline_kernel, kernel

FIGURE_COUNT = len(FRICTION_FIGURES)
"""The certificate's figures in the array a solve fills, after r and u."""
PACKED_HEADER = 9
"""Leading entries of the integer array of :func:`pack`: d·m, d, m, the entries of W̃ kept,
whether some contact's unit is not 1, whether the problem is posed, then the budgets
(Newton steps, sweeps, local iterations) and ``whole``."""


@kernel(interpretable=True)
def pack(W, rows, q, mu, d, budgets):
    """A problem of a few contacts posed in its contacts' units
    (:func:`~impactqp.kernels.friction_tiny.posed_rows`) with what its sweeps read (W̃'s
    diagonal blocks and their local steps) and the budgets of its solve, in two arrays, so
    that a solve of the same problem again (:func:`solve_packed`) starts from them: numba
    takes each array argument of a call from Python for about 0.3 µs, and returns one for
    about 1 µs, so the problem travels as two (docs/theory.md §15).

    Parameters
    ----------
    W : (d·m, d·m) float array
        W when it is dense; ignored (any 2-D float array) when ``rows`` hold it.
    rows : (indptr, indices, data, by_columns)
        W compressed as scipy keeps it (CSR rows, or CSC columns when ``by_columns``; int32
        indices), duplicates summed; empty arrays (``indptr`` of size 0) when W is dense.
    q, mu, d
        As for :func:`~impactqp.kernels.friction_tiny.solve_tiny`.
    budgets : (newton_steps, sweeps, local_iters, whole)
        The integer fields of :class:`~impactqp.kernels.friction_tiny.TinyLimits` as a plain
        tuple (numba types a NamedTuple at each call in about 2 µs, a plain tuple in a few
        hundred ns), and ``whole``: False to end after the first sweep (then kept where it
        is within tol/2, the first sweep of the ``"nsgs-short"`` method, with
        ``local_iters`` of that method).

    Returns
    -------
    (floats, ints)
        ``ints``: :data:`PACKED_HEADER` entries, then W̃'s ``indptr`` (d·m + 1) and
        ``indices``; ``floats``: s, q̂ (d·m each), μ, the local steps ρ_c (m each), the
        diagonal blocks W̃_cc (m·d·d) and W̃'s entries. Where the problem cannot be posed
        as it is (the header says so) the rest is not to be used.
    """
    size = q.size
    m = mu.size
    s, scaled, posed, indptr, indices, data, qu = posed_rows(W, rows, q, d)
    entries = indptr[size]
    ints = np.empty(PACKED_HEADER + size + 1 + entries, dtype=np.int32)
    newton_steps, sweeps, local_iters, whole = budgets
    ints[0], ints[1], ints[2], ints[3] = size, d, m, entries
    ints[4], ints[5] = scaled, posed
    ints[6], ints[7], ints[8] = newton_steps, sweeps, local_iters
    for i in range(size + 1):  # loops: a slice copy compiles numba's shape errors
        ints[PACKED_HEADER + i] = indptr[i]
    for p in range(entries):
        ints[PACKED_HEADER + size + 1 + p] = indices[p]
    block = m * d * d
    floats = np.empty(2 * size + 2 * m + block + entries)
    for i in range(size):
        floats[i] = s[i]
        floats[size + i] = qu[i]
    Wcc = diagonal_blocks(indptr, indices, data, m, d)
    rhos = local_steps(Wcc)
    for c in range(m):
        floats[2 * size + c] = mu[c]
        floats[2 * size + m + c] = rhos[c]
        for a in range(d):
            for b in range(d):
                floats[2 * size + 2 * m + (c * d + a) * d + b] = Wcc[c, a, b]
    for p in range(entries):
        floats[2 * size + 2 * m + block + p] = data[p]
    if not whole:
        ints[8] = -local_iters - 1  # the sign carries ``whole``: one int32 array
    return floats, ints


@inline_kernel(interpretable=True)
def _unpacked(floats, ints):
    """The arrays of :func:`pack` as views: (s, q̂, μ, (indptr, indices, data), (W̃_cc, ρ),
    d, scaled, posed, (newton_steps, sweeps, local_iters, whole))."""
    size, d, m, entries = ints[0], ints[1], ints[2], ints[3]
    block = m * d * d
    indptr = ints[PACKED_HEADER:PACKED_HEADER + size + 1]
    indices = ints[PACKED_HEADER + size + 1:PACKED_HEADER + size + 1 + entries]
    s = floats[:size]
    qu = floats[size:2 * size]
    mu = floats[2 * size:2 * size + m]
    rhos = floats[2 * size + m:2 * size + 2 * m]
    Wcc = floats[2 * size + 2 * m:2 * size + 2 * m + block].reshape((m, d, d))
    data = floats[2 * size + 2 * m + block:2 * size + 2 * m + block + entries]
    local = ints[8]
    whole = local >= 0
    budgets = (np.int64(ints[6]), np.int64(ints[7]), np.int64(local if whole else -local - 1),
               whole)
    return (s, qu, mu, (indptr, indices, data), (Wcc, rhos), np.int64(d), ints[4] != 0,
            ints[5] != 0, budgets)


def answer_size(size: int) -> int:
    """The floats of the array ``out`` that :func:`solve_packed` fills
    for a problem of ``size`` = d·m entries: r, u, the certificate's figures, the
    iterations done (at :func:`iterations_at`), then the call's own work (r̂, û, F of d·m
    floats each, and 3·d ≤ 9 for a contact's local problem), taken from the one new array
    a call is given rather than allocated in it (each array numba allocates costs ~25 ns,
    a tenth of a 1-contact certificate)."""
    return 5 * size + FIGURE_COUNT + 10


@inline_kernel(interpretable=True)
def iterations_at(size):
    """Where in ``out`` (:func:`answer_size`) a solve of ``size`` = d·m entries writes the
    iterations it did: after r, u and the figures. Returned in ``out``, so that the call
    returns one integer (numba boxes a returned tuple for ~40 ns)."""
    return 2 * size + FIGURE_COUNT


@inline_kernel(interpretable=True)
def _work(out, size, d):
    """The work views of ``out`` (:func:`answer_size`): (r̂ set to 0, û, F, scratch)."""
    at = iterations_at(size) + 1
    ru = out[at:at + size]
    for i in range(size):
        ru[i] = 0.0
    return (ru, out[at + size:at + 2 * size], out[at + 2 * size:at + 3 * size],
            out[at + 3 * size:at + 3 * size + 3 * d])


@kernel(internal=True)
def _finish(ru, s, rows, qu, mu, d, tol, out):
    """The answer r̂ in ``ru`` scaled back into ``out`` (r = r̂/s) and certified from r as
    given (r̂ = s∘r, û = W̃r̂ + q̂ recomputed from W̃'s ``rows``, the velocity given
    u = s∘û: W r + q), its figures after r and u in ``out``, û and F in its work
    (:func:`answer_size`). Returns the verdict of
    :func:`~impactqp.kernels.friction_tiny.judged`."""
    size = qu.size
    r, u, figures = out[:size], out[size:2 * size], out[2 * size:2 * size + FIGURE_COUNT]
    at = iterations_at(size) + 1 + size
    uw, F = out[at:at + size], out[at + size:at + 2 * size]
    for i in range(size):  # the answer as given, r = r̂/s, and r̂ = s∘r from it
        r[i] = ru[i] / s[i]
        ru[i] = r[i] * s[i]
    # û = W̃r̂ + q̂ of the certificate; u = s∘û (W r + q as given)
    row_products(rows[0], rows[1], rows[2], ru, qu, uw)
    for i in range(size):
        u[i] = uw[i] * s[i]
    return judged(ru, uw, u, s, qu, mu, d, tol, figures, F)


@kernel(interpretable=True)
def solve_packed(floats, ints, tol, out):
    """Solve and certify a problem of a few contacts packed by :func:`pack`, in one call
    (docs/theory.md §15): one sweep of the projected Gauss–Seidel from r = 0 on W̃
    (:func:`~impactqp.kernels.friction_sweep.sweep_once`), with ``whole`` each contact's local
    problem solved exactly where it has a solution (apart, sticking, a planar contact by its
    cases, a 3-D contact sliding by its slip angle,
    :func:`~impactqp.kernels.friction_slip.sliding_3d`), which solves a problem of one
    contact. That answer is certified at once
    (:func:`_finish`: scaled back, r = r̂/s, and recomputed from r as given, r̂ = s∘r,
    û = W̃r̂ + q̂, the velocity given u = s∘û) and kept where it passes with ‖F‖/‖q̂‖ within
    :data:`~impactqp.kernels.friction_newton.ROUND_OFF` (tol/2 without ``whole``): one
    product by W̃ serves as both the sweep's stopping test and the certificate, which
    reads nothing of the sweep but r. Otherwise, with ``whole``, the sweeps go on from
    there by :func:`~impactqp.kernels.friction_newton.sweeps_on` while their rate is worth
    it, ended where needed by one Newton step to round-off (as the ``"kernel"`` method
    answers, without its restart from r = 0), and their answer is kept where it is within
    tol/2; else the ``"kernel"`` method whole
    (:func:`~impactqp.kernels.friction_newton.solve_small`) runs on the dense W̃. Either
    answer is certified again by :func:`_finish`.

    Parameters
    ----------
    floats, ints : ndarray
        The problem as :func:`pack` returns it.
    tol : float
        Tolerance of the certificate.
    out : (:func:`answer_size`,) float array
        Receives r, u, the figures of the certificate and the iterations done (sweeps and
        Newton steps, at :func:`iterations_at`), in that order, then the call's work.

    Returns
    -------
    outcome : int
        As for :func:`~impactqp.kernels.friction_tiny.solve_tiny`; :data:`NOT_CERTIFIED`
        without ``whole`` where the first sweep did not reach tol/2 (``out`` then
        unspecified but for the iterations).
    """
    s, qu, mu, rows, blocks, d, _, posed, budgets = _unpacked(floats, ints)
    size = qu.size
    done = iterations_at(size)
    out[done] = 0.0
    if not posed:
        return NEEDS_SCALING
    newton_steps, sweeps, local_iters, whole = budgets
    ru, _, _, scratch = _work(out, size, d)
    sweep_once(rows, blocks, qu, mu, d, ru, local_iters, whole, scratch)
    out[done] = 1.0
    # the certificate of this answer; its natural map is the sweeps' measure from here
    outcome = _finish(ru, s, rows, qu, mu, d, tol, out)
    err = out[2 * size]
    if outcome == CERTIFIED and err <= (ROUND_OFF if whole else 0.5 * tol):
        return outcome
    if not whole:
        return NOT_CERTIFIED
    swept, err = sweeps_on(rows, blocks, qu, mu, d, ru, tol, local_iters, 1, err)
    out[done] = swept
    if err <= 0.5 * tol:  # within tol and taken to round-off
        return _finish(ru, s, rows, qu, mu, d, tol, out)
    dense, diagonal = densified(rows, size)  # W̃ dense, for the method whole
    its, _ = solve_small(dense, qu, mu, scales(diagonal, d), d, tol, ru, newton_steps, sweeps,
                         local_iters)
    out[done] = swept + its
    return _finish(ru, s, rows, qu, mu, d, tol, out)


__all__ = ["FIGURE_COUNT", "PACKED_HEADER", "answer_size", "iterations_at", "pack",
           "solve_packed"]
