"""Moreau–Jean time-stepping with any impact law (docs/theory.md §14).

One step from (q_k, v_k) at t_k to t_{k+1} = t₀ + (k+1)h, in the order Siconos' MoreauJeanOSI
uses:

1. closed contacts: gᵢ(q_k) + ½h γᵢ(v_k) ≤ 0 (the gap predicted half a step ahead);
2. free velocity: v_free = v_k + Ŵ⁻¹ h((1 − θ)f_k + θf_{k+1} − Kq_k − hθKv_k), with the
   iteration matrix Ŵ = M + h²θ²K of a :class:`~impactqp.simulation.system.LinearForce`
   (Ŵ = M and K = 0 otherwise; a callable force is evaluated at (t_k, q_k, v_k) and at
   (t_{k+1}, q_k + hv_k, v_k));
3. the impact problem (Ŵ, H_closed, u⁻ = v_free) of each cluster, solved with the law through
   :func:`impactqp.solve` (complementarity laws in the step form
   ``0 ≤ Λ ⟂ γ_{k+1} + Eγ_k``), giving v_{k+1} = u⁺;
4. q_{k+1} = q_k + h((1 − θ)v_k + θv_{k+1}).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from ..base.checks import DEFAULT_TOL
from ..laws.base import ImpactLaw
from ..model.structure import ImpactStructure
from .clusters import ClusterCache
from .impacts import ImpactSolver
from .system import LinearSystem
from .trajectory import Trajectory


def step_count(t0: float, t_end: float, h: float) -> int:
    """Number of steps of length h that reach t_end (at least one)."""
    return max(1, math.ceil((t_end - t0) / h - 1e-9))


class _FreeVelocity:
    """v_free of step 2 for the system's kind of force, with Ŵ factorized once."""

    def __init__(self, system: LinearSystem, h: float, theta: float) -> None:
        self.system, self.h, self.theta = system, h, theta
        lin = system.linear_force
        self.K = None if lin is None else lin.stiffness
        if self.K is None:
            self.metric, self.solver = system.M, system.structure
        else:
            M = system.M
            K = sp.csc_matrix(self.K) if sp.issparse(M) else np.asarray(
                self.K.toarray() if sp.issparse(self.K) else self.K)
            self.metric = M + (h * theta) ** 2 * K
            self.solver = ImpactStructure(self.metric, np.zeros((system.n_dof, 0)))
            self.constant = lin.constant

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        h, th = self.h, self.theta
        if self.K is not None:  # Ŵ(v_free − v_k) = h c − hKq_k − h²θKv_k
            residual = h * (self.K @ q) + (h * h * th) * (self.K @ v) - h * self.constant
        elif self.system.constant_force is not None:
            f = self.system.constant_force
            residual = -(h * (1.0 - th)) * f - (h * th) * f
        else:
            f_k = self.system.force_at(t, q, v)
            f_next = self.system.force_at(t + h, q + h * v, v)
            residual = -(h * (1.0 - th)) * f_k - (h * th) * f_next
        return v - self.solver.solve_mass(np.asarray(residual, dtype=float))


def moreau_jean(system: LinearSystem, law: ImpactLaw, t_end: float, h: float,
                theta: float = 0.5, *, t0: float = 0.0, backend: str = "auto",
                tol: float = DEFAULT_TOL, record_every: int = 1, keep_events: bool = True,
                progress: Callable[[float], None] | None = None) -> Trajectory:
    """Integrate ``system`` from t0 to t_end by Moreau–Jean time-stepping (docs/theory.md §14).

    Parameters
    ----------
    system : LinearSystem
    law : ImpactLaw
        Any impact law; Moreau, Newton and Frémond act in the step form
        ``0 ≤ Λ ⟂ γ_{k+1} + Eγ_k ≥ 0``, other laws map u⁻ = v_free to u⁺ = v_{k+1}.
    t_end, h, theta : float
        Final time, step and θ ∈ [0, 1] (validated by :func:`~.simulate.simulate`).
    t0 : float
        Initial time.
    backend, tol : str, float
        Passed to :func:`impactqp.solve` for every impact problem.
    record_every : int
        Keep every k-th step in the trajectory (the last step always).
    keep_events : bool
        Keep every solved impact problem as an :class:`~.impacts.ImpactEvent`.
    progress : callable, optional
        Called with the current time now and then (a progress bar).

    Returns
    -------
    Trajectory
    """
    free = _FreeVelocity(system, h, theta)
    cache = ClusterCache(free.metric, system.H, system.chain)
    solver = ImpactSolver(cache, law, backend=backend, tol=tol)
    steps = step_count(t0, t_end, h)
    kept = np.unique(np.append(np.arange(0, steps + 1, record_every), steps))
    n, m = system.n_dof, system.n_contacts
    T, Q, V = t0 + kept * h, np.empty((kept.size, n)), np.empty((kept.size, n))
    L = np.zeros((kept.size, m))
    q, v = system.q0.copy(), system.v0.copy()
    Q[0], V[0] = q, v
    row, events = 1, []
    report = max(1, steps // 200)
    for k in range(steps):
        t = t0 + k * h
        closed = system.gaps(q) + (0.5 * h) * system.contact_velocities(v) <= 0.0
        v_free = free(t, q, v)
        if closed.any():
            v_next, lam, new = solver.solve(t0 + (k + 1) * h, v_free, closed, v_previous=v)
            if keep_events:
                events.extend(new)
        else:
            v_next, lam = v_free, None
        q = q + h * ((1.0 - theta) * v + theta * v_next)
        v = v_next
        if row < kept.size and kept[row] == k + 1:
            Q[row], V[row] = q, v
            if lam is not None:
                L[row] = lam
            row += 1
        if progress is not None and (k + 1) % report == 0:
            progress(t0 + (k + 1) * h)
    settings = {"h": h, "theta": theta, "t0": t0, "t_end": t_end, "steps": steps,
                "backend": backend, "tol": tol, "record_every": record_every,
                "keep_events": keep_events,
                "activation": "g + h/2 γ <= 0"}
    return Trajectory(system, law, "moreau-jean", T, Q, V, L, events, settings)
