"""A whole Moreau–Jean run in compiled code (docs/theory.md §14, "The compiled loop").

:func:`run` integrates a dense linear system with a constant or linear force and a
complementarity law in its step form ``0 ≤ Λ ⟂ γ_{k+1} + Eγ_k ≥ 0``, step after step:

1. closed contacts: gᵢ(q_k) + ½h γᵢ(v_k) ≤ 0;
2. free velocity v_free = v_k − Ŵ⁻¹r_k (r_k of the force, Ŵ = M + h²θ²K factorized once);
3. the closed contacts grouped into clusters by :func:`impactqp.kernels.clusters.group`
   (as :class:`impactqp.simulation.clusters.ClusterCache` groups them);
   a cluster with q = γ(v_free) + Eγ(v_k) ≥ 0 needs no impulse; the others solve the LCP
   ``0 ≤ Λ ⟂ G_cΛ + q ≥ 0`` by the active-set search
   (:func:`impactqp.kernels.active_set.lcp_psd_work`, warm-started by the contacts' last
   support), with G_c = H_cᵀŴ⁻¹H_c and Ŵ⁻¹H_c taken from the products of all contacts
   formed once, and their certificate is recomputed by
   :func:`impactqp.kernels.residuals.dense_step_residuals`; on a chain of balls with one
   restitution e (what the isotonic path of the Python loop takes) a run is instead
   z = prox_{T_C}(v_free + e v_k) by :func:`impactqp.kernels.chain.project`,
   v_{k+1} = z − e v_k, certified by :func:`impactqp.kernels.residuals.chain_step_residuals`
   in O(N);
4. q_{k+1} = q_k + h((1 − θ)v_k + θv_{k+1}), and the kept rows are recorded.

The kernel stops early, with the state of the last completed step, when a certificate fails
(:data:`FAILED`: the caller solves that step on the general path and resumes) or when the
event buffers are full (:data:`FULL`: the caller enlarges them and resumes).
"""

from __future__ import annotations

import numpy as np

from .active_set import SOLVED, cholesky_solve, lcp_psd_work
from .chain import project
from .clusters import group, group_work
from .jit import inline_kernel, kernel
from .residuals import chain_step_residuals, dense_step_residuals

DONE, FAILED, FULL = 0, 1, 2
"""Status codes of :func:`run`."""

CHECKED = 4
"""Residuals of the step law's certificate: momentum, impulse sign, law feasibility and
complementarity (the first four of :data:`impactqp.kernels.residuals.RESIDUALS`)."""


@kernel
def _free_velocity(v, q, chol, K, c, shift, h, theta, linear, out, y):
    """v_free = v − shift (constant force: shift = Ŵ⁻¹r formed once) or, for the force
    c − Kq, v − Ŵ⁻¹(hKq + h²θKv − hc) with Ŵ = LLᵀ (``chol`` = L), solved as LAPACK's
    potrs does (forward, then backward substitution; ``y`` is scratch of n floats)."""
    n = v.size
    if not linear:
        for i in range(n):
            out[i] = v[i] - shift[i]
        return
    for i in range(n):
        kq = 0.0
        kv = 0.0
        for j in range(n):
            kq += K[i, j] * q[j]
            kv += K[i, j] * v[j]
        y[i] = h * kq + (h * h * theta) * kv - h * c[i]
    cholesky_solve(chol, n, y)
    for i in range(n):
        out[i] = v[i] - y[i]


@kernel
def _dense_work(n, m):
    """Scratch of :func:`_solve_dense` for clusters of up to n dofs and m contacts."""
    return (np.empty(n * n), np.empty(m * n), np.empty(n * m), np.empty(m * m),
            np.empty(m * m), np.empty(m), np.empty(m), np.empty(m, dtype=np.bool_),
            np.empty((m, m)), np.empty(m, dtype=np.int64), np.empty(m),
            np.empty(m, dtype=np.bool_))


@kernel
def _chain_work(n):
    """Scratch of :func:`_solve_chain` for runs of up to n balls."""
    return np.empty(n + 1), np.empty(n), np.empty(n + 1), np.empty(n + 1, dtype=np.int64)


