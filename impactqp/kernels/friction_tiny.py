"""A local frictional problem of a few contacts posed, solved and certified in one compiled
call (docs/theory.md §15).

The route of :func:`impactqp.solve_friction` for a small dense problem, without a Python
object on the way: the contacts' units (:func:`impactqp.kernels.units.contact_units`), the
problem in them (W̃ = DWD, q̂ = Dq, D = diag(1/s)), the solve of the ``"kernel"`` method
(:func:`impactqp.kernels.friction_newton.solve_small`), the answer scaled back to the
problem as given (r = r̂/s, u = s∘û) and the certificate of that answer, recomputed from W
and q as given by :func:`impactqp.kernels.coulomb_certificate.friction_figures`. A problem
whose q in contact units needs the scale-first rule (max|q̂ᵢ| outside 1e±100) is left to
the general route, which applies it.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .coulomb_certificate import FRICTION_FIGURES, friction_figures
from .friction import natural_map, nsgs_rows
from .friction_newton import ROUND_OFF, scales, solve_small, sweeps_on
from .friction_slip import sliding_alone
from .jit import inline_kernel, kernel
from .units import contact_units

CERTIFIED, NOT_CERTIFIED, NEEDS_SCALING = 0, 1, 2
"""The outcomes of :func:`solve_tiny`."""

LOG2_RANGE = (-333, 333)
"""The binary exponents (``math.frexp``) of max|q̂ᵢ|, strictly between these two, for which
q̂ is posed as it is: those of :data:`impactqp.model.friction.QUANTITY_RANGE`, 1e-100…1e100
(docs/theory.md §15)."""


class TinyLimits(NamedTuple):
    """The tolerance and the budgets of the ``"kernel"`` method.

    Attributes
    ----------
    tol : float
        Tolerance of the certificate.
    newton_steps, sweeps, local_iters : int
        Newton steps per run, NSGS sweeps, local iterations per contact and sweep.
    """

    tol: float
    newton_steps: int
    sweeps: int
    local_iters: int


@inline_kernel(interpretable=True)
def _units(diagonal, q, d):
    """The contacts' units s of W's ``diagonal``
    (:func:`impactqp.kernels.units.contact_units`), whether one is not 1, and whether q̂ = q/s
    is posed as it is (the binary exponent of max|q̂ᵢ| within :data:`LOG2_RANGE`; 0 when
    q = 0)."""
    s = contact_units(diagonal, d)
    scaled = False
    for i in range(q.size):
        scaled = scaled or s[i] != 1.0
    top = 0
    found = False
    for i in range(q.size):
        if q[i] != 0.0:
            e = math.frexp(q[i])[1] - math.frexp(s[i])[1]
            top = e if not found else max(top, e)
            found = True
    return s, scaled, LOG2_RANGE[0] < top < LOG2_RANGE[1]


@inline_kernel(interpretable=True)
def _judged(rw, uw, u, s, qu, mu, d, tol, figures):
    """The certificate of an answer (r, u) as given, from r̂ = s∘r in ``rw`` and
    û = W̃r̂ + q̂ in ``uw`` recomputed by the caller from W̃ and q̂: the figures of
    :func:`~impactqp.kernels.coulomb_certificate.friction_figures` into ``figures``, with
    ‖F(r̂, û)‖ and ‖u/s − û‖. Returns :data:`CERTIFIED` when each residual is within
    ``tol`` (a NaN fails), else :data:`NOT_CERTIFIED`."""
    mismatch = 0.0
    for i in range(u.size):
        gap = u[i] / s[i] - uw[i]
        mismatch += gap * gap
    F = natural_map(rw, uw, mu, d)
    f_norm = 0.0
    for i in range(u.size):
        f_norm += F[i] * F[i]
    friction_figures(rw, uw, qu, mu, d, (np.sqrt(f_norm), np.sqrt(mismatch)), figures)
    for i in range(5):
        if not figures[i] <= tol:  # NaN fails
            return NOT_CERTIFIED
    return CERTIFIED


@kernel(interpretable=True)
def solve_tiny(W, q, mu, d, limits, r, u, figures):
    """Solve and certify ``u = W r + q, K_μ ∋ r ⟂ ũ ∈ K*_μ`` for a dense W of a few contacts.

    Parameters
    ----------
    W : (d·m, d·m) float array
    q : (d·m,) float array
    mu : (m,) float array
    d : int
        Entries per contact (2 or 3).
    limits : TinyLimits
    r, u : (d·m,) float arrays
        Receive the reaction and the velocity, in the problem's units.
    figures : (7,) float array
        Receives the certificate's figures (order
        :data:`~impactqp.kernels.coulomb_certificate.FRICTION_FIGURES`).

    Returns
    -------
    (iterations, outcome, scaled)
        ``outcome`` is :data:`CERTIFIED` (every residual within ``limits.tol``),
        :data:`NOT_CERTIFIED` or :data:`NEEDS_SCALING` (nothing solved); ``scaled`` whether
        some contact's unit is not 1 (the problem was posed in other units than given).
    """
    size = q.size
    diagonal = np.empty(size)
    for i in range(size):
        diagonal[i] = W[i, i]
    s, scaled, posable = _units(diagonal, q, d)
    if not posable:
        return 0, NEEDS_SCALING, True
    Wu = np.empty((size, size))
    qu = np.empty(size)
    for i in range(size):
        qu[i] = q[i] / s[i]
        for j in range(size):
            Wu[i, j] = W[i, j] * (1.0 / s[i]) * (1.0 / s[j])
            if not math.isfinite(Wu[i, j]):
                return 0, NEEDS_SCALING, True
    for i in range(size):
        diagonal[i] = Wu[i, i]
    ru = np.empty(size)
    its, _ = solve_small(Wu, qu, mu, scales(diagonal, d), d, limits.tol, ru,
                         limits.newton_steps, limits.sweeps, limits.local_iters)
    for i in range(size):  # the answer as given: r = r̂/s, u = s∘(W̃r̂ + q̂)
        r[i] = ru[i] / s[i]
    for i in range(size):
        total = qu[i]
        for j in range(size):
            total += Wu[i, j] * ru[j]
        u[i] = total * s[i]
    # its certificate, from r and u as given: r̂ = s∘r, û = W̃r̂ + q̂
    for i in range(size):
        ru[i] = r[i] * s[i]
    uw = np.empty(size)
    for i in range(size):
        total = qu[i]
        for j in range(size):
            total += Wu[i, j] * ru[j]
        uw[i] = total
    return its, _judged(ru, uw, u, s, qu, mu, d, limits.tol, figures), scaled


@inline_kernel(interpretable=True)
def _row_products(indptr, indices, data, x, q, out):
    """out = A x + q for A given by its compressed rows."""
    for i in range(q.size):
        total = q[i]
        for p in range(indptr[i], indptr[i + 1]):
            total += data[p] * x[indices[p]]
        out[i] = total


@inline_kernel(interpretable=True)
def _posed(W, rows, q, d):
    """The problem in its contacts' units, W̃ = DWD by its nonzero compressed rows and
    q̂ = Dq (D = diag(1/s), s of :func:`_units`), from W dense or compressed (as
    :func:`solve_given` takes it): one pass over W's entries.

    Returns
    -------
    (s, scaled, posed, indptr, indices, data, q̂)
        ``posed`` False where q̂ needs the scale-first rule or an entry of W̃ is not finite
        (the rest is then not to be used).
    """
    size = q.size
    indptr, indices, data, by_columns = rows
    diagonal = np.zeros(size)
    dense = indptr.size == 0
    if dense:
        for i in range(size):
            diagonal[i] = W[i, i]
    else:
        for a in range(size):
            for p in range(indptr[a], indptr[a + 1]):
                if indices[p] == a:
                    diagonal[a] += data[p]
    s, scaled, posed = _units(diagonal, q, d)
    qu = np.empty(size)
    for i in range(size):
        qu[i] = q[i] / s[i]
    if dense:  # its nonzero entries by rows, room for all of them
        starts = np.zeros(size + 1, dtype=np.int32)
        columns = np.empty(size * size, dtype=np.int32)
        values = np.empty(size * size)
        p = 0
        for i in range(size):
            for j in range(size):
                w = W[i, j]
                if w != 0.0:
                    columns[p] = j
                    values[p] = w
                    p += 1
            starts[i + 1] = p
    elif by_columns:  # the rows of W from its columns, a counting pass
        starts = np.zeros(size + 1, dtype=np.int32)
        for p in range(indices.size):
            starts[indices[p] + 1] += 1
        for i in range(size):
            starts[i + 1] += starts[i]
        at = starts[:size].copy()
        columns = np.empty(indices.size, dtype=np.int32)
        values = np.empty(indices.size)
        for j in range(size):
            for p in range(indptr[j], indptr[j + 1]):
                i = indices[p]
                columns[at[i]] = j
                values[at[i]] = data[p]
                at[i] += 1
    else:
        starts, columns, values = indptr.copy(), indices.copy(), data.copy()
    for i in range(size):  # W̃ = DWD
        for p in range(starts[i], starts[i + 1]):
            values[p] = values[p] * (1.0 / s[i]) * (1.0 / s[columns[p]])
            posed = posed and math.isfinite(values[p])
    return s, scaled, posed, starts, columns, values, qu


@kernel(interpretable=True)
def solve_given(W, rows, q, mu, d, limits, out):
    """Solve and certify a problem of a few contacts, W as the problem holds it (dense or
    compressed), in one call (docs/theory.md §15): posed in its contacts' units by its
    nonzero entries (:func:`_posed`), one sweep of the projected Gauss–Seidel from r = 0
    (:func:`~impactqp.kernels.friction.nsgs_rows`; a single 3-D contact it left sliding is
    solved sliding by its slip angle, :func:`~impactqp.kernels.friction_slip.sliding_alone`),
    more by :func:`~impactqp.kernels.friction_newton.sweeps_on` while their rate is worth it,
    ended where needed by one Newton step to round-off (as the ``"kernel"`` method answers,
    without its restart from r = 0). Their answer is kept where it is within tol/2;
    otherwise, with ``whole``, the method whole by :func:`solve_tiny`. The answer is scaled
    back (r = r̂/s) and certified from r as given
    (r̂ = s∘r, û = W̃r̂ + q̂ recomputed, the velocity given u = s∘û: W r + q, the product
    the sweeps' own ‖F‖ did not share).

    Parameters
    ----------
    W : (d·m, d·m) float array
        W when it is dense; ignored (any 2-D float array) when ``rows`` hold it.
    rows : (indptr, indices, data, by_columns)
        W compressed as scipy keeps it (CSR rows, or CSC columns when ``by_columns``; int32
        indices), duplicates summed; empty arrays (``indptr`` of size 0) when W is dense.
    q, mu, d
        As for :func:`solve_tiny`.
    limits : (tol, newton_steps, sweeps, local_iters, whole)
        The fields of :class:`TinyLimits` as a plain tuple (numba types a NamedTuple at
        each call in about 2 µs, a plain tuple in a few hundred ns), and ``whole``: False to
        end after the first sweep (then kept where it is within tol/2, the first sweep of
        the ``"nsgs-short"`` method, with ``local_iters`` of that method).
    out : (2·d·m + 7,) float array
        Receives r, u and the figures of the certificate, in that order.

    Returns
    -------
    (iterations, outcome, scaled), as :func:`solve_tiny`; :data:`NOT_CERTIFIED` without
    ``whole`` where the first sweep did not reach tol/2 (``out`` then unspecified).
    """
    size = q.size
    tol, newton_steps, sweeps, local_iters, whole = limits
    s, scaled, posed, indptr, indices, data, qu = _posed(W, rows, q, d)
    if not posed:
        return 0, NEEDS_SCALING, True
    r, u, figures = out[:size], out[size:2 * size], out[2 * size:]
    target = ROUND_OFF if whole else 0.5 * tol
    ru = np.zeros(size)
    ask = np.int64(1)  # an int64, not a literal 1: one compiled sweep
    done, err = nsgs_rows(indptr, indices, data, qu, mu, d, ru, target, ask, local_iters)
    if whole and err > target and size == 3 and d == 3:  # one contact, sliding
        err = sliding_alone(indptr, indices, data, qu, mu, ru, err)
    if whole:
        done, err = sweeps_on((indptr, indices, data), qu, mu, d, ru, tol, local_iters, done,
                              err)
    if err <= 0.5 * tol:  # target, or within tol and taken to round-off
        for i in range(size):  # the answer as given, r = r̂/s, and r̂ = s∘r from it
            r[i] = ru[i] / s[i]
            ru[i] = r[i] * s[i]
        uw = np.empty(size)  # û = W̃r̂ + q̂ of the certificate; u = s∘û (W r + q as given)
        _row_products(indptr, indices, data, ru, qu, uw)
        for i in range(size):
            u[i] = uw[i] * s[i]
        return done, _judged(ru, uw, u, s, qu, mu, d, tol, figures), scaled
    if not whole:
        return done, NOT_CERTIFIED, scaled
    given, positions, entries, by_columns = rows
    if given.size == 0:  # W dense: solve_tiny poses it again
        dense = W
    else:  # W as given, dense, duplicates summed
        dense = np.zeros((size, size))
        for a in range(size):
            for p in range(given[a], given[a + 1]):
                if by_columns:
                    dense[positions[p], a] += entries[p]
                else:
                    dense[a, positions[p]] += entries[p]
    its, outcome, scaled = solve_tiny(dense, q, mu, d,
                                      TinyLimits(tol, newton_steps, sweeps, local_iters),
                                      r, u, figures)
    return done + its, outcome, scaled


__all__ = ["CERTIFIED", "FRICTION_FIGURES", "LOG2_RANGE", "NEEDS_SCALING", "NOT_CERTIFIED",
           "TinyLimits", "solve_given", "solve_tiny"]
