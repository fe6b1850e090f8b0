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

from .friction_blocks import diagonal_blocks, exact_contact, local_steps, nonzero_rows
from .jit import inline_kernel, kernel

CHECK_GAP = 8
"""Most sweeps of :func:`nsgs_rows` between two evaluations of ‖F‖."""


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
    """A writable copy of the (read-only) μ of a problem or law, for the kernels: they take μ
    as the kernels of a time step index it (``friction.mu[cons]``, a writable array), so one
    compiled version of each serves both (a read-only array is another argument type to
    numba, which would compile every kernel on μ twice). Taken once per solve."""
    return np.array(mu, dtype=float)


@inline_kernel
def natural_map_into(r, u, mu, d, F):
    """``F`` = r − P_{K_μ}(r − ũ) contact by contact, ũ = u + μ‖u_T‖e_n (F neither r nor
    u): the one definition, without an array of its own."""
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
    """F = r − P_{K_μ}(r − ũ) contact by contact, ũ = u + μ‖u_T‖e_n
    (:func:`natural_map_into`)."""
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
def projection_jacobian(x, mu, d):
    """An element of the (Clarke) Jacobian of P_{K_μ} at x, one d × d block per contact
    (the derivative of the closed form; on a kink, the branch the closed form takes)."""
    m = mu.size
    J = np.zeros((m, d, d))
    for c in range(m):
        k = c * d
        m_ = mu[c]
        xn = x[k]
        t = tangent_norm(x, k, d)
        if t <= m_ * xn:
            for j in range(d):
                J[c, j, j] = 1.0
        elif m_ * t <= -xn:
            continue
        else:
            s = 1.0 / (1.0 + m_ * m_)
            a = (xn + m_ * t) * s
            J[c, 0, 0] = s
            for j in range(1, d):
                w = x[k + j] / t
                J[c, 0, j] = s * m_ * w
                J[c, j, 0] = s * m_ * w
                for i in range(1, d):
                    wi = x[k + i] / t
                    J[c, j, i] = m_ * m_ * s * w * wi - m_ * a / t * w * wi
                J[c, j, j] += m_ * a / t
    return J


@kernel
def modified_velocity_jacobian(u, mu, d):
    """The derivative of u ↦ ũ = u + μ‖u_T‖e_n, one d × d block per contact (the row of
    e_n gains μ u_Tᵀ/‖u_T‖; nothing where u_T = 0)."""
    m = mu.size
    J = np.zeros((m, d, d))
    for c in range(m):
        k = c * d
        for j in range(d):
            J[c, j, j] = 1.0
        t = tangent_norm(u, k, d)
        if t > 0.0:
            for j in range(1, d):
                J[c, 0, j] = mu[c] * u[k + j] / t
    return J


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


@kernel
def nsgs(W, q, mu, d, r, tol, max_sweeps, local_iters):
    """:func:`nsgs_rows` for a dense W, on its nonzero entries
    (:func:`~impactqp.kernels.friction_blocks.nonzero_rows`)."""
    indptr, indices, data = nonzero_rows(W)
    return nsgs_rows(indptr, indices, data, q, mu, d, r, tol, max_sweeps, local_iters)


@kernel
def nsgs_rows(indptr, indices, data, q, mu, d, r, tol, max_sweeps, local_iters):
    """:func:`nsgs_blocks` on W's compressed rows (scipy's CSR ``indptr``, ``indices``,
    ``data``), its diagonal blocks and their steps gathered at each call
    (:func:`~impactqp.kernels.friction_blocks.diagonal_blocks`). Returns (sweeps, ‖F‖/‖q‖)."""
    Wcc = diagonal_blocks(indptr, indices, data, mu.size, d)
    return nsgs_blocks((indptr, indices, data), (Wcc, local_steps(Wcc)), q, mu, d, r, tol,
                       max_sweeps, local_iters)


