"""A whole frictional Moreau–Jean run in compiled code (docs/theory.md §17, "The compiled
loop").

:func:`run` integrates a dense linear system with a constant or linear force and Coulomb
friction, step after step, as the Python loop's frictional step does:

1. closed contacts: gᵢ(q_k) + ½h γ_{n,i}(v_k) ≤ 0 (normal rows of H);
2. free velocity v_free, by :func:`impactqp.kernels.moreau_jean._free_velocity`;
3. on the closed set A with some negative q_n, the local problem u = W r + q with
   W = H_AᵀŴ⁻¹H_A gathered from the products of all contacts formed once and
   q = H_Aᵀv_free + eγ_{n,k} on the normal rows, solved by the projected Gauss–Seidel
   :func:`impactqp.kernels.friction.nsgs` from r = 0, projected onto the cones
   (:func:`impactqp.kernels.friction.project_cones`) and accepted only when the figures of
   :func:`impactqp.model.friction.certify_friction` (from
   :func:`impactqp.kernels.friction.certificate_sums`) are within ``tol``;
   v_{k+1} = v_free + Ŵ⁻¹H_A r;
4. q_{k+1} = q_k + h((1 − θ)v_k + θv_{k+1}), and the kept rows are recorded.

It stops early, with the state of the last completed step, when a step is not certified
(:data:`FAILED`: the caller solves that step with :func:`impactqp.solve_friction` and
resumes) or when the event buffers are full (:data:`FULL`).
"""

from __future__ import annotations

import numpy as np

from .friction import certificate_sums, nsgs, project_cones
from .jit import kernel
from .moreau_jean import DONE, FAILED, FULL, _free_velocity, end_step

LOCAL_ITERATIONS = 5
"""Most projected fixed-point iterations on one contact per Gauss–Seidel sweep (5: a few
more sweeps on one contact, several times fewer operations on a box's four corners)."""

HEAD = 6
"""Columns of a recorded step's head: step k + 1, first contact, contacts, first local entry,
first velocity entry, sweeps."""


