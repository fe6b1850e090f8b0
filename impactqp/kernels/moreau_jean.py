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
from .jit import inline_kernel, kernel, read_only
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


@inline_kernel
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


@inline_kernel
def _solve_dense(cl, contacts, law, tol, dense_work, res, work):
    """One cluster ``cl`` = (dofs D, contacts C, u⁻, v_k, u⁺, Λ, q) by the active-set search
    on G_CC, u⁺ = u⁻ + (Ŵ⁻¹H)_DC Λ and the dense certificate; True when certified (then
    ``law.passive`` keeps the support)."""
    D, C, um, vp, up, lam, qc = cl
    nc, mc = D.size, C.size
    Mc, Wt, MW, Gc, Ec, sc, w, pas, Lf, idx, sv, blocked = dense_work
    metric, MinvH, G, units = contacts.metric, contacts.MinvH, contacts.G, contacts.units
    ptr, cidx, val = contacts.ptr, contacts.idx, contacts.val
    e, E, passive = law
    Mv = Mc[:nc * nc].reshape((nc, nc))
    Wv = Wt[:mc * nc].reshape((mc, nc))
    Xv = MW[:nc * mc].reshape((nc, mc))
    Gv = Gc[:mc * mc].reshape((mc, mc))
    Ev = Ec[:mc * mc].reshape((mc, mc))
    for x in range(nc):
        for y in range(nc):
            Mv[x, y] = metric[D[x], D[y]]
        for y in range(mc):
            Xv[x, y] = MinvH[D[x], C[y]]
    for x in range(mc):
        for y in range(nc):
            Wv[x, y] = 0.0
        sc[x] = units[C[x]]
        pas[x] = passive[C[x]]
        for y in range(mc):
            Gv[x, y] = G[C[x], C[y]]
            if E.shape[0] > 0:
                Ev[x, y] = E[C[x], C[y]]
            else:
                Ev[x, y] = e[C[x]] if x == y else 0.0
    for x in range(mc):
        i = C[x]
        for p in range(ptr[i], ptr[i + 1]):
            for y in range(nc):
                if D[y] == cidx[p]:
                    Wv[x, y] = val[p]
    if lcp_psd_work(Gv, qc[:mc], pas[:mc], lam[:mc], w[:mc], 20 * mc + 50, Lf, idx, sv,
                    blocked) != SOLVED:
        return False
    for x in range(nc):
        total = um[x]
        for y in range(mc):
            total += Xv[x, y] * lam[y]
        up[x] = total
    dense_step_residuals(read_only(Mv), read_only(Wv), read_only(Xv), read_only(sc[:mc]),
                         read_only(um[:nc]), read_only(up[:nc]), read_only(lam[:mc]),
                         read_only(vp[:nc]), read_only(Ev), 0.0, np.bool_(False), res, work)
    # inputs read-only and run-time flags: the signature of an impact's certificate
    for x in range(CHECKED):
        if not res[x] <= tol:  # NaN fails
            return False
    for x in range(mc):
        passive[C[x]] = pas[x]
    return True


@inline_kernel
def _solve_chain(cl, units, chain, left, right, tol, chain_work, res):
    """One run ``cl`` of a chain (balls D, contacts C) with one restitution e, as the
    isotonic path solves it (docs/theory.md §14): z = prox_{T_C}(u⁻ + e v_k) by
    :func:`impactqp.kernels.chain.project`, u⁺ = z − e v_k, and the chain certificate;
    True when certified. ``left``/``right``: the run ends at the chain's wall."""
    D, C, um, vp, up, lam, _ = cl
    nc, mc = D.size, C.size
    _, masses, inverse, _, _, e = chain
    shifted, z, L, starts = chain_work
    first = D[0]
    for x in range(nc):
        shifted[x] = um[x] + e * vp[x]
    weight = up  # scratch until u⁺ is formed
    # masses writable, the velocities read-only: the signature of an impact's chain
    project(masses[first:first + nc], read_only(shifted[:nc]), left, right, z[:nc],
            L[:nc + 1], starts[:nc + 1], weight[:nc])
    lo = 0 if left else 1
    for x in range(mc):
        lam[x] = L[lo + x]
    for x in range(nc):
        up[x] = z[x] - e * vp[x]
    sc = shifted  # scratch again: the contact scales of the run
    for x in range(mc):
        sc[x] = units[C[x]]
    chain_step_residuals(read_only(um[:nc]), read_only(up[:nc]), read_only(lam[:mc]),
                         read_only(vp[:nc]), read_only(masses[first:first + nc]),
                         read_only(inverse[first:first + nc]), read_only(sc[:mc]), left, right,
                         e, 0.0, np.bool_(False), res)  # the signature of a chain's certificate
    for x in range(CHECKED):
        if not res[x] <= tol:  # NaN fails
            return False
    return True