@kernel
def nsgs_blocks(rows, blocks, q, mu, d, r, tol, max_sweeps, local_iters):
    """Projected Gauss–Seidel over the contacts (docs/theory.md §15), updating ``r`` in place;
    W given by its compressed ``rows`` (indptr, indices, data: scipy's CSR arrays), so that a
    sweep costs the entries of W, and ``blocks`` = (W_cc, ρ_c): its diagonal blocks
    (:func:`~impactqp.kernels.friction_blocks.diagonal_blocks`) and their steps
    (:func:`~impactqp.kernels.friction_blocks.local_steps`), which a caller solving the same
    W again keeps.

    Each contact's local problem (the others held) is solved exactly where a closed form
    holds (:func:`~impactqp.kernels.friction_blocks.exact_contact`: apart, sticking, a planar
    contact sliding), else by at most
    ``local_iters`` steps of the projected fixed point r_c ← P_{K_μ}(r_c − ρ_c ũ_c), fewer
    once a step moves r_c by less than 10⁻⁶‖r_c‖; the sweeps stop when ‖F‖ ≤ tol·‖q‖.
    ‖F‖ (a product by W, as dear as a sweep) is evaluated after the first sweep, then after
    as many sweeps as its decrease since the last evaluation predicts are left to reach tol
    (at most :data:`CHECK_GAP`, and one while it does not decrease) and after the last.
    Returns (sweeps done, ‖F‖/‖q‖ at the end).
    """
    indptr, indices, data = rows
    n = r.size
    qn = np.sqrt(np.sum(q * q))
    if qn == 0.0:
        qn = 1.0
    u = np.empty(n)
    F = np.empty(n)
    scratch = np.empty(5 * d)
    err = np.inf
    last_err, last_at, check_at = np.inf, 0, 1
    for sweep in range(max_sweeps):
        sweep_once(rows, blocks, q, mu, d, r, local_iters, scratch)
        done = sweep + 1
        if done < check_at and done < max_sweeps:
            continue
        for i in range(n):
            v = q[i]
            for p in range(indptr[i], indptr[i + 1]):
                v += data[p] * r[indices[p]]
            u[i] = v
        natural_map_into(r, u, mu, d, F)
        err = np.sqrt(np.sum(F * F)) / qn
        if err <= tol:
            return done, err
        gap = 1
        if tol > 0.0 and err < last_err < np.inf:  # the sweeps left at the rate since then
            left = np.log(tol / err) / np.log(err / last_err) * (done - last_at)
            gap = int(min(max(left, 1.0), CHECK_GAP))
        last_err, last_at, check_at = err, done, done + gap
    return max_sweeps, err


@inline_kernel
def sweep_once(rows, blocks, q, mu, d, r, local_iters, scratch):
    """One sweep of :func:`nsgs_blocks` over the contacts, updating ``r`` in place, with
    ``scratch`` of 5·d floats: each contact's local problem solved exactly where a closed
    form holds, else by at most ``local_iters`` projected fixed-point steps. A contact whose
    normal row b_n is ≥ 0 is apart (r_c = 0) before its tangential rows are summed: most
    contacts of a pile of spheres are (41 of NESpheres-30's 44 in its one sweep)."""
    indptr, indices, data = rows
    Wcc, rhos = blocks
    x = scratch[:d]
    rc = scratch[d:2 * d]
    uc = scratch[2 * d:3 * d]
    mc = scratch[3 * d:4 * d]
    base = scratch[4 * d:5 * d]  # q_c + Σ_{j≠c} W_cj r_j
    for c in range(mu.size):
        k = c * d
        rho = rhos[c]
        for i in range(d):
            v = q[k + i]
            for p in range(indptr[k + i], indptr[k + i + 1]):
                v += data[p] * r[indices[p]]
            for j in range(d):
                v -= Wcc[c, i, j] * r[k + j]
            base[i] = v
            rc[i] = r[k + i]
            if i == 0 and v >= 0.0:  # apart (the first case of exact_contact): r_c = 0
                break
        if base[0] >= 0.0:
            for i in range(d):
                r[k + i] = 0.0
            continue
        exact = exact_contact(Wcc[c], base, mu[c], d, rc)
        for _ in range(0 if exact else local_iters):
            for i in range(d):
                v = base[i]
                for j in range(d):
                    v += Wcc[c, i, j] * rc[j]
                uc[i] = v
            modified_contact(uc, mu[c], 0, d, mc)
            for i in range(d):
                x[i] = rc[i] - rho * mc[i]
            change = 0.0
            size = 0.0
            project_contact(x, mu[c], 0, d, mc)
            for i in range(d):
                change += (mc[i] - rc[i]) ** 2
                size += mc[i] * mc[i]
                rc[i] = mc[i]
            if change <= 1e-12 * (size + 1e-300):  # squares: 10⁻⁶ in norm
                break
        for i in range(d):
            r[k + i] = rc[i]
