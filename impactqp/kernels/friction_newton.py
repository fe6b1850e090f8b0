"""Newton's method on Alart–Curnier's function for a dense W, and the compiled call that
solves a local frictional problem of a few contacts whole (docs/theory.md §15).

:func:`solve_small` is to frictional contacts what :mod:`impactqp.kernels.impact` is to
frictionless impacts: one call, no Python object per step, microseconds for one to four
contacts. It returns whether its answer is within half the tolerance of the certificate's
figure; the caller certifies it (:func:`impactqp.model.friction.certify_friction`).
"""

from __future__ import annotations

import numpy as np

from .friction import alart_curnier, natural_map, nsgs_rows, project_cones
from .friction_blocks import densified, nonzero_rows
from .friction_sweep import nsgs_blocks
from .jit import inline_kernel, kernel


@kernel(interpretable=True)
def scales(diagonal, d):
    """ρ_c of each contact's Alart–Curnier function (docs/theory.md §15): 1 over the mean of
    W_cc's diagonal (1 where that mean is not positive), from W's ``diagonal``."""
    m = diagonal.size // d
    rho = np.ones(m)
    for c in range(m):
        mean = 0.0
        for j in range(d):
            mean += diagonal[c * d + j]
        mean /= d
        if mean > 0.0:
            rho[c] = 1.0 / mean
    return rho


@kernel
def lu_solve(J, b):
    """Solve J x = b in place by Gaussian elimination with partial pivoting (J is overwritten,
    b receives x); False when a pivot is zero or not finite."""
    n = b.size
    for k in range(n):
        p = k
        big = abs(J[k, k])
        for i in range(k + 1, n):
            if abs(J[i, k]) > big:
                p, big = i, abs(J[i, k])
        if not big > 0.0 or not np.isfinite(big):
            return False
        if p != k:
            for j in range(n):
                J[k, j], J[p, j] = J[p, j], J[k, j]
            b[k], b[p] = b[p], b[k]
        for i in range(k + 1, n):
            f = J[i, k] / J[k, k]
            if f != 0.0:
                for j in range(k + 1, n):
                    J[i, j] -= f * J[k, j]
                b[i] -= f * b[k]
    for i in range(n - 1, -1, -1):
        v = b[i]
        for j in range(i + 1, n):
            v -= J[i, j] * b[j]
        b[i] = v / J[i, i]
    return True


@inline_kernel
def affine(W, r, q, out):
    """out = W r + q by plain loops (for the few unknowns here, cheaper than a BLAS call)."""
    for i in range(q.size):
        v = q[i]
        for j in range(r.size):
            v += W[i, j] * r[j]
        out[i] = v
    return out


@kernel
def abh_error(W, q, mu, d, r, qn):
    """‖F(r)‖/qn with u = W r + q (W dense)."""
    F = natural_map(r, affine(W, r, q, np.empty_like(q)), mu, d)
    return np.sqrt(np.sum(F * F)) / qn


