"""The projected Gauss–Seidel of a problem of a few contacts, on W's compressed rows and its
diagonal blocks kept packed, each contact's local problem solved exactly where it has a
solution — apart, sticking, a planar contact by its cases, a 3-D contact sliding by its slip
angle — as the compiled call of a few contacts sweeps it (docs/theory.md §15;
:mod:`impactqp.kernels.friction_packed`). The general route's sweeps, on W by contacts, are
:func:`impactqp.kernels.friction.nsgs_contacts`.
"""

from __future__ import annotations

import numpy as np

from .friction import contact_steps, next_check, relative_error
from .friction_blocks import sticking
from .friction_planar import planar_contact
from .friction_slip import sliding_3d, sliding_from
from .jit import inline_kernel, kernel


@inline_kernel
def nsgs_blocks(rows, blocks, q, mu, d, r, tol, max_sweeps, local_iters):
    """:func:`~impactqp.kernels.friction.nsgs_contacts` by :func:`sweep_once` on W's
    compressed ``rows`` (scipy's CSR arrays) and ``blocks`` = (W_cc, ρ_c)
    (:func:`~impactqp.kernels.friction_blocks.local_steps`), which a caller solving W again
    keeps: a few sweeps of a few contacts, where gathering W by contacts at each call costs
    more than it saves (LMGC-00046: 2 µs a call), each 3-D contact sliding solved by its slip
    angle (``slip`` of :func:`sweep_once`)."""
    indptr, indices, data = rows
    n = r.size
    slip = np.bool_(True)  # not a literal: one compiled sweep_once serves solve_packed too
    u, F, scratch = np.empty(n), np.empty(n), np.empty(3 * d)
    err, last_err, last_at, check_at = np.inf, np.inf, 0, 1
    for sweep in range(max_sweeps):
        sweep_once(rows, blocks, q, mu, d, r, local_iters, slip, scratch)
        done = sweep + 1
        if done < check_at and done < max_sweeps:
            continue
        for i in range(n):
            v = q[i]
            for p in range(indptr[i], indptr[i + 1]):
                v += data[p] * r[indices[p]]
            u[i] = v
        err = relative_error(r, u, q, mu, d, F)
        if err <= tol:
            return done, err
        last_err, last_at, check_at = err, done, next_check(done, err, tol, last_err, last_at)
    return max_sweeps, err


@kernel(internal=True, refcounted=False)
def sweep_once(rows, blocks, q, mu, d, r, local_iters, slip, scratch):
    """One sweep over the contacts on W's compressed ``rows`` and ``blocks`` (as
    :func:`nsgs_blocks` takes them), updating ``r`` in place (``scratch``: ≥ 3·d floats).
    A contact is apart (r_c = 0) where its normal row gives b_n ≥ 0, before its tangential
    rows are summed (41 of NESpheres-30's 44 contacts in its one sweep); a planar contact is
    solved by its cases in scalars (:func:`~impactqp.kernels.friction_planar.planar_contact`)
    in the loop itself (in an inlined helper numba compiled them ten times slower); with
    ``slip``, a 3-D contact that neither separates nor sticks is solved sliding by its slip
    angle (by Newton from its last one, :func:`~impactqp.kernels.friction_slip.sliding_from`,
    else :func:`~impactqp.kernels.friction_slip.sliding_3d`), so that every local problem
    with a solution is solved exactly (docs/theory.md §15); any other contact by
    :func:`~impactqp.kernels.friction.contact_steps`."""
    indptr, indices, data = rows
    Wcc, rhos = blocks
    for c in range(mu.size):
        k = c * d
        for i in range(d):
            v = q[k + i]
            for p in range(indptr[k + i], indptr[k + i + 1]):
                v += data[p] * r[indices[p]]
            for j in range(d):
                v -= Wcc[c, i, j] * r[k + j]
            scratch[2 * d + i] = v
            if i == 0 and v >= 0.0:
                break
        if scratch[2 * d] >= 0.0:  # apart
            for i in range(d):
                r[k + i] = 0.0
            continue
        if d == 2:
            exact, rn, rt = planar_contact(Wcc[c, 0, 0], Wcc[c, 0, 1], Wcc[c, 1, 0],
                                           Wcc[c, 1, 1], scratch[4], scratch[5], mu[c])
            if exact:
                r[k], r[k + 1] = rn, rt
                continue
        elif slip and (sticking(Wcc[c], scratch[2 * d:], mu[c], d, scratch)
                       or sliding_from(Wcc[c], scratch[2 * d:], mu[c], r[k + 1], r[k + 2],
                                       scratch)
                       or sliding_3d(Wcc[c], scratch[2 * d:], mu[c], scratch)):
            for i in range(d):
                r[k + i] = scratch[i]
            continue
        contact_steps(Wcc, rhos, mu, c, d, r, local_iters, scratch)


__all__ = ["nsgs_blocks", "sweep_once"]
