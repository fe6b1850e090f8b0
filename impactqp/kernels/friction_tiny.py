"""A local frictional problem of a few contacts posed, solved and certified in one compiled
call (docs/theory.md §15).

The route of :func:`impactqp.solve_friction` for a small dense problem, without a Python
object on the way: the contacts' units (:func:`impactqp.kernels.units.contact_units`), the
problem in them (W̃ = DWD, q̂ = Dq, D = diag(1/s)), the solve of the ``"kernel"`` method
(:func:`impactqp.kernels.friction_newton.solve_small`), the answer scaled back to the
problem as given (r = r̂/s, u = s∘û) and the certificate of that answer, recomputed from W
and q as given by :func:`impactqp.kernels.coulomb_certificate.friction_figures`. A problem
whose q in contact units needs the scale-first rule (max|q̂ᵢ| outside 1e±100) is left to
the general route, which applies it. The posing of W by its nonzero rows
(:func:`posed_rows`) and the certificate (:func:`judged`) serve the packed route of
:mod:`impactqp.kernels.friction_packed` too.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .coulomb_certificate import FRICTION_FIGURES, friction_figures
from .friction import natural_map_into
from .friction_newton import scales, solve_small
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
def judged(rw, uw, u, s, qu, mu, d, tol, figures, F):
    """The certificate of an answer (r, u) as given, from r̂ = s∘r in ``rw`` and
    û = W̃r̂ + q̂ in ``uw`` recomputed by the caller from W̃ and q̂: the figures of
    :func:`~impactqp.kernels.coulomb_certificate.friction_figures` into ``figures``, with
    ‖F(r̂, û)‖ (F written into ``F``, d·m floats) and ‖u/s − û‖. Returns
    :data:`CERTIFIED` when each residual is within ``tol`` (a NaN fails), else
    :data:`NOT_CERTIFIED`."""
    mismatch = 0.0
    for i in range(u.size):
        gap = u[i] / s[i] - uw[i]
        mismatch += gap * gap
    natural_map_into(rw, uw, mu, d, F)
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
    return its, judged(ru, uw, u, s, qu, mu, d, limits.tol, figures, np.empty(size)), scaled


@inline_kernel(interpretable=True)
def row_products(indptr, indices, data, x, q, out):
    """out = A x + q for A given by its compressed rows."""
    for i in range(q.size):
        total = q[i]
        for p in range(indptr[i], indptr[i + 1]):
            total += data[p] * x[indices[p]]
        out[i] = total


@inline_kernel(interpretable=True)
def posed_rows(W, rows, q, d):
    """The problem in its contacts' units, W̃ = DWD by its nonzero compressed rows and
    q̂ = Dq (D = diag(1/s), s of :func:`_units`), from W dense or compressed (as
    :func:`~impactqp.kernels.friction_packed.pack` takes it): one pass over W's entries.

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


__all__ = ["CERTIFIED", "FRICTION_FIGURES", "LOG2_RANGE", "NEEDS_SCALING", "NOT_CERTIFIED",
           "TinyLimits", "judged", "posed_rows", "row_products", "solve_tiny"]
