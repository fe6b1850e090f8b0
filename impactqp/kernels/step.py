"""One Moreau–Jean step, the one specification every loop calls (docs/theory.md §14, §17).

A step from (q_k, v_k) to (q_{k+1}, v_{k+1}) is, whatever the law and whoever runs it (the
compiled loops :mod:`impactqp.kernels.moreau_jean` and :mod:`impactqp.kernels.friction_loop`,
the Python loop of :mod:`impactqp.simulation.time_stepping`):

1. :func:`activation`: the contacts closed for the step, gᵢ(q_k) + ½h γᵢ(v_k) ≤ 0;
2. :func:`free_velocity`: v_free of the θ-method (a constant or linear force);
3. :func:`step_q`: the step's q = H_Cᵀv_free + Eγ_k on the closed contacts C (restitution on
   the normal rows only), and, with friction, :func:`gather_local`: the local problem
   u = W̃r + q̃ gathered in contact units (W̃ = DWD, q̃ = Dq, D = diag(1/s) with s of
   :func:`impactqp.kernels.units.contact_units`); the law's solve then gives v_{k+1};
4. :func:`end_step`: q_{k+1} = q_k + h((1 − θ)v_k + θv_{k+1}) and the recorded row.

The compiled loops take their arguments grouped (:class:`Contacts`, :class:`Force`,
:class:`Scheme`, :class:`Record`, the event buffers) and unpack them once per call; the
rules above take plain arrays, so a step touches no tuple.

What the step needs from the system is handed to it, not built into it: the gaps g(q_k),
the normal velocities γ_k = H_nᵀv_k, v_free and a :class:`Contacts` (H, Ŵ and the products
Ŵ⁻¹H, HᵀŴ⁻¹H, the contact units). A linear system (constant M and H) forms its
:class:`Contacts` once and computes g and γ by :func:`linear_gaps`. A system whose mass
matrix M(q) and gaps g(q) depend on the configuration (H(q) = ∂g/∂q: a pendulum cradle, a
rocking block, a slider-crank) would evaluate M(q_k), H(q_k) and g(q_k) at the start of each
step, form that step's :class:`Contacts` and v_free from them, and call the same functions:
nothing in them assumes the data are constant over a run.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from .active_set import cholesky_solve
from .jit import inline_kernel, kernel


class Contacts(NamedTuple):
    """The contacts of a system as one step sees them (formed once for a linear system).

    Attributes
    ----------
    ptr, idx, val : int, int, float arrays
        Hᵀ in compressed rows, d rows per contact (the normal first): row j acts on the
        dofs idx[ptr[j]:ptr[j + 1]] with the weights val[ptr[j]:ptr[j + 1]].
    b : (m,) float array
        Gap offsets of the linear gaps g = H_nᵀq + b (:func:`linear_gaps`).
    d : int
        Rows per contact (1 frictionless, 2 or 3 with friction).
    metric : (n, n) float array
        Ŵ = M + h²θ²K, the iteration matrix (read by the frictionless certificate).
    couple_a, couple_b : int arrays
        Pairs of degrees of freedom that Ŵ couples (what clusters join).
    MinvH, G : (n, d·m), (d·m, d·m) float arrays
        Ŵ⁻¹H and HᵀŴ⁻¹H of all contacts.
    units : (d·m,) float array
        s_c of each row's contact (:func:`impactqp.kernels.units.contact_units` of G's
        diagonal): the unit the step's problem is certified (and, with friction, posed) in.
    """

    ptr: np.ndarray
    idx: np.ndarray
    val: np.ndarray
    b: np.ndarray
    d: int
    metric: np.ndarray
    couple_a: np.ndarray
    couple_b: np.ndarray
    MinvH: np.ndarray
    G: np.ndarray
    units: np.ndarray


class Force(NamedTuple):
    """The force of the θ-method as :func:`free_velocity` takes it.

    Attributes
    ----------
    chol : (n, n) float array
        The lower Cholesky factor L of Ŵ = LLᵀ (with ``linear``).
    K, c : (n, n), (n,) float arrays
        The linear force c − Kq (with ``linear``).
    shift : (n,) float array
        Ŵ⁻¹r of a constant force, formed once (without ``linear``).
    linear : bool
        The force is c − Kq.
    """

    chol: np.ndarray
    K: np.ndarray
    c: np.ndarray
    shift: np.ndarray
    linear: bool


class Scheme(NamedTuple):
    """The settings of a run: step h, θ and the tolerance of every certificate."""

    h: float
    theta: float
    tol: float


class Record(NamedTuple):
    """The rows a run keeps: the step numbers ``kept`` and the arrays Q, V, L receiving the
    positions, velocities and impulses after those steps."""

    kept: np.ndarray
    Q: np.ndarray
    V: np.ndarray
    L: np.ndarray


@inline_kernel
def linear_gaps(ptr, idx, val, b, d, q, v, g, gamma):
    """The gaps g = H_nᵀq + b and normal velocities γ = H_nᵀv of a linear system (H_n: row
    c·d of each contact c of Hᵀ in compressed rows ``ptr``, ``idx``, ``val``; see
    :class:`Contacts`), into ``g`` and ``gamma``."""
    for i in range(g.size):
        r = i * d
        gap = 0.0
        vel = 0.0
        for p in range(ptr[r], ptr[r + 1]):
            gap += val[p] * q[idx[p]]
            vel += val[p] * v[idx[p]]
        g[i] = gap + b[i]
        gamma[i] = vel
    return g, gamma


def gap_ahead(g: Any, gamma: Any, h: float) -> Any:
    """gᵢ + ½h γᵢ, the gap predicted half a step ahead (docs/theory.md §14), of one contact
    or elementwise of arrays: :func:`activation` closes a contact where it is ≤ 0. Plain
    Python for arrays (numpy's operations give the same bits), and :func:`predicted_gap`
    in the kernels: compiled for arrays, it would cost half a second of compile time for
    one call."""
    return g + (0.5 * h) * gamma


predicted_gap = inline_kernel(gap_ahead)
"""The kernels' :func:`gap_ahead` of one contact."""


@inline_kernel
def activation(g, gamma, h, closed):
    """The contacts the step closes, closed[i] = gᵢ + ½h γᵢ ≤ 0 (:func:`predicted_gap`;
    docs/theory.md §14); returns how many."""
    count = 0
    for i in range(g.size):
        closed[i] = predicted_gap(g[i], gamma[i], h) <= 0.0
        count += closed[i]
    return count


@inline_kernel
def free_velocity(chol, K, c, shift, linear, h, theta, q, v, out, y):
    """v_free into ``out`` for the force of :class:`Force` (its fields first): v − shift (a
    constant force: shift = Ŵ⁻¹r formed once) or, for the force c − Kq,
    v − Ŵ⁻¹(hKq + h²θKv − hc), solved as LAPACK's potrs does (forward, then backward
    substitution; ``y`` is scratch of n floats)."""
    n = v.size
    if not linear:
        for i in range(n):
            out[i] = v[i] - shift[i]
        return out
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
    return out


@inline_kernel
def rows_times(ptr, idx, val, d, C, x, out):
    """H_Cᵀx on the d rows of each contact in C (in order) into ``out`` (Hᵀ in compressed
    rows, as :class:`Contacts` holds it)."""
    for a in range(C.size):
        for j in range(d):
            r = C[a] * d + j
            total = 0.0
            for p in range(ptr[r], ptr[r + 1]):
                total += val[p] * x[idx[p]]
            out[a * d + j] = total
    return out


@inline_kernel
def step_q(gamma_free, gamma_k, e, E, C, d, out):
    """The step's q on the contacts C (d rows each, the normal first): q = γ(v_free) + Eγ_k
    on the normal rows and γ(v_free) on the tangent rows (docs/theory.md §14, §17).

    Parameters
    ----------
    gamma_free : (d·|C|,) float array
        H_Cᵀv_free.
    gamma_k : float array
        Normal velocities γ_k at the start of the step, indexed like ``e`` and ``E``.
    e, E : float arrays
        The restitution: one coefficient per contact (``e``, with E of shape (0, 0)) or
        Frémond's matrix ``E`` (q_c adds Σ_{c' ∈ C} E[c, c'] γ_k[c']).
    C : int array
        The contacts.
    d : int
    out : (d·|C|,) float array
        Receives q.

    Returns
    -------
    bool
        Some normal row of q is negative: some contact approaches, else Λ = 0 solves the step.
    """
    approaching = False
    for x in range(C.size):
        i = C[x]
        if E.shape[0] == 0:
            restitution = e[i] * gamma_k[i]
        else:
            restitution = 0.0
            for y in range(C.size):
                restitution += E[i, C[y]] * gamma_k[C[y]]
        out[x * d] = gamma_free[x * d] + restitution
        approaching |= out[x * d] < 0.0
        for j in range(1, d):
            out[x * d + j] = gamma_free[x * d + j]
    return approaching


@kernel
def gather_local(G, units, cols, q, W_out, q_out):
    """The local problem u = W̃r + q̃ of the rows ``cols`` in contact units
    (docs/theory.md §16, §17): W̃ = G[cols, cols]/(sₛs_t), q̃ = q/s with s = units[cols];
    its reaction r̃ = s·r. ``q`` is the step's q on those rows (:func:`step_q`)."""
    na = cols.size
    for a in range(na):
        sa = units[cols[a]]
        q_out[a] = q[a] / sa
        for t in range(na):
            W_out[a, t] = G[cols[a], cols[t]] / (sa * units[cols[t]])
    return W_out, q_out


@inline_kernel
def end_step(q, v, vn, lam, h, theta, k, row, kept, Q, V, L):
    """The end of step k: q_{k+1} = q_k + h((1 − θ)v_k + θv_{k+1}), v ← v_{k+1} (in place),
    and the record row of step k + 1 (q, v and the impulses ``lam``) when it is kept (the
    fields of :class:`Record` last); returns the next record row."""
    for i in range(q.size):
        q[i] = q[i] + h * ((1.0 - theta) * v[i] + theta * vn[i])
        v[i] = vn[i]
    if row < kept.size and kept[row] == k + 1:
        for i in range(q.size):
            Q[row, i] = q[i]
            V[row, i] = v[i]
        for i in range(lam.size):
            L[row, i] = lam[i]
        row += 1
    return row
