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
from .friction import natural_map
from .friction_newton import scales, solve_small
from .jit import kernel
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
    s = contact_units(diagonal, d)
    scaled = False
    for i in range(size):
        scaled = scaled or s[i] != 1.0
    top = 0  # the binary exponent of max|qᵢ/sᵢ| (0 when q = 0)
    found = False
    for i in range(size):
        if q[i] != 0.0:
            e = math.frexp(q[i])[1] - math.frexp(s[i])[1]
            top = e if not found else max(top, e)
            found = True
    if not LOG2_RANGE[0] < top < LOG2_RANGE[1]:
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
    # its certificate, from r and u as given: r̂ = s∘r, û = W̃r̂ + q̂, ‖u/s − û‖
    for i in range(size):
        ru[i] = r[i] * s[i]
    uw = np.empty(size)
    mismatch = 0.0
    for i in range(size):
        total = qu[i]
        for j in range(size):
            total += Wu[i, j] * ru[j]
        uw[i] = total
        gap = u[i] / s[i] - total
        mismatch += gap * gap
    f_norm = 0.0
    F = natural_map(ru, uw, mu, d)
    for i in range(size):
        f_norm += F[i] * F[i]
    friction_figures(ru, uw, qu, mu, d, (np.sqrt(f_norm), np.sqrt(mismatch)), figures)
    for i in range(5):
        if not figures[i] <= limits.tol:  # NaN fails
            return its, NOT_CERTIFIED, scaled
    return its, CERTIFIED, scaled


__all__ = ["CERTIFIED", "FRICTION_FIGURES", "LOG2_RANGE", "NEEDS_SCALING", "NOT_CERTIFIED",
           "TinyLimits", "solve_tiny"]