@kernel
def newton_dense(W, q, mu, rho, d, r, tol, kappa, max_steps):
    """Semismooth Newton on Alart–Curnier's function for a dense W, updating ``r`` in place:
    the iteration of ``impactqp.qp.friction.newton.newton`` (docs/theory.md §15), its steps
    (J + λI)Δ = −Φ solved by :func:`lu_solve`. Once within tolerance it takes one step more
    and keeps it if it is better (near a solution a step gains digits quadratically: the few
    contacts of a time step are answered to round-off, not just to the tolerance). Returns
    (steps done, whether the projected r, left in ``r``, is within tol/2 in ‖F‖/‖q‖)."""
    n = r.size
    m = mu.size
    qn = np.sqrt(np.sum(q * q))
    # run-time flags (np.bool_): one compiled alart_curnier serves these calls and Python's,
    # where literal True/False would compile one specialization each
    jac, value = np.bool_(True), np.bool_(False)
    if qn == 0.0:
        qn = 1.0
    A = np.empty((m, d, d))
    B = np.empty((m, d, d))
    J = np.empty((n, n))
    scale = np.sqrt(np.sum(alart_curnier(np.zeros(n), q, mu, rho, d, value, A, B) ** 2))
    if scale == 0.0:
        scale = 1.0
    u = affine(W, r, q, np.empty(n))
    u_try = np.empty(n)
    r_try = np.empty(n)
    phi = alart_curnier(r, u, mu, rho, d, jac, A, B)
    f = np.sqrt(np.sum(phi * phi))
    steps = 0
    kept = np.empty(n)  # the first projected r within tolerance
    kept_error = np.inf
    kept_at = max_steps
    while True:
        F = natural_map(r, u, mu, d)
        if np.sqrt(np.sum(F * F)) <= 0.5 * tol * qn:
            rp = project_cones(r, mu, d)
            error = abh_error(W, q, mu, d, rp, qn)
            if error <= 0.5 * tol:
                if kept_error <= 0.5 * tol or error == 0.0:  # the step more is taken
                    best = rp if error < kept_error else kept
                    for i in range(r.size):  # loops: a slice copy compiles numba's shape errors
                        r[i] = best[i]
                    return steps, True
                for i in range(r.size):
                    kept[i] = rp[i]
                kept_error = error
                kept_at = steps
        if steps == max_steps or steps > kept_at:  # the step more did not do better
            break
        steps += 1
        shift = kappa * min(f / scale, 1e-2)
        for c in range(m):
            k = c * d
            for i in range(d):
                for col in range(n):
                    v = 0.0
                    for j in range(d):
                        v += B[c, i, j] * W[k + j, col]
                    J[k + i, col] = v
                for j in range(d):
                    J[k + i, k + j] += A[c, i, j]
                J[k + i, k + i] += shift
        step = -phi
        if not lu_solve(J, step):
            break
        t = 1.0
        while t > 1e-8:
            for i in range(n):
                r_try[i] = r[i] + t * step[i]
            affine(W, r_try, q, u_try)
            phi_try = alart_curnier(r_try, u_try, mu, rho, d, value, A, B)
            f_try = np.sqrt(np.sum(phi_try * phi_try))
            if f_try <= (1.0 - 1e-4 * t) * f:
                break
            t *= 0.5
        if not t > 1e-8:
            break  # no descent: stalled
        for i in range(r.size):
            r[i] = r_try[i]
            u[i] = u_try[i]
        phi = alart_curnier(r, u, mu, rho, d, jac, A, B)
        f = f_try
    if kept_error <= 0.5 * tol:  # the step more failed: the r within tolerance
        for i in range(r.size):
            r[i] = kept[i]
        return steps, True
    return steps, False


@inline_kernel
def _accept(W, q, mu, d, r, tol):
    """Whether P_K(r) is within tol/2 in ‖F‖/‖q‖; r is replaced by P_K(r) when it is."""
    qn = np.sqrt(np.sum(q * q))
    rp = project_cones(r, mu, d)
    if abh_error(W, q, mu, d, rp, qn if qn > 0.0 else 1.0) <= 0.5 * tol:
        for i in range(r.size):
            r[i] = rp[i]
        return True
    return False


ROUND_OFF = 1e-14
"""‖F‖/‖q‖ below which the sweeps' answer is kept as it is; above it, Newton takes one step
from it and keeps it when better (:func:`to_round_off`)."""


@inline_kernel
def to_round_off(W, q, mu, rho, d, r, tol):
    """One Newton step from the sweeps' r (within tol/2), kept when it is better, unless r is
    within :data:`ROUND_OFF` already: as :func:`newton_dense` answers, the few contacts of a
    time step are answered to round-off, not just to the tolerance. Returns the steps."""
    qn = np.sqrt(np.sum(q * q))
    if abh_error(W, q, mu, d, r, qn if qn > 0.0 else 1.0) <= ROUND_OFF:
        return 0
    steps, _ = newton_dense(W, q, mu, rho, d, r, tol, 1.0, np.int64(1))  # not a literal
    return steps