@kernel
def _solve_dense(D, C, um, vp, up, lam, qc, Wh, MinvH, G, s, E, Ht_ptr, Ht_idx, Ht_val,
                 passive, tol, dense_work, res, work):
    """One cluster (dofs D, contacts C, u⁻ = um, v_k = vp on D, q = qc) by the active-set
    search on G_CC, u⁺ = u⁻ + (Ŵ⁻¹H)_DC Λ and the dense certificate; True when certified
    (then ``passive`` keeps the support)."""
    nc, mc = D.size, C.size
    Mc, Wt, MW, Gc, Ec, sc, w, pas, Lf, idx, sv, blocked = dense_work
    Mv = Mc[:nc * nc].reshape((nc, nc))
    Wv = Wt[:mc * nc].reshape((mc, nc))
    Xv = MW[:nc * mc].reshape((nc, mc))
    Gv = Gc[:mc * mc].reshape((mc, mc))
    Ev = Ec[:mc * mc].reshape((mc, mc))
    for x in range(nc):
        for y in range(nc):
            Mv[x, y] = Wh[D[x], D[y]]
        for y in range(mc):
            Xv[x, y] = MinvH[D[x], C[y]]
    for x in range(mc):
        for y in range(nc):
            Wv[x, y] = 0.0
        sc[x] = s[C[x]]
        pas[x] = passive[C[x]]
        for y in range(mc):
            Gv[x, y] = G[C[x], C[y]]
            Ev[x, y] = E[C[x], C[y]]
    for x in range(mc):
        i = C[x]
        for p in range(Ht_ptr[i], Ht_ptr[i + 1]):
            for y in range(nc):
                if D[y] == Ht_idx[p]:
                    Wv[x, y] = Ht_val[p]
    if lcp_psd_work(Gv, qc[:mc], pas[:mc], lam[:mc], w[:mc], 20 * mc + 50, Lf, idx, sv,
                    blocked) != SOLVED:
        return False
    for x in range(nc):
        total = um[x]
        for y in range(mc):
            total += Xv[x, y] * lam[y]
        up[x] = total
    dense_step_residuals(Mv, Wv, Xv, sc[:mc], um[:nc], up[:nc], lam[:mc], vp[:nc], Ev, 0.0,
                         False, res, work)
    for x in range(CHECKED):
        if not res[x] <= tol:  # NaN fails
            return False
    for x in range(mc):
        passive[C[x]] = pas[x]
    return True


@kernel
def _solve_chain(D, C, um, vp, up, lam, s, masses, inverse, left, right, e, tol, chain_work,
                 res):
    """One run of a chain (balls D, contacts C) with one restitution e, as the isotonic path
    solves it (docs/theory.md §14): z = prox_{T_C}(u⁻ + e v_k) by
    :func:`impactqp.kernels.chain.project`, u⁺ = z − e v_k, and the chain certificate;
    True when certified."""
    nc, mc = D.size, C.size
    shifted, z, L, starts = chain_work
    first = D[0]
    for x in range(nc):
        shifted[x] = um[x] + e * vp[x]
    weight = up  # scratch until u⁺ is formed
    project(masses[first:first + nc], shifted[:nc], left, right, z[:nc], L[:nc + 1],
            starts[:nc + 1], weight[:nc])
    lo = 0 if left else 1
    for x in range(mc):
        lam[x] = L[lo + x]
    for x in range(nc):
        up[x] = z[x] - e * vp[x]
    sc = shifted  # scratch again: the contact scales of the run
    for x in range(mc):
        sc[x] = s[C[x]]
    chain_step_residuals(um[:nc], up[:nc], lam[:mc], vp[:nc], masses[first:first + nc],
                         inverse[first:first + nc], sc[:mc], left, right, e, 0.0, False, res)
    for x in range(CHECKED):
        if not res[x] <= tol:  # NaN fails
            return False
    return True


@inline_kernel
def end_step(q, v, vn, lam, h, theta, k, row, kept, Q, V, L):
    """The end of step k of both Moreau–Jean loops: q_{k+1} = q_k + h((1 − θ)v_k + θv_{k+1}),
    v ← v_{k+1}, and the record row of step k + 1 (q, v and the impulses ``lam``) when it
    is kept; returns the next record row."""
    for i in range(q.size):
        q[i] = q[i] + h * ((1.0 - theta) * v[i] + theta * vn[i])
        v[i] = vn[i]
    if row < kept.size and kept[row] == k + 1:
        Q[row, :] = q
        V[row, :] = v
        L[row, :] = lam
        row += 1
    return row