@kernel
def run(q, v, k_first, k_stop, row, h, theta, Hn, b, Ht, chol, K, c, shift, linear, MinvH,
        G, units, mu, e, d, tol, target, sweeps, kept, Q, V, L, keep, ev_head, ev_contacts,
        ev_q, ev_r, ev_um, ev_up, counts):
    """Steps k_first … k_stop − 1 of a frictional Moreau–Jean run (module docstring), in place.

    Parameters
    ----------
    q, v : (n,) float arrays
        The state at step k_first; on return, the state after the last completed step.
    k_first, k_stop, row : int
        First step, step to stop before, next record row.
    h, theta : float
        Step and θ.
    Hn : (m, n) float array
        The normal rows of Hᵀ.
    b : (m,) float array
        Gap offsets.
    Ht : (d·m, n) float array
        Hᵀ, every row.
    chol, K, c, shift, linear
        The force, as :func:`impactqp.kernels.moreau_jean.run` takes it.
    MinvH, G : (n, d·m), (d·m, d·m) float arrays
        Ŵ⁻¹H and HᵀŴ⁻¹H of all contacts.
    units : (d·m,) float array
        s_c = √G_nn of each row's contact: the step's local problem is gathered, solved and
        checked in contact units (W̃ = DWD, q̃ = Dq, D = diag(1/s); docs/theory.md §16, §17),
        its reaction r̃ = s·r.
    mu, e : (m,) float arrays
        Friction and restitution coefficients.
    d : int
        Rows per contact.
    tol, target : float
        Tolerance of the certificate; error ‖F‖/‖q‖ the Gauss–Seidel sweeps aim at.
    sweeps : int
        Most sweeps per step.
    kept : int array
        Step numbers of the record rows; Q, V, L receive them.
    keep : bool
        Record every solved step in the ev_* buffers.
    ev_head : (E, HEAD) int array
        Per recorded step: step number k + 1, first entry in ``ev_contacts``, number of
        contacts, first entry in ``ev_q``/``ev_r``, first entry in ``ev_um``/``ev_up``,
        sweeps done.
    ev_contacts, ev_q, ev_r, ev_um, ev_up : arrays
        The closed contacts, q̃, r̃ (contact units), v_free and v_{k+1} of each recorded step.
    counts : (4,) int array
        Used entries of (ev_head, ev_contacts, ev_q, ev_um), updated.

    Returns
    -------
    (int, int, int)
        Status (:data:`DONE`, :data:`FAILED`, :data:`FULL`), the first step not done, the
        next record row.
    """
    n, m = v.size, b.size
    vf = np.empty(n)
    vn = np.empty(n)
    y = np.empty(n)
    gam = np.empty(m)
    cons = np.empty(m, dtype=np.int64)
    cols = np.empty(m * d, dtype=np.int64)
    lam = np.zeros(m * d)
    for k in range(k_first, k_stop):
        if keep and (counts[0] + 1 > ev_head.shape[0] or counts[1] + m > ev_contacts.size
                     or counts[2] + m * d > ev_q.size or counts[3] + n > ev_um.size):
            return FULL, k, row
        closed = 0
        for i in range(m):
            g = b[i]
            gv = 0.0
            for j in range(n):
                g += Hn[i, j] * q[j]
                gv += Hn[i, j] * v[j]
            gam[i] = gv
            if g + 0.5 * h * gv <= 0.0:
                cons[closed] = i
                closed += 1
        _free_velocity(v, q, chol, K, c, shift, h, theta, linear, vf, y)
        for j in range(n):
            vn[j] = vf[j]
        lam[:] = 0.0
        na = closed * d
        qa = np.empty(na)
        approaching = False
        for t in range(closed):
            for i in range(d):
                cols[t * d + i] = cons[t] * d + i
        for t in range(na):
            s = 0.0
            for j in range(n):
                s += Ht[cols[t], j] * vf[j]
            qa[t] = s / units[cols[t]]
        for t in range(closed):
            qa[t * d] += e[cons[t]] * gam[cons[t]] / units[cols[t * d]]
            if qa[t * d] < 0.0:
                approaching = True
        if approaching:  # else r = 0 solves the step exactly
            Wa = np.empty((na, na))
            for s_ in range(na):
                for t in range(na):
                    Wa[s_, t] = G[cols[s_], cols[t]] / (units[cols[s_]] * units[cols[t]])
            mua = np.empty(closed)
            for t in range(closed):
                mua[t] = mu[cons[t]]
            r = np.zeros(na)
            done, _ = nsgs(Wa, qa, mua, d, r, target, sweeps, LOCAL_ITERATIONS)
            r = project_cones(r, mua, d)
            u = np.empty(na)
            for s_ in range(na):
                w = qa[s_]
                for t in range(na):
                    w += Wa[s_, t] * r[t]
                u[s_] = w
            f2, _, _, cone = certificate_sums(r, u, mua, d)
            qn = np.sqrt(np.sum(qa * qa))
            rn = np.sqrt(np.sum(r * r))
            if not (np.sqrt(f2) <= tol * (qn if qn > 0.0 else 1.0)
                    and (cone == 0.0 or np.sqrt(cone) <= tol * rn)):
                return FAILED, k, row
            for j in range(n):
                w = vf[j]
                for t in range(na):
                    w += MinvH[j, cols[t]] * r[t] / units[cols[t]]
                vn[j] = w
            for t in range(na):
                lam[cols[t]] = r[t] / units[cols[t]]
            if keep:
                e0, c0, q0, u0 = counts[0], counts[1], counts[2], counts[3]
                ev_head[e0, 0] = k + 1
                ev_head[e0, 1] = c0
                ev_head[e0, 2] = closed
                ev_head[e0, 3] = q0
                ev_head[e0, 4] = u0
                ev_head[e0, 5] = done
                for t in range(closed):
                    ev_contacts[c0 + t] = cons[t]
                for t in range(na):
                    ev_q[q0 + t] = qa[t]
                    ev_r[q0 + t] = r[t]
                for j in range(n):
                    ev_um[u0 + j] = vf[j]
                    ev_up[u0 + j] = vn[j]
                counts[0] += 1
                counts[1] += closed
                counts[2] += na
                counts[3] += n
        row = end_step(q, v, vn, lam, h, theta, k, row, kept, Q, V, L)
    return DONE, k_stop, row
