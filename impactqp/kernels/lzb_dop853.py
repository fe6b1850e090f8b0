"""DOP853's step on the components of one LZB piece (docs/theory.md §13).

A piece steps only the components of its live contacts, ``comps[:nc]`` of x = (z, P, D). The
step works on them contiguously, c < nc (the tableau's combinations then run along rows and
vectorize); the rates (:func:`impactqp.kernels.lzb_model.rates`) read the full state, into
which each stage is scattered, and their components are gathered back. The coefficients
and the step-size control are scipy's (Dop853 and its dense output).
"""

from __future__ import annotations

import numpy as np

from .jit import inline_kernel, kernel
from .lzb_model import rates


@inline_kernel
def combine(K, coefficients, nc, out):
    """out[c] = Σ_q coefficients[q] K[q, c] for c < nc (row by row, skipping the tableau's
    zeros). The number of rows is read from the array, not written as a constant, so that
    the compiler does not unroll the rows into a copy of the loop each (the code, and its
    compile time, grow tenfold)."""
    for c in range(nc):
        out[c] = 0.0
    for q in range(coefficients.size):
        a = coefficients[q]
        if a != 0.0:
            for c in range(nc):
                out[c] += a * K[q, c]


@inline_kernel
def evaluate(xc, piece, impact, stages, row):
    """row = the rates at the components xc (scattered into the full state), on the
    components."""
    k, live, nlive, comps, nc = piece.k, piece.live, piece.nlive, piece.comps, piece.nc
    indptr, indices, data, gamma0, law = impact
    xs, rate = stages.xs, stages.rate
    for c in range(nc):
        xs[comps[c]] = xc[c]
    rates(xs, k, live, nlive, indptr, indices, data, gamma0, law, stages.gamma, rate)
    for c in range(nc):
        row[c] = rate[comps[c]]


@kernel(refcounted=False, internal=True)
def stage(s, x, h, piece, impact, A, stages):
    """Stage s of a step of length h from x: xc = x + h Σ_{q<s} A[s, q] K[q], then K[s]
    there (one compiled stage serves the step and its dense output)."""
    K, xc, nc = stages.K, stages.xc, piece.nc
    combine(K, A[s], nc, xc)  # A is strictly lower triangular
    for c in range(nc):
        xc[c] = x[c] + h * xc[c]
    evaluate(xc, piece, impact, stages, K[s])


@kernel(refcounted=False, internal=True)
def rk_step(x, h, piece, impact, tableau, stages, out):
    """One DOP853 step of length h from x (K[0] = its rates) into ``out``, stages into K."""
    for s in range(1, tableau.B.size):
        stage(s, x, h, piece, impact, tableau.A, stages)
    nc = piece.nc
    combine(stages.K, tableau.B, nc, out)
    for c in range(nc):
        out[c] = x[c] + h * out[c]


@kernel(refcounted=False, internal=True)
def error_norm(x, x_new, h, nc, n, tableau, K, e5, e3):
    """h‖err‖ of the step from x to x_new: scipy's RMS over all n components of the 5th-order
    estimate, corrected by the 3rd-order one, relative to 1 + |x| (the frozen components
    count, with no error)."""
    combine(K, tableau.E5, nc, e5)
    combine(K, tableau.E3, nc, e3)
    err5, err3 = 0.0, 0.0
    for c in range(nc):
        scale = 1.0 + max(abs(x[c]), abs(x_new[c]))
        err5 += (e5[c] / scale) ** 2
        err3 += (e3[c] / scale) ** 2
    if err5 == 0.0 and err3 == 0.0:
        return 0.0
    return h * err5 / np.sqrt((err5 + 0.01 * err3) * n)


@kernel(refcounted=False, internal=True)
def dense_output(x, x_new, h, piece, impact, tableau, stages, F):
    """F = the coefficients of the step's 7th-order dense output (three more stages)."""
    K, nc = stages.K, piece.nc
    for s in range(tableau.E5.size, tableau.A.shape[0]):
        stage(s, x, h, piece, impact, tableau.A, stages)
    for r in range(tableau.D.shape[0]):
        combine(K, tableau.D[r], nc, F[3 + r])
    for c in range(nc):
        delta = x_new[c] - x[c]
        F[0, c] = delta
        F[1, c] = h * K[0, c] - delta
        F[2, c] = 2.0 * delta - h * (K[12, c] + K[0, c])
        for r in range(3, F.shape[0]):
            F[r, c] *= h


@inline_kernel
def interpolate(F, x_old, theta, nc, out):
    """DOP853's dense output at θ ∈ [0, 1] of the step (scipy's Dop853DenseOutput)."""
    rows = F.shape[0]
    for c in range(nc):
        v = 0.0
        for r in range(rows - 1, -1, -1):
            v += F[r, c]
            v *= theta if (rows - 1 - r) % 2 == 0 else 1.0 - theta
        out[c] = v + x_old[c]


@inline_kernel
def scatter(xc, comps, nc, out):
    """out[comps[c]] = xc[c] for c < nc."""
    for c in range(nc):
        out[comps[c]] = xc[c]
