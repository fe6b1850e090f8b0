"""Coulomb friction of local contact problems: the one definition of the projection onto the
friction cone, of De Saxcé's modified velocity, of the natural map and of their derivatives,
Alart–Curnier's function with its derivative, and a projected Gauss–Seidel over the contacts
(docs/theory.md §15).

Vectors are flat, d entries per contact (d = 2 or 3), the normal first: contact c occupies
``[c·d, c·d + d)``. K_μ = {r : ‖r_T‖ ≤ μ r_n} is the Coulomb cone and its projection has a
closed form, the same for the 3-D cone and the planar wedge (d = 2): with t = ‖x_T‖,

- x itself when t ≤ μ x_n,
- 0 when μ t ≤ −x_n (x is in the polar cone),
- otherwise a·(1, μ x_T/t) with a = (x_n + μ t)/(1 + μ²).

A NaN anywhere fails every comparison and falls into the last case, where it propagates.
"""

from __future__ import annotations

import numpy as np

from .friction_blocks import exact_contact, local_steps, nonzero_rows
from .friction_planar import planar_contact
from .friction_rows import contact_rows, off_diagonal, velocity_into
from .jit import inline_kernel, kernel

CHECK_GAP = 8
"""Most sweeps of :func:`nsgs_rows` between two evaluations of ‖F‖."""
RELAX_FROM = 8
"""First sweep after which :func:`nsgs_contacts` may measure the plain sweeps' rate to
over-relax by (the first sweeps' rates are faster than the sweeps' asymptotic one)."""


@inline_kernel
def tangent_norm(x, k, d):
    """‖x_T‖ of the contact starting at index ``k``."""
    t2 = 0.0
    for j in range(1, d):
        t2 += x[k + j] * x[k + j]
    return np.sqrt(t2)


@inline_kernel
def project_contact(x, mu, k, d, out):
    """``out[k:k+d]`` = P_{K_μ}(``x[k:k+d]``) by the closed form of the module's docstring."""
    xn = x[k]
    t = tangent_norm(x, k, d)
    if t <= mu * xn:
        for j in range(d):
            out[k + j] = x[k + j]
    elif mu * t <= -xn:
        for j in range(d):
            out[k + j] = 0.0
    else:
        a = (xn + mu * t) / (1.0 + mu * mu)
        out[k] = a
        for j in range(1, d):
            out[k + j] = mu * a * x[k + j] / t


@kernel(interpretable=True)
def project_cones(x, mu, d):
    """P_{K_μ}(x) contact by contact (μ one coefficient per contact)."""
    out = np.empty_like(x)
    for c in range(mu.size):
        project_contact(x, mu[c], c * d, d, out)
    return out


@inline_kernel
def modified_contact(u, mu, k, d, out):
    """``out[k:k+d]`` = ũ = u + μ‖u_T‖e_n (De Saxcé's modified velocity) of one contact."""
    out[k] = u[k] + mu * tangent_norm(u, k, d)
    for j in range(1, d):
        out[k + j] = u[k + j]


@kernel
def modified_velocity(u, mu, d):
    """ũ = u + μ‖u_T‖e_n contact by contact."""
    ut = np.empty_like(u)
    for c in range(mu.size):
        modified_contact(u, mu[c], c * d, d, ut)
    return ut


def kernel_mu(mu: np.ndarray) -> np.ndarray:
    """A writable copy of a read-only μ, as a time step's kernels pass it: one signature."""
    return np.array(mu, dtype=float)


@kernel(internal=True, refcounted=False)
def natural_map_into(r, u, mu, d, F):
    """``F`` = r − P_{K_μ}(r − ũ) contact by contact, ũ = u + μ‖u_T‖e_n (F neither r nor
    u): the one definition, without an array of its own. Compiled once, not inlined: its
    callers (the sweeps' stopping test, the certificate of a few contacts, :func:`natural_map`)
    would otherwise each compile its inlined helpers again."""
    for c in range(mu.size):
        k = c * d
        modified_contact(u, mu[c], k, d, F)
        for j in range(d):
            F[k + j] = r[k + j] - F[k + j]
        project_contact(F, mu[c], k, d, F)  # in place: each entry is read before written
        for j in range(d):
            F[k + j] = r[k + j] - F[k + j]