@kernel
def run(q, v, k_first, k_stop, row, h, theta, Ht_ptr, Ht_idx, Ht_val, b, Wh, chol, K, c,
        shift, linear, MinvH, G, s, E, diagonal, couple_a, couple_b, passive, chain, masses,
        inverse, left_wall, right_wall, e_chain, tol, kept, Q, V, L, keep, ev_head, ev_res,
        ev_dofs, ev_contacts, ev_um, ev_up, ev_vp, ev_lam, counts):
    """Steps k_first … k_stop − 1 of a Moreau–Jean run (module docstring), in place.

    Parameters
    ----------
    q, v : (n,) float arrays
        The state at step k_first; on return, the state after the last completed step.
    k_first, k_stop, row : int
        First step, step to stop before, next record row.
    h, theta : float
        Step and θ.
    Ht_ptr, Ht_idx, Ht_val : arrays
        Hᵀ in compressed rows (contact i acts on dofs Ht_idx[Ht_ptr[i]:Ht_ptr[i + 1]]).
    b : (m,) float array
        Gap offsets.
    Wh, chol : (n, n) float arrays
        Ŵ and its lower Cholesky factor (used with ``linear``).
    K, c : (n, n), (n,) float arrays
        The linear force c − Kq (with ``linear``).
    shift : (n,) float array
        Ŵ⁻¹r of a constant force (without ``linear``).
    linear : bool
        The force is c − Kq.
    MinvH, G, s : (n, m), (m, m), (m,) float arrays
        Ŵ⁻¹H, HᵀŴ⁻¹H and sᵢ = √Gᵢᵢ of all contacts.
    E : (m, m) float array
        The step law's restitution over all contacts.
    diagonal : bool
        E is diagonal (Moreau, Newton): Eγ_k needs no sum over the cluster.
    couple_a, couple_b : int arrays
        Pairs of degrees of freedom that Ŵ couples.
    passive : (m,) bool array
        Warm start of the LCP searches (each contact's last support), updated.
    chain : bool
        A chain of balls (docs/theory.md §5) with diagonal Ŵ and one restitution
        ``e_chain``: every cluster is a run of balls, solved by the isotonic projection
        (:func:`_solve_chain`) instead of the LCP search.
    masses, inverse : (n,) float arrays
        With ``chain``: the diagonal of Ŵ and its inverse.
    left_wall, right_wall : bool
        With ``chain``: the chain's walls (first and last contacts).
    e_chain : float
        With ``chain``: the restitution.
    tol : float
        Tolerance of every residual.
    kept : int array
        Step numbers of the record rows; Q, V, L receive them.
    keep : bool
        Record every solved cluster in the ev_* buffers.
    ev_head : (E, 4) int array
        Per recorded cluster: step number k + 1, first entry in the dof buffers, first entry in
        the contact buffers, number of contacts (dofs end where the next cluster's start).
    ev_res : (E, 4) float array
        Its residuals.
    ev_dofs, ev_um, ev_up, ev_vp : int and float arrays
        Its degrees of freedom, v_free, v_{k+1} and v_k on them.
    ev_contacts, ev_lam : int and float arrays
        Its contacts and impulses.
    counts : (3,) int array
        Used entries of (ev_head, dof buffers, contact buffers), updated.

    Returns
    -------
    (int, int, int)
        Status (:data:`DONE`, :data:`FAILED`, :data:`FULL`), the first step not done, the
        next record row.
    """
    n, m = v.size, b.size
    vf = np.empty(n)
    gk = np.empty(m)
    vn = np.empty(n)
    scratch = np.empty(n)
    lam_all = np.zeros(m)
    closed = np.zeros(m, dtype=np.bool_)
    cluster_work = group_work(n)
    n_of = np.zeros(n + 1, dtype=np.int64)
    m_of = np.zeros(n + 1, dtype=np.int64)
    dofs = np.empty(n, dtype=np.int64)
    cons = np.empty(m, dtype=np.int64)
    um = np.empty(n)
    up = np.empty(n)
    vp = np.empty(n)
    qc = np.empty(m)
    lam = np.empty(m)
    dense_work = _dense_work(0 if chain else n, 0 if chain else m)
    chain_work = _chain_work(n if chain else 0)
    res = np.empty(6)
    work = np.empty(2 * n + 2 * m)
    for k in range(k_first, k_stop):
        if keep and (counts[0] + n > ev_head.shape[0] or counts[1] + n > ev_dofs.size
                     or counts[2] + m > ev_contacts.size):
            return FULL, k, row
        start = (counts[0], counts[1], counts[2])
        any_closed = False
        for i in range(m):  # 1. g(q_k) + h/2 γ(v_k) ≤ 0
            g = 0.0
            gam = 0.0
            for p in range(Ht_ptr[i], Ht_ptr[i + 1]):
                g += Ht_val[p] * q[Ht_idx[p]]
                gam += Ht_val[p] * v[Ht_idx[p]]
            closed[i] = g + b[i] + (0.5 * h) * gam <= 0.0
            gk[i] = gam
            any_closed |= closed[i]
            lam_all[i] = 0.0
        _free_velocity(v, q, chol, K, c, shift, h, theta, linear, vf, scratch)  # 2.
        for i in range(n):
            vn[i] = vf[i]
        if any_closed:  # 3. clusters: dofs joined by Ŵ and by the closed contacts
            n_cl = group(closed, Ht_ptr, Ht_idx, couple_a, couple_b, cluster_work, dofs,
                         cons, n_of, m_of)
            for a in range(n_cl):
                D = dofs[n_of[a]:n_of[a + 1]]
                C = cons[m_of[a]:m_of[a + 1]]
                nc, mc = D.size, C.size
                for x in range(nc):
                    um[x] = vf[D[x]]
                    vp[x] = v[D[x]]
                need = False
                for x in range(mc):  # q = γ(v_free) + Eγ(v_k)
                    i = C[x]
                    total = 0.0
                    for p in range(Ht_ptr[i], Ht_ptr[i + 1]):
                        total += Ht_val[p] * vf[Ht_idx[p]]
                    if diagonal:
                        total += E[i, i] * gk[i]
                    else:
                        restitution = 0.0
                        for y in range(mc):
                            restitution += E[i, C[y]] * gk[C[y]]
                        total += restitution
                    qc[x] = total
                    need |= total < 0.0
                if not need:
                    continue
                if chain:
                    ok = _solve_chain(D, C, um, vp, up, lam, s, masses, inverse,
                                      left_wall and C[0] == 0, right_wall and C[mc - 1] == m - 1,
                                      e_chain, tol, chain_work, res)
                else:
                    ok = _solve_dense(D, C, um, vp, up, lam, qc, Wh, MinvH, G, s, E, Ht_ptr,
                                      Ht_idx, Ht_val, passive, tol, dense_work, res, work)
                if not ok:
                    counts[0], counts[1], counts[2] = start
                    return FAILED, k, row
                for x in range(mc):
                    lam_all[C[x]] = lam[x]
                for x in range(nc):
                    vn[D[x]] = up[x]
                if keep:
                    e = counts[0]
                    ev_head[e, 0] = k + 1
                    ev_head[e, 1] = counts[1]
                    ev_head[e, 2] = counts[2]
                    ev_head[e, 3] = mc
                    for x in range(CHECKED):
                        ev_res[e, x] = res[x]
                    for x in range(nc):
                        ev_dofs[counts[1] + x] = D[x]
                        ev_um[counts[1] + x] = um[x]
                        ev_up[counts[1] + x] = up[x]
                        ev_vp[counts[1] + x] = vp[x]
                    for x in range(mc):
                        ev_contacts[counts[2] + x] = C[x]
                        ev_lam[counts[2] + x] = lam[x]
                    counts[0] += 1
                    counts[1] += nc
                    counts[2] += mc
        row = end_step(q, v, vn, lam_all, h, theta, k, row, kept, Q, V, L)  # 4.
    return DONE, k_stop, row
