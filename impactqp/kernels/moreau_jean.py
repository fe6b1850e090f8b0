"""A whole Moreau–Jean run in compiled code (docs/theory.md §14, "The compiled loop").

:func:`run` integrates a system with a constant or linear force and a complementarity law in
its step form ``0 ≤ Λ ⟂ γ_{k+1} + Eγ_k ≥ 0``, step after step, by the one step of
:mod:`impactqp.kernels.step`:

1. the closed contacts (:func:`~impactqp.kernels.step.activation` of the gaps and normal
   velocities the system hands the step, here :func:`~impactqp.kernels.step.linear_gaps`);
2. v_free (:func:`~impactqp.kernels.step.free_velocity`, Ŵ = M + h²θ²K factorized once);
3. the closed contacts grouped into clusters by :func:`impactqp.kernels.clusters.group`
   (as :class:`impactqp.simulation.clusters.ClusterCache` groups them); a cluster whose
   step q (:func:`~impactqp.kernels.step.step_q`) is ≥ 0 needs no impulse; the others solve
   the LCP ``0 ≤ Λ ⟂ G_cΛ + q ≥ 0`` by the active-set search
   (:func:`impactqp.kernels.active_set.lcp_psd_work`, warm-started by the contacts' last
   support), with G_c and Ŵ⁻¹H_c taken from the products of all contacts, and their
   certificate is recomputed by :func:`impactqp.kernels.residuals.dense_step_residuals`; on
   a chain of balls with one restitution e (what the isotonic path of the Python loop
   takes) a run is instead z = prox_{T_C}(v_free + e v_k) by
   :func:`impactqp.kernels.chain.project`, v_{k+1} = z − e v_k, certified by
   :func:`impactqp.kernels.residuals.chain_step_residuals` in O(N);
4. :func:`~impactqp.kernels.step.end_step`.

The kernel stops early, with the state of the last completed step, when a certificate fails
(:data:`FAILED`: the caller solves that step on the general path and resumes) or when the
event buffers might not hold the next step (:data:`FULL`: the caller enlarges them and
resumes). Each solved cluster is recorded (:mod:`impactqp.kernels.events`) with head
integers (contacts, dofs), the integers (dofs, contacts) and the floats (residuals, v_free,
v_{k+1} and v_k on its dofs, its impulses).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .active_set import SOLVED, lcp_psd_work
from .chain import project
from .clusters import group, group_work
from .events import full, mark, open_record, put_floats, put_ints, rollback
from .jit import kernel
from .residuals import chain_step_residuals, dense_step_residuals
from .step import activation, end_step, free_velocity, linear_gaps, rows_times, step_q

DONE, FAILED, FULL = 0, 1, 2
"""Status codes of :func:`run`."""

CHECKED = 4
"""Residuals of the step law's certificate: momentum, impulse sign, law feasibility and
complementarity (the first four of :data:`impactqp.kernels.residuals.RESIDUALS`)."""


class Impacts(NamedTuple):
    """The step law of the frictionless loop.

    Attributes
    ----------
    e : (m,) float array
        One restitution per contact (a diagonal E: Moreau, Newton), or empty.
    E : (m, m) float array
        Frémond's matrix, or of shape (0, 0) with ``e``.
    passive : (m,) bool array
        Warm start of the LCP searches (each contact's last support), updated.
    """

    e: np.ndarray
    E: np.ndarray
    passive: np.ndarray


class Chain(NamedTuple):
    """A chain of balls (docs/theory.md §5) with diagonal Ŵ and one restitution: every
    cluster is a run of balls, solved by the isotonic projection instead of the LCP search.

    Attributes
    ----------
    on : bool
        The system is such a chain (else the other fields are unused).
    masses, inverse : (n,) float arrays
        The diagonal of Ŵ and its inverse.
    left_wall, right_wall : bool
        The chain's walls (its first and last contacts).
    e : float
        The restitution.
    """

    on: bool
    masses: np.ndarray
    inverse: np.ndarray
    left_wall: bool
    right_wall: bool
    e: float


def worst_step(n: int, m: int) -> np.ndarray:
    """Most (records, ints, floats) one step adds: a cluster per degree of freedom, every
    dof and contact in some cluster."""
    return np.array([n, n + m, CHECKED * n + 3 * n + m], dtype=np.int64)


@kernel
def _work(n, m, chain):
    """Scratch of a run: the clusters' buffers, the dense or chain solves' scratch."""
    dense = 0 if chain else n
    mm = 0 if chain else m
    nk = n if chain else 0
    return (group_work(n), np.zeros(n + 1, dtype=np.int64), np.zeros(n + 1, dtype=np.int64),
            np.empty(n, dtype=np.int64), np.empty(m, dtype=np.int64),
            np.empty(n), np.empty(n), np.empty(n), np.empty(m), np.empty(m), np.empty(m),
            (np.empty(dense * dense), np.empty(mm * dense), np.empty(dense * mm),
             np.empty(mm * mm), np.empty(mm * mm), np.empty(mm), np.empty(mm),
             np.empty(mm, dtype=np.bool_), np.empty((mm, mm)), np.empty(mm, dtype=np.int64),
             np.empty(mm), np.empty(mm, dtype=np.bool_)),
            (np.empty(nk + 1), np.empty(nk), np.empty(nk + 1), np.empty(nk + 1, dtype=np.int64)),
            np.empty(6), np.empty(2 * n + 2 * m))


@kernel
def _solve_dense(cl, contacts, law, tol, dense_work, res, work):
    """One cluster ``cl`` = (dofs D, contacts C, u⁻, v_k, u⁺, Λ, q) by the active-set search
    on G_CC, u⁺ = u⁻ + (Ŵ⁻¹H)_DC Λ and the dense certificate; True when certified (then
    ``law.passive`` keeps the support)."""
    D, C, um, vp, up, lam, qc = cl
    nc, mc = D.size, C.size
    Mc, Wt, MW, Gc, Ec, sc, w, pas, Lf, idx, sv, blocked = dense_work
    Mv = Mc[:nc * nc].reshape((nc, nc))
    Wv = Wt[:mc * nc].reshape((mc, nc))
    Xv = MW[:nc * mc].reshape((nc, mc))
    Gv = Gc[:mc * mc].reshape((mc, mc))
    Ev = Ec[:mc * mc].reshape((mc, mc))
    for x in range(nc):
        for y in range(nc):
            Mv[x, y] = contacts.metric[D[x], D[y]]
        for y in range(mc):
            Xv[x, y] = contacts.MinvH[D[x], C[y]]
    for x in range(mc):
        for y in range(nc):
            Wv[x, y] = 0.0
        sc[x] = contacts.units[C[x]]
        pas[x] = law.passive[C[x]]
        for y in range(mc):
            Gv[x, y] = contacts.G[C[x], C[y]]
            if law.E.shape[0] > 0:
                Ev[x, y] = law.E[C[x], C[y]]
            else:
                Ev[x, y] = law.e[C[x]] if x == y else 0.0
    for x in range(mc):
        i = C[x]
        for p in range(contacts.ptr[i], contacts.ptr[i + 1]):
            for y in range(nc):
                if D[y] == contacts.idx[p]:
                    Wv[x, y] = contacts.val[p]
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
        law.passive[C[x]] = pas[x]
    return True


@kernel
def _solve_chain(cl, units, chain, left, right, tol, chain_work, res):
    """One run ``cl`` of a chain (balls D, contacts C) with one restitution e, as the
    isotonic path solves it (docs/theory.md §14): z = prox_{T_C}(u⁻ + e v_k) by
    :func:`impactqp.kernels.chain.project`, u⁺ = z − e v_k, and the chain certificate;
    True when certified. ``left``/``right``: the run ends at the chain's wall."""
    D, C, um, vp, up, lam, _ = cl
    nc, mc = D.size, C.size
    e = chain.e
    shifted, z, L, starts = chain_work
    first = D[0]
    for x in range(nc):
        shifted[x] = um[x] + e * vp[x]
    weight = up  # scratch until u⁺ is formed
    project(chain.masses[first:first + nc], shifted[:nc], left, right, z[:nc], L[:nc + 1],
            starts[:nc + 1], weight[:nc])
    lo = 0 if left else 1
    for x in range(mc):
        lam[x] = L[lo + x]
    for x in range(nc):
        up[x] = z[x] - e * vp[x]
    sc = shifted  # scratch again: the contact scales of the run
    for x in range(mc):
        sc[x] = units[C[x]]
    chain_step_residuals(um[:nc], up[:nc], lam[:mc], vp[:nc], chain.masses[first:first + nc],
                         chain.inverse[first:first + nc], sc[:mc], left, right, e, 0.0, False,
                         res)
    for x in range(CHECKED):
        if not res[x] <= tol:  # NaN fails
            return False
    return True


@kernel
def _clusters(k, v, vf, gk, closed, contacts, law, chain, tol, events, work, vn, lam_all):
    """Step 3 on the closed contacts: each cluster with an approaching contact solved,
    v_{k+1} and Λ written into ``vn`` and ``lam_all``, each solved cluster recorded; False
    (at the first cluster not certified) hands the step back."""
    cluster_work, n_of, m_of, dofs, cons, um, up, vp, gf, qc, lam, dense_work, chain_work, \
        res, rwork = work
    m = gk.size
    n_cl = group(closed, contacts.ptr, contacts.idx, contacts.couple_a, contacts.couple_b,
                 cluster_work, dofs, cons, n_of, m_of)
    for a in range(n_cl):
        D = dofs[n_of[a]:n_of[a + 1]]
        C = cons[m_of[a]:m_of[a + 1]]
        nc, mc = D.size, C.size
        for x in range(nc):
            um[x] = vf[D[x]]
            vp[x] = v[D[x]]
        rows_times(contacts, C, vf, gf)
        if not step_q(gf, gk, law.e, law.E, C, 1, qc):
            continue
        cl = (D, C, um, vp, up, lam, qc)
        if chain.on:
            ok = _solve_chain(cl, contacts.units, chain, chain.left_wall and C[0] == 0,
                              chain.right_wall and C[mc - 1] == m - 1, tol, chain_work, res)
        else:
            ok = _solve_dense(cl, contacts, law, tol, dense_work, res, rwork)
        if not ok:
            return False
        for x in range(mc):
            lam_all[C[x]] = lam[x]
        for x in range(nc):
            vn[D[x]] = up[x]
        if events.keep:
            open_record(events, k + 1, mc, nc)
            put_ints(events, D)
            put_ints(events, C)
            put_floats(events, res[:CHECKED])
            put_floats(events, um[:nc])
            put_floats(events, up[:nc])
            put_floats(events, vp[:nc])
            put_floats(events, lam[:mc])
    return True


@kernel
def run(q, v, k_first, k_stop, row, contacts, force, scheme, law, chain, record, events):
    """Steps k_first … k_stop − 1 of a Moreau–Jean run (module docstring), in place.

    Parameters
    ----------
    q, v : (n,) float arrays
        The state at step k_first; on return, the state after the last completed step.
    k_first, k_stop, row : int
        First step, step to stop before, next record row.
    contacts : impactqp.kernels.step.Contacts
        H (d = 1), b, Ŵ, its couplings, Ŵ⁻¹H, HᵀŴ⁻¹H and the contact units.
    force : impactqp.kernels.step.Force
    scheme : impactqp.kernels.step.Scheme
    law : Impacts
    chain : Chain
    record : impactqp.kernels.step.Record
    events : impactqp.kernels.events.Events
        With :func:`worst_step`.

    Returns
    -------
    (int, int, int)
        Status (:data:`DONE`, :data:`FAILED`, :data:`FULL`), the first step not done, the
        next record row.
    """
    n, m = v.size, contacts.b.size
    vf, vn, y = np.empty(n), np.empty(n), np.empty(n)
    g, gk, lam = np.empty(m), np.empty(m), np.zeros(m)
    closed = np.zeros(m, dtype=np.bool_)
    work = _work(n, m, chain.on)
    for k in range(k_first, k_stop):
        if full(events):
            return FULL, k, row
        at = mark(events)
        linear_gaps(contacts, q, v, g, gk)  # 1.
        count = activation(g, gk, scheme.h, closed)
        free_velocity(force, scheme, q, v, vf, y)  # 2.
        vn[:] = vf
        lam[:] = 0.0
        if count > 0 and not _clusters(k, v, vf, gk, closed, contacts, law, chain, scheme.tol,
                                       events, work, vn, lam):  # 3.
            rollback(events, at)
            return FAILED, k, row
        row = end_step(q, v, vn, lam, scheme, k, row, record)  # 4.
    return DONE, k_stop, row