@kernel(interpretable=True)
def natural_map(r, u, mu, d):
    """F = r − P_{K_μ}(r − ũ), ũ = u + μ‖u_T‖e_n, by :func:`natural_map_into`."""
    F = np.empty_like(u)
    natural_map_into(r, u, mu, d, F)
    return F


@kernel
def certificate_sums(r, u, mu, d):
    """The sums of the certificate of docs/theory.md §15, in one pass over the contacts:
    (‖F‖², Σ_c |r_c·ũ_c|, Σ_c (−u_n,c)₊², ‖r − P_{K_μ}(r)‖²)."""
    F = natural_map(r, u, mu, d)
    pr = project_cones(r, mu, d)
    ut = modified_velocity(u, mu, d)
    f2 = 0.0
    comp = 0.0
    pen = 0.0
    cone = 0.0
    for c in range(mu.size):
        k = c * d
        dot = 0.0
        for j in range(d):
            dot += r[k + j] * ut[k + j]
        comp += abs(dot)
        neg = -u[k] if u[k] < 0.0 else (u[k] - u[k])  # keeps a NaN
        pen += neg * neg
    for i in range(r.size):
        f2 += F[i] * F[i]
        cone += (r[i] - pr[i]) * (r[i] - pr[i])
    return f2, comp, pen, cone


@kernel
def alart_curnier(r, u, mu, rho, d, jac, A, B):
    """Alart–Curnier's function Φ of docs/theory.md §15 contact by contact, with the scale ρ_c
    of each contact: Φ_n = r_n − (r_n − ρu_n)₊ and Φ_T = r_T − P_D(r_T − ρu_T) on the disc D
    of radius μ(r_n − ρu_n)₊. When ``jac``, an element of its Jacobian is written into A and
    B, one d × d block per contact: dΦ_c = A_c dr_c + B_c du_c (the branch the formula takes
    on a kink). Returns Φ."""
    m = mu.size
    Phi = np.empty_like(r)
    for c in range(m):
        k = c * d
        rh = rho[c]
        if jac:
            for i in range(d):
                for j in range(d):
                    A[c, i, j] = 0.0
                    B[c, i, j] = 0.0
        xn = r[k] - rh * u[k]
        active = xn > 0.0
        pn = xn if active else 0.0
        Phi[k] = r[k] - pn
        if jac:
            if active:
                B[c, 0, 0] = rh
            else:
                A[c, 0, 0] = 1.0
        radius = mu[c] * pn
        t2 = 0.0
        for j in range(1, d):
            xj = r[k + j] - rh * u[k + j]
            t2 += xj * xj
        t = np.sqrt(t2)
        if t <= radius:  # sticking: Φ_T = ρ u_T
            for j in range(1, d):
                Phi[k + j] = rh * u[k + j]
                if jac:
                    B[c, j, j] = rh
            continue
        s = radius / t
        for i in range(1, d):
            wi = (r[k + i] - rh * u[k + i]) / t
            Phi[k + i] = r[k + i] - radius * wi
            if not jac:
                continue
            if active:
                A[c, i, 0] = -mu[c] * wi
                B[c, i, 0] = mu[c] * rh * wi
            for j in range(1, d):
                wj = (r[k + j] - rh * u[k + j]) / t
                proj = (1.0 if i == j else 0.0) - wi * wj
                A[c, i, j] = (1.0 if i == j else 0.0) - s * proj
                B[c, i, j] = s * rh * proj
    return Phi


@inline_kernel
def nsgs(W, q, mu, d, r, tol, max_sweeps, local_iters):
    """:func:`nsgs_rows` on a dense W's nonzero entries
    (:func:`~impactqp.kernels.friction_blocks.nonzero_rows`)."""
    indptr, indices, data = nonzero_rows(W)
    return nsgs_rows(indptr, indices, data, q, mu, d, r, tol, max_sweeps, local_iters)


