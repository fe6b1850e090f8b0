"""A whole frictional Moreau–Jean run in compiled code (docs/theory.md §17, "The compiled
loop").

:func:`run` integrates a system with a constant or linear force and Coulomb friction, step
after step, by the one step of :mod:`impactqp.kernels.step` (as the Python loop does):

1. the closed contacts (:func:`~impactqp.kernels.step.activation` on the normal rows);
2. v_free (:func:`~impactqp.kernels.step.free_velocity`);
3. on the closed set A with some negative normal q (:func:`~impactqp.kernels.step.step_q`:
   q = H_Aᵀv_free + eγ_{n,k} on the normal rows), the local problem u = W̃r + q̃ gathered in
   contact units (:func:`~impactqp.kernels.step.gather_local`), solved by the projected
   Gauss–Seidel :func:`impactqp.kernels.friction.nsgs` from r = 0, projected onto the cones
   (:func:`impactqp.kernels.friction.project_cones`) and accepted only when the figures of
   :func:`impactqp.model.friction.certify_friction` (from
   :func:`impactqp.kernels.friction.certificate_sums`) are within ``tol``;
   v_{k+1} = v_free + Ŵ⁻¹H_A r;
4. :func:`~impactqp.kernels.step.end_step`.

It stops early, with the state of the last completed step, when a step is not certified
(:data:`FAILED`: the caller solves that step with :func:`impactqp.solve_friction` and
resumes) or when the event buffers might not hold the next step (:data:`FULL`). Each solved
step is recorded (:mod:`impactqp.kernels.events`) with head integers (closed contacts,
sweeps), the closed contacts and the floats q̃, r̃ (contact units), v_free and v_{k+1}.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .events import full, open_record, put_floats, put_ints
from .friction import certificate_sums, nsgs, project_cones
from .jit import kernel
from .moreau_jean import DONE, FAILED, FULL
from .step import (
    activation,
    end_step,
    free_velocity,
    gather_local,
    linear_gaps,
    rows_times,
    step_q,
)

LOCAL_ITERATIONS = 5
"""Most projected fixed-point iterations on one contact per Gauss–Seidel sweep (5: a few
more sweeps on one contact, several times fewer operations on a box's four corners)."""


class Friction(NamedTuple):
    """Coulomb's law in the compiled loop.

    Attributes
    ----------
    mu, e : (m,) float arrays
        Friction and restitution coefficients.
    target : float
        Error ‖F‖/‖q‖ the Gauss–Seidel sweeps aim at.
    sweeps : int
        Most sweeps per step.
    """

    mu: np.ndarray
    e: np.ndarray
    target: float
    sweeps: int


def worst_step(n: int, m: int, d: int) -> np.ndarray:
    """Most (records, ints, floats) one step adds: one record, every contact closed."""
    return np.array([1, m, 2 * m * d + 2 * n], dtype=np.int64)


@kernel(internal=True)
def _certified(W, q, r, mu, d, tol):
    """The figures of :func:`impactqp.model.friction.certify_friction` of (W, q, μ, r)
    within ``tol``: ‖F‖ ≤ tol·‖q‖ and the cone gap ≤ tol·‖r‖."""
    na = q.size
    u = np.empty(na)
    for s in range(na):
        w = q[s]
        for t in range(na):
            w += W[s, t] * r[t]
        u[s] = w
    f2, _, _, cone = certificate_sums(r, u, mu, d)
    qn = np.sqrt(np.sum(q * q))
    rn = np.sqrt(np.sum(r * r))
    return (np.sqrt(f2) <= tol * (qn if qn > 0.0 else 1.0)
            and (cone == 0.0 or np.sqrt(cone) <= tol * rn))


@kernel(internal=True)
def _local(k, vf, gk, closed, contacts, friction, tol, events, vn, lam):
    """Step 3 on the closed contacts: the local problem solved and certified, v_{k+1} and
    the impulses written into ``vn`` and ``lam``, the step recorded; False hands the step
    back."""
    ptr, idx, val, _, d, _, _, _, MinvH, G, units = contacts
    cons = np.flatnonzero(closed)
    closed_count = cons.size
    na = closed_count * d
    cols = np.empty(na, dtype=np.int64)
    for t in range(closed_count):
        for i in range(d):
            cols[t * d + i] = cons[t] * d + i
    qa = np.empty(na)
    if not step_q(rows_times(ptr, idx, val, d, cons, vf, np.empty(na)), gk, friction.e,
                  np.zeros((0, 0)), cons, d, qa):
        return True  # r = 0 solves the step exactly
    W, qt = gather_local(G, units, cols, qa, np.empty((na, na)), np.empty(na))
    mu = friction.mu[cons]
    r = np.zeros(na)
    done, _ = nsgs(W, qt, mu, d, r, friction.target, friction.sweeps,
                   np.int64(LOCAL_ITERATIONS))  # not a literal: the sweeps compile once
    r = project_cones(r, mu, d)
    if not _certified(W, qt, r, mu, d, tol):
        return False
    for j in range(vf.size):
        w = vf[j]
        for t in range(na):
            w += MinvH[j, cols[t]] * r[t] / units[cols[t]]
        vn[j] = w
    for t in range(na):
        lam[cols[t]] = r[t] / units[cols[t]]
    if events.keep:
        open_record(events, k + 1, closed_count, done)
        put_ints(events, cons)
        put_floats(events, qt)
        put_floats(events, r)
        put_floats(events, vf)
        put_floats(events, vn)
    return True


@kernel
def run(q, v, k_first, k_stop, row, contacts, force, scheme, friction, record, events):
    """Steps k_first … k_stop − 1 of a frictional Moreau–Jean run (module docstring), in place.

    Parameters
    ----------
    q, v : (n,) float arrays
        The state at step k_first; on return, the state after the last completed step.
    k_first, k_stop, row : int
        First step, step to stop before, next record row.
    contacts : impactqp.kernels.step.Contacts
        H (d = 2 or 3 rows per contact), b, Ŵ⁻¹H, HᵀŴ⁻¹H and the contact units in which
        each step's local problem is gathered, solved and checked (docs/theory.md §16, §17).
    force : impactqp.kernels.step.Force
    scheme : impactqp.kernels.step.Scheme
    friction : Friction
    record : impactqp.kernels.step.Record
    events : impactqp.kernels.events.Events
        With :func:`worst_step`.

    Returns
    -------
    (int, int, int)
        Status (:data:`DONE`, :data:`FAILED`, :data:`FULL`), the first step not done, the
        next record row.
    """
    ptr, idx, val, b, d = contacts.ptr, contacts.idx, contacts.val, contacts.b, contacts.d
    chol, K, c, shift, linear = force
    h, theta, tol = scheme
    kept, Q, V, L = record
    n, m = v.size, b.size
    vf, vn, y = np.empty(n), np.empty(n), np.empty(n)
    g, gk = np.empty(m), np.empty(m)
    closed = np.zeros(m, dtype=np.bool_)
    lam = np.zeros(m * d)
    for k in range(k_first, k_stop):
        if full(events):
            return FULL, k, row
        linear_gaps(ptr, idx, val, b, d, q, v, g, gk)  # 1.
        count = activation(g, gk, h, closed)
        free_velocity(chol, K, c, shift, linear, h, theta, q, v, vf, y)  # 2.
        for j in range(n):
            vn[j] = vf[j]
        for j in range(m * d):
            lam[j] = 0.0
        if count > 0 and not _local(k, vf, gk, closed, contacts, friction, tol, events, vn,
                                    lam):  # 3.
            return FAILED, k, row
        row = end_step(q, v, vn, lam, h, theta, k, row, kept, Q, V, L)  # 4.
    return DONE, k_stop, row