@inline_kernel
def _record(events, k, D, C, res, um, up, vp, lam):
    """Record a solved cluster (dofs D, contacts C) of step k."""
    nc, mc = D.size, C.size
    open_record(events, k + 1, mc, nc)
    put_ints(events, D)
    put_ints(events, C)
    put_floats(events, res[:CHECKED])
    put_floats(events, um[:nc])
    put_floats(events, up[:nc])
    put_floats(events, vp[:nc])
    put_floats(events, lam[:mc])


@kernel
def run(q, v, k_first, k_stop, row, contacts, force, scheme, law, chain, record, events):
    """Steps k_first … k_stop − 1 of a Moreau–Jean run (module docstring), in place: (q, v)
    the state at step k_first, on return the state after the last completed step; ``row``
    the next record row; ``contacts`` (d = 1), ``force``, ``scheme``, ``record``
    (:mod:`impactqp.kernels.step`), ``law`` (:class:`Impacts`), ``chain`` (:class:`Chain`)
    and ``events`` (:mod:`impactqp.kernels.events`, with :func:`worst_step`). Returns
    (status :data:`DONE`, :data:`FAILED` or :data:`FULL`, the first step not done, the next
    record row)."""
    ptr, idx, val, b, _, _, couple_a, couple_b, _, _, units = contacts
    chol, K, c, shift, linear = force
    h, theta, tol = scheme
    kept, Q, V, L = record
    e, E, _ = law
    n, m = v.size, b.size
    vf, vn, y = np.empty(n), np.empty(n), np.empty(n)
    g, gk, lam_all = np.empty(m), np.empty(m), np.zeros(m)
    closed = np.zeros(m, dtype=np.bool_)
    cluster_work, n_of, m_of, dofs, cons, um, up, vp, gf, qc, lam, dense_work, chain_work, \
        res, rwork = _work(n, m, chain.on)
    for k in range(k_first, k_stop):
        if full(events):
            return FULL, k, row
        at = mark(events)
        linear_gaps(ptr, idx, val, b, 1, q, v, g, gk)  # 1.
        count = activation(g, gk, h, closed)
        free_velocity(chol, K, c, shift, linear, h, theta, q, v, vf, y)  # 2.
        for i in range(n):
            vn[i] = vf[i]
        for i in range(m):
            lam_all[i] = 0.0
        n_cl = group(closed, ptr, idx, couple_a, couple_b, cluster_work, dofs, cons, n_of,
                     m_of) if count > 0 else 0
        for a in range(n_cl):  # 3. each cluster with an approaching contact
            D = dofs[n_of[a]:n_of[a + 1]]
            C = cons[m_of[a]:m_of[a + 1]]
            nc, mc = D.size, C.size
            for x in range(nc):
                um[x] = vf[D[x]]
                vp[x] = v[D[x]]
            rows_times(ptr, idx, val, 1, C, vf, gf)
            if not step_q(gf, gk, e, E, C, 1, qc):
                continue
            cl = (D, C, um, vp, up, lam, qc)
            if chain.on:
                ok = _solve_chain(cl, units, chain, chain.left_wall and C[0] == 0,
                                  chain.right_wall and C[mc - 1] == m - 1, tol, chain_work, res)
            else:
                ok = _solve_dense(cl, contacts, law, tol, dense_work, res, rwork)
            if not ok:
                rollback(events, at)
                return FAILED, k, row
            for x in range(mc):
                lam_all[C[x]] = lam[x]
            for x in range(nc):
                vn[D[x]] = up[x]
            if events.keep:
                _record(events, k, D, C, res, um, up, vp, lam)
        row = end_step(q, v, vn, lam_all, h, theta, k, row, kept, Q, V, L)  # 4.
    return DONE, k_stop, row