@inline_kernel
def nsgs_rows(indptr, indices, data, q, mu, d, r, tol, max_sweeps, local_iters):
    """:func:`nsgs_contacts` on W's compressed rows (scipy's CSR arrays), W gathered by
    contacts at each call (:func:`~impactqp.kernels.friction_rows.contact_rows`)."""
    rows = contact_rows(indptr, indices, data, mu.size, d)
    return nsgs_contacts(rows, local_steps(rows.diagonal), q, mu, d, r, tol, max_sweeps,
                         local_iters, 1.0)


@inline_kernel
def relative_error(r, u, q, mu, d, F):
    """‖F‖/‖q‖ (‖F‖ for q = 0) at (r, u), F = r − P_{K_μ}(r − ũ) written into ``F``."""
    natural_map_into(r, u, mu, d, F)
    qn = np.sqrt(np.sum(q * q))
    return np.sqrt(np.sum(F * F)) / (qn if qn > 0.0 else 1.0)


@inline_kernel
def next_check(done, err, tol, last_err, last_at):
    """The sweep after which the sweeps evaluate ‖F‖ next, at ``err`` after ``done`` and at
    ``last_err`` after ``last_at``: as many sweeps on as the decrease since then predicts
    are left to reach tol, at most :data:`CHECK_GAP`, and one while it does not decrease."""
    gap = 1
    if tol > 0.0 and err < last_err < np.inf:  # the sweeps left at the rate since then
        left = np.log(tol / err) / np.log(err / last_err) * (done - last_at)
        gap = int(min(max(left, 1.0), CHECK_GAP))
    return done + gap


@inline_kernel
def relax_contact(r, k, d, mu, omega, o0, o1, o2):
    """Over-relaxation of one contact's sweep: ``r[k:k+d]`` ← P_{K_μ}((1 − ω)·r_old + ω·r_new),
    r_old = (o0, o1, o2) the contact's reaction before the sweep solved its local problem
    (o2 unused for d = 2), r_new what it wrote (docs/theory.md §15)."""
    r[k] = (1.0 - omega) * o0 + omega * r[k]
    r[k + 1] = (1.0 - omega) * o1 + omega * r[k + 1]
    if d == 3:
        r[k + 2] = (1.0 - omega) * o2 + omega * r[k + 2]
    project_contact(r, mu, k, d, r)  # in place: each entry is read before written


@inline_kernel
def relaxation(rate, relax):
    """The over-relaxation factor of the sweeps at the measured rate of plain sweeps (‖F‖
    divided by ``rate`` < 1 a sweep): 2/(1 + √(1 − rate)), the best factor of successive
    over-relaxation of a linear system whose Gauss–Seidel contracts at that rate (Young's
    formula, docs/theory.md §15), at most ``relax``."""
    return min(2.0 / (1.0 + np.sqrt(1.0 - rate)), relax)