NEWTON_EXPECTED = 8
"""Newton steps :func:`sweeps_first` weighs its sweeps against (the dense Newton of a few
contacts takes 4 to 8 where it converges)."""
LOCAL_WORK = 40
"""Operations one projected fixed-point step on one contact costs, in units of a product by
one entry of W (measured: a local step ≈ 40 ns, a sweep over 9 contacts of 121 entries with
10 local steps each ≈ 3.4 µs, a dense Newton step on 27 unknowns ≈ 6 µs)."""


@inline_kernel
def sweep_budget(n, m, entries, sweeps, local_iters):
    """Most sweeps worth trying before Newton: as many as cost the work of
    :data:`NEWTON_EXPECTED` dense Newton steps on n unknowns (an LU, n³/3, and J and the line
    search, 4n²), a sweep costing its ``entries`` and m contacts' ``local_iters`` local steps
    (planar contacts are solved exactly, in about one); at most ``sweeps``."""
    local = 1 if m > 0 and n == 2 * m else local_iters
    newton = NEWTON_EXPECTED * (n * n * n / 3.0 + 4.0 * n * n)
    return min(float(sweeps), newton / (entries + LOCAL_WORK * local * m))


@inline_kernel
def sweeps_first(rows, q, mu, d, r, tol, sweeps, local_iters):
    """The projected Gauss–Seidel from r = 0 on W's nonzero ``rows`` (indptr, indices,
    data), into ``r``, while it costs less than Newton would (:func:`sweep_budget`; none
    where the budget is below one sweep): one sweep, then twice the number its rate predicts
    are left to tol/2 (‖F‖ falling linearly in log scale, from r = 0 or the last check),
    each time only while that prediction lies within the budget (docs/theory.md §15).
    Returns the sweeps done (the caller checks ‖F‖)."""
    indptr, indices, data = rows
    budget = sweep_budget(q.size, mu.size, indices.size, sweeps, local_iters)
    r[:] = 0.0
    if budget < 1.0:  # one sweep costs more than Newton
        return 0
    qn = np.sqrt(np.sum(q * q))
    F = natural_map(r, q, mu, d)  # at r = 0, u = q
    last = np.sqrt(np.sum(F * F)) / (qn if qn > 0.0 else 1.0)
    done, err = nsgs_rows(indptr, indices, data, q, mu, d, r, 0.5 * tol, np.int64(1),
                          local_iters)  # an int64, not a literal 1: one compiled sweep
    last_at = 0
    for _ in range(2):
        if err <= 0.5 * tol or not 0.0 < err < last:
            return done
        left = (done - last_at) * np.log(0.5 * tol / err) / np.log(err / last)
        if done + left > budget:
            return done
        more, new = nsgs_rows(indptr, indices, data, q, mu, d, r, 0.5 * tol,
                              min(int(left) + 1, sweeps - done), local_iters)
        last, last_at, err = err, done, new
        done += more
    return done


@kernel(interpretable=True)
def solve_small(W, q, mu, rho, d, tol, r, newton_steps, sweeps, local_iters):
    """A local problem of a few contacts (dense W) in one compiled call, into ``r``: the
    projected Gauss–Seidel on W's nonzero entries while its rate says it finishes within
    ``sweeps`` (:func:`sweeps_first`; its answer taken to round-off by
    :func:`to_round_off`), else Newton from r = 0, then the sweeps on from where
    they stopped (``sweeps`` in all) followed by Newton, then the damped Newton (shift factor
    10) from r = 0 — the order of ``auto`` without the cone programs (docs/theory.md §15).
    Returns (iterations, whether the projected r left in ``r`` is within tol/2 in ‖F‖/‖q‖);
    the caller certifies it."""
    rows = nonzero_rows(W)
    swept_its = sweeps_first(rows, q, mu, d, r, tol, sweeps, local_iters)
    if _accept(W, q, mu, d, r, tol):
        return swept_its + to_round_off(W, q, mu, rho, d, r, tol), True
    swept = r.copy()
    r[:] = 0.0
    steps, ok = newton_dense(W, q, mu, rho, d, r, tol, 1.0, newton_steps)
    its = swept_its + steps
    if ok:
        return its, True
    for i in range(r.size):
        r[i] = swept[i]
    if swept_its < sweeps:
        done, _ = nsgs_rows(rows[0], rows[1], rows[2], q, mu, d, r, 0.5 * tol,
                            sweeps - swept_its, local_iters)
        its += done
        if _accept(W, q, mu, d, r, tol):
            return its + to_round_off(W, q, mu, rho, d, r, tol), True
    more, ok = newton_dense(W, q, mu, rho, d, r, tol, 1.0, newton_steps)
    its += more
    if ok:
        return its, True
    r[:] = 0.0
    more, ok = newton_dense(W, q, mu, rho, d, r, tol, 10.0, newton_steps)
    return its + more, ok