@kernel
def nsgs_contacts(rows, rhos, q, mu, d, r, tol, max_sweeps, local_iters, relax):
    """Projected Gauss–Seidel over the contacts (docs/theory.md §15), updating ``r`` in place,
    on W by contacts ``rows`` (:class:`~impactqp.kernels.friction_rows.ContactRows`, so that
    a sweep costs W's blocks) with the steps ``rhos`` of the contacts' fixed points
    (:func:`~impactqp.kernels.friction_blocks.local_steps`). Each contact's local problem
    (the others held) is solved as in :func:`~impactqp.kernels.friction_sweep.sweep_once`
    without ``slip``; the sweeps stop when ‖F‖ ≤ tol·‖q‖. ‖F‖ (a product by W, as dear as
    a sweep) is evaluated after the first sweep, then after the sweeps :func:`next_check`
    says, and after the last.

    With ``relax`` > 1 the sweeps over-relax (:func:`relax_contact`) once the plain sweeps'
    rate is measured between two evaluations from sweep :data:`RELAX_FROM` on, by the factor
    :func:`relaxation` gives at that rate (at most ``relax``); they sweep plainly again for
    good as soon as ‖F‖ falls no faster than it did by plain sweeps. Returns (sweeps done,
    ‖F‖/‖q‖ at the end)."""
    start, other, block, Wcc = rows
    u, F, work = np.empty(r.size), np.empty(r.size), np.empty(3 * d)
    err, last_err, last_at, check_at = np.inf, np.inf, 0, 1
    omega, plain = 1.0, 1.0
    o0, o1, o2 = 0.0, 0.0, 0.0
    for sweep in range(max_sweeps):
        for c in range(mu.size):  # as sweep_once, b_c by blocks
            k = c * d
            if omega != 1.0:
                o0, o1 = r[k], r[k + 1]
                o2 = r[k + 2] if d == 3 else 0.0
            b0, b1, b2 = off_diagonal(start, other, block, q, r, c, d)
            solved = False
            if d == 2:
                exact, rn, rt = planar_contact(Wcc[c, 0, 0], Wcc[c, 0, 1], Wcc[c, 1, 0],
                                               Wcc[c, 1, 1], b0, b1, mu[c])
                if exact:
                    r[k], r[k + 1] = rn, rt
                    solved = True
            elif b0 >= 0.0:  # apart
                r[k], r[k + 1], r[k + 2] = 0.0, 0.0, 0.0
                solved = True
            if not solved:
                work[2 * d], work[2 * d + 1] = b0, b1
                if d == 3:
                    work[8] = b2
                contact_steps(Wcc, rhos, mu, c, d, r, local_iters, work)
            if omega != 1.0:
                relax_contact(r, k, d, mu[c], omega, o0, o1, o2)
        done = sweep + 1
        if done < check_at and done < max_sweeps:
            continue
        velocity_into(rows, q, r, d, u)
        err = relative_error(r, u, q, mu, d, F)
        if err <= tol:
            return done, err
        if relax > 1.0 and err < last_err:
            rate = (err / last_err) ** (1.0 / (done - last_at))
            if omega != 1.0 and not rate < plain:  # over-relaxing does not pay here
                omega, relax = 1.0, 1.0
            elif omega == 1.0 and done >= RELAX_FROM:
                omega, plain = relaxation(rate, relax), rate
        elif omega != 1.0:  # ‖F‖ rose
            omega, relax = 1.0, 1.0
        last_err, last_at, check_at = err, done, next_check(done, err, tol, last_err, last_at)
    return max_sweeps, err


@kernel(internal=True, refcounted=False)
def contact_steps(Wcc, rhos, mu, c, d, r, local_iters, work):
    """Contact c's local problem u_c = W_cc r_c + b_c (b_c in ``work[2·d:3·d]``) into
    ``r[c·d:c·d + d]``, where the sweeps' scalar cases have not solved it: sticking
    (:func:`~impactqp.kernels.friction_blocks.exact_contact`), else at most ``local_iters``
    steps of the fixed point r_c ← P_{K_μ}(r_c − ρ_c ũ_c), fewer once one moves r_c by less
    than 10⁻⁶‖r_c‖ (r_c in ``work[0:d]``, ũ_c and the step in place in ``work[d:2·d]``)."""
    k = c * d
    for i in range(d):
        work[i] = r[k + i]
    exact = d == 3 and exact_contact(Wcc[c], work[2 * d:], mu[c], d, work)
    for _ in range(0 if exact else local_iters):
        for i in range(d):
            v = work[2 * d + i]
            for j in range(d):
                v += Wcc[c, i, j] * work[j]
            work[d + i] = v
        modified_contact(work, mu[c], d, d, work)  # in place: ũ_c
        for i in range(d):
            work[d + i] = work[i] - rhos[c] * work[d + i]
        project_contact(work, mu[c], d, d, work)  # in place
        change = 0.0
        size = 0.0
        for i in range(d):
            change += (work[d + i] - work[i]) ** 2
            size += work[d + i] * work[d + i]
            work[i] = work[d + i]
        if change <= 1e-12 * (size + 1e-300):  # squares: 10⁻⁶ in norm
            break
    for i in range(d):
        r[k + i] = work[i]