FIRST_SWEEPS = 12
"""Most sweeps :func:`sweeps_on` tries before the ``"kernel"`` method whole: while their
rate says they reach :data:`ROUND_OFF` within this many
(a sweep of a few contacts costs less than a microsecond, the dense Newton steps the method
takes a few microseconds: Rover4396, two contacts sliding, reaches round-off in six sweeps,
about 2.5e-3 of ‖F‖ kept a sweep)."""
FAST_RATE = 0.1
"""Most ‖F‖ a sweep may keep of the last one's for :func:`sweeps_on` to sweep on, one sweep
at a time, where the rate of the last ones does not promise round-off within
:data:`FIRST_SWEEPS`: the sweeps of LMGC-00046 (9 contacts) speed up, 2e-1, 1.6e-2, 9e-5,
2e-12, 7e-15 (a rate of 0.08, then 0.006), those of the problems Newton solves sooner keep
0.3 to 0.95 of ‖F‖ from the second sweep on (Rover1039 to Rover9770, NESpheres-10, the
slider-crank)."""
POLISH_SWEEPS = 2
"""Most sweeps :func:`sweeps_on` predicts to round-off that it takes once within tol/2;
beyond them it takes one Newton step on the dense W̃ (with the local problems solved by the
fixed point, TwoRods1-condensed was within tol/2 after 2 sweeps, 5e-12 after 4, then kept
0.65 of ‖F‖ a sweep)."""


@inline_kernel(interpretable=True)
def sweeps_on(rows, blocks, q, mu, d, r, tol, local_iters, done, err):
    """The projected Gauss–Seidel on W's nonzero ``rows`` (indptr, indices, data) and its
    diagonal ``blocks`` with their steps (:func:`~impactqp.kernels.friction_sweep.nsgs_blocks`,
    every local problem with a closed form or a slip angle solved exactly) from the answer
    in ``r`` of ``done`` sweeps, at ‖F‖/‖q‖ = ``err`` (docs/theory.md §15): one more, then
    more while their rate says they reach :data:`ROUND_OFF` within :data:`FIRST_SWEEPS`,
    or, one at a time, while each keeps at most :data:`FAST_RATE` of the last one's ‖F‖;
    once within tol/2, only while at most :data:`POLISH_SWEEPS` are left, and then one
    Newton step on the dense W (:func:`to_round_off`). Returns (sweeps and steps done,
    ‖F‖/‖q‖ of the sweeps, at most tol/2 where ``r`` is within it)."""
    ask = np.int64(1)  # an int64, not a literal 1: one compiled sweep
    last, last_done = np.inf, 0
    while ROUND_OFF < err < last and done < FIRST_SWEEPS:
        if last < np.inf:  # the sweeps left to round-off at the rate of the last ones
            rate = (err / last) ** (1.0 / (done - last_done))  # per sweep
            left = np.log(ROUND_OFF / err) / np.log(rate)
            if err <= 0.5 * tol and left > POLISH_SWEEPS:
                break  # within tol: one Newton step costs less
            if done + left <= FIRST_SWEEPS:
                ask = min(int(left) + 1, FIRST_SWEEPS - done)
            elif rate <= FAST_RATE:
                ask = 1
            else:
                break
        more, new = nsgs_blocks(rows, blocks, q, mu, d, r, ROUND_OFF, ask, local_iters)
        last, last_done, err = err, done, new
        done += more
    if ROUND_OFF < err <= 0.5 * tol:  # within tol: one Newton step to round-off
        dense, diagonal = densified(rows, q.size)
        done += to_round_off(dense, q, mu, scales(diagonal, d), d, r, tol)
    return done, err
