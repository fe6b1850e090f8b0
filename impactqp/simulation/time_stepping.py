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

Four loops run these steps, chosen by :func:`route`. A
:class:`~impactqp.laws.coulomb.Coulomb` law on a system with ``contact_dim`` 2 or 3 takes a
frictional loop (docs/theory.md §17): the compiled one
(:class:`~impactqp.simulation.friction_loop.CompiledFriction`) under the conditions of the
compiled loop below, else the Python loop with
:class:`~impactqp.simulation.friction_step.FrictionStep` as its step; a Coulomb law on a
frictionless system or another law on a frictional system are refused by name. The
compiled loop (:func:`impactqp.kernels.moreau_jean.run`) takes a run when
:func:`compiled_applies` says so: a built-in complementarity law (Moreau, Newton, Frémond,
by exact type), a constant or linear force, ``backend="auto"`` and a system small enough to
be held dense. Every other run — a callable force, any other law (the sector and reflection
laws, LZB, a user's law), a named backend, a large system — takes the Python loop, which
solves each cluster through :func:`impactqp.solve`. A step whose compiled certificate fails
is solved again by the Python loop's step (which raises what it raises), and the compiled
loop resumes after it.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from ..base.checks import DEFAULT_TOL
from ..kernels.moreau_jean import CHECKED, run
from ..kernels.residuals import RESIDUALS
from ..laws.base import ImpactLaw
from ..laws.certificate import Certificate
from ..laws.result import ImpactResult
from ..model.problem import ImpactProblem
from ..model.residuals import restitution_matrix
from ..model.structure import ImpactStructure
from .clusters import ClusterCache
from .compiled_driver import CompiledDriver
from .friction_loop import CompiledFriction
from .friction_step import FrictionEvent, FrictionStep
from .impacts import ImpactEvent, ImpactSolver
from .routing import compiled_applies as compiled_applies  # re-exported: imported from here
from .routing import route
from .step_law import MoreauJeanStep
from .system import LinearSystem
from .trajectory import Trajectory

LOOP_BACKEND = "compiled Moreau–Jean loop"
"""What answered an impact solved inside the compiled loop (its events' ``result.backend``)."""

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

    def residual(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """r with Ŵ(v_free − v) = −r."""
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
        return np.asarray(residual, dtype=float)

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return v - self.solver.solve_mass(self.residual(t, q, v))

    def kernel_arrays(self, t0: float) -> tuple:
        """(L of Ŵ = LLᵀ, K, c, Ŵ⁻¹r, linear): the force as the compiled loops take it, for
        a linear force or (Ŵ⁻¹r formed once) a constant one."""
        n = self.system.n_dof
        if self.K is not None:
            K = self.K.toarray() if sp.issparse(self.K) else self.K
            return (self.solver.cholesky_factor, np.ascontiguousarray(K, dtype=float),
                    self.constant, np.zeros(n), True)
        shift = self.solver.solve_mass(self.residual(t0, self.system.q0, self.system.v0))
        return np.zeros((0, 0)), np.zeros((0, 0)), np.zeros(0), shift, False


def moreau_jean(system: LinearSystem, law: ImpactLaw, t_end: float, h: float,
                theta: float = 0.5, *, t0: float = 0.0, backend: str = "auto",
                tol: float = DEFAULT_TOL, record_every: int = 1, keep_events: bool = True,
                progress: Callable[[float], None] | None = None,
                compiled: bool | None = None) -> Trajectory:
    """Integrate ``system`` from t0 to t_end by Moreau–Jean time-stepping (docs/theory.md §14).

    Parameters
    ----------
    system : LinearSystem
    law : ImpactLaw
        Any impact law; Moreau, Newton and Frémond act in the step form
        ``0 ≤ Λ ⟂ γ_{k+1} + Eγ_k ≥ 0``, other laws map u⁻ = v_free to u⁺ = v_{k+1};
        Coulomb (on a system with ``contact_dim`` 2 or 3) solves the local frictional
        problem of docs/theory.md §17 on the closed contacts.
    t_end, h, theta : float
        Final time, step and θ ∈ [0, 1] (validated by :func:`~.simulate.simulate`).
    t0 : float
        Initial time.
    backend, tol : str, float
        Passed to :func:`impactqp.solve` for every impact problem (to
        :func:`impactqp.solve_friction` with Coulomb's law).
    record_every : int
        Keep every k-th step in the trajectory (the last step always).
    keep_events : bool
        Keep every solved impact problem as an :class:`~.impacts.ImpactEvent`.
    progress : callable, optional
        Called with the current time now and then (a progress bar).
    compiled : bool, optional
        Force the compiled loop (True; only where :func:`compiled_applies`, with Coulomb's
        law where ``routing.friction_compiled_applies``) or the Python loop (False); by
        default those rules decide.

    Returns
    -------
    Trajectory
        ``settings["loop"]`` says which loop ran (``"compiled"``, ``"python"`` or
        ``"friction-compiled"`` or ``"friction"``); ``impulses`` has one column per column
        of H.

    Raises
    ------
    InputError
        A law and system :func:`route` refuses.
    CertificateError
        A step no method certifies (with its time).
    """
    loop = route(system, law, backend, compiled)
    free = _FreeVelocity(system, h, theta)
    steps = step_count(t0, t_end, h)
    kept = np.unique(np.append(np.arange(0, steps + 1, record_every), steps))
    n, m = system.n_dof, system.H.shape[1]
    T, Q, V = t0 + kept * h, np.empty((kept.size, n)), np.empty((kept.size, n))
    L = np.zeros((kept.size, m))
    Q[0], V[0] = system.q0, system.v0
    report = max(1, steps // 200)
    step: _Step | FrictionStep
    if loop.startswith("friction"):
        step = FrictionStep(system, free, law, h, theta, t0, backend=backend, tol=tol)
    else:
        cache = ClusterCache(free.metric, system.H, system.chain)
        step = _Step(system, free, ImpactSolver(cache, law, backend=backend, tol=tol),
                     h, theta, t0)
    events: list[ImpactEvent | FrictionEvent] | Callable[[], list[ImpactEvent]]
    if loop == "compiled":
        events = _CompiledLoop(system, law, free, step, tol, keep_events).run(
            steps, kept, Q, V, L, report, progress)
    elif loop == "friction-compiled":
        events = CompiledFriction(step, keep_events).run(steps, kept, Q, V, L, report,
                                                         progress)
    else:
        events = []
        q, v = system.q0.copy(), system.v0.copy()
        row = 1
        for k in range(steps):
            q, v, lam, new = step(k, q, v)
            if keep_events:
                events.extend(new)
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
                "activation": "g + h/2 γ <= 0", "loop": loop}
    return Trajectory(system, law, "moreau-jean", T, Q, V, L, events, settings)


class _Step:
    """One step of the Python loop: (q_{k+1}, v_{k+1}, Λ or None, events) from (q_k, v_k)."""

    def __init__(self, system: LinearSystem, free: _FreeVelocity, solver: ImpactSolver,
                 h: float, theta: float, t0: float) -> None:
        self.system, self.free, self.solver = system, free, solver
        self.h, self.theta, self.t0 = h, theta, t0

    def __call__(self, k: int, q: np.ndarray, v: np.ndarray,
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, list[ImpactEvent]]:
        h, theta, system = self.h, self.theta, self.system
        closed = system.gaps(q) + (0.5 * h) * system.contact_velocities(v) <= 0.0
        v_free = self.free(self.t0 + k * h, q, v)
        if closed.any():
            v_next, lam, new = self.solver.solve(self.t0 + (k + 1) * h, v_free, closed,
                                                 v_previous=v)
        else:
            v_next, lam, new = v_free, None, []
        return q + h * ((1.0 - theta) * v + theta * v_next), v_next, lam, new


class _CompiledLoop(CompiledDriver):
    """The arrays of :func:`impactqp.kernels.moreau_jean.run`, formed once per run, the calls
    of the kernel (resumed after a step solved by the Python loop or after enlarging the
    event buffers) and the events built from what the kernel recorded."""

    def __init__(self, system: LinearSystem, law: ImpactLaw, free: _FreeVelocity,
                 step: _Step, tol: float, keep: bool) -> None:
        self.system, self.law, self.free, self.step = system, law, free, step
        self.tol, self.keep, self.kernel = tol, keep, run
        self.q0, self.v0 = system.q0, system.v0
        m = system.n_contacts
        Wh = np.ascontiguousarray(free.metric, dtype=float)
        H = np.ascontiguousarray(system.H, dtype=float)
        cache = step.solver.cache
        if cache.diagonal is not None:  # diagonal Ŵ: products without a factorization
            MinvH = H / cache.diagonal[:, None]
            G = sp.csc_matrix(H.T) @ sp.csc_matrix(MinvH)
            G = (0.5 * (G + G.T)).toarray()
        else:
            full = ImpactStructure(Wh, H)
            MinvH, G = full.dense_Minv_W, np.asarray(full.delassus)
        Ht = sp.csr_matrix(H.T)
        Ht.sort_indices()
        self.force = free.kernel_arrays(step.t0)
        pairs = np.argwhere(np.triu(Wh != 0.0, 1))
        E = law.step_restitution(np.arange(m))
        self.geometry = (Ht.indptr.astype(np.int64), Ht.indices.astype(np.int64),
                         Ht.data.astype(float), system.b, Wh)
        self.impacts = (np.ascontiguousarray(MinvH), np.ascontiguousarray(G, dtype=float),
                        np.sqrt(np.diag(G)),
                        restitution_matrix(E, m), np.ndim(E) < 2,
                        np.ascontiguousarray(pairs[:, 0], dtype=np.int64),
                        np.ascontiguousarray(pairs[:, 1], dtype=np.int64))
        self.passive = np.zeros(m, dtype=bool)
        if cache.chain is not None and np.ndim(E) == 0:  # runs of balls: isotonic
            chain = cache.chain
            self.chain = (True, cache.diagonal, 1.0 / cache.diagonal, bool(chain.left_wall),
                          bool(chain.right_wall), float(E))
        else:
            self.chain = (False, np.zeros(0), np.zeros(0), False, False, 0.0)
        self.buffers = self._buffers(*(self._room(0, 0, 0) if keep else (0, 0, 0)))
        self.counts = np.zeros(3, dtype=np.int64)
        self.pieces: list[tuple[int, int] | list[ImpactEvent]] = []

    @staticmethod
    def _buffers(events: int, dofs: int, contacts: int) -> tuple[np.ndarray, ...]:
        """(head, residuals, dofs, contacts, u⁻, u⁺, v_k, Λ) of ``events`` recorded clusters
        on ``dofs`` degrees of freedom and ``contacts`` contacts in all."""
        return (np.empty((events, 4), dtype=np.int64), np.empty((events, CHECKED)),
                np.empty(dofs, dtype=np.int64), np.empty(contacts, dtype=np.int64),
                np.empty(dofs), np.empty(dofs), np.empty(dofs), np.empty(contacts))

    def _room(self, events: int, dofs: int, contacts: int) -> tuple[int, int, int]:
        """Buffer sizes for twice what is used plus one step's worst case (a cluster per
        degree of freedom, every dof and contact in some cluster) and some slack."""
        n, m = self.system.n_dof, self.system.n_contacts
        return 2 * events + n + 64, 2 * dofs + n + 256, 2 * contacts + m + 256

    @staticmethod
    def _used(events: int, dofs: int, contacts: int) -> tuple[int, ...]:
        """Entries in use of (head, residuals, dofs, contacts, u⁻, u⁺, v_k, Λ)."""
        return events, events, dofs, contacts, dofs, dofs, dofs, contacts

    def kernel_data(self) -> tuple:
        return (*self.geometry, *self.force, *self.impacts, self.passive, *self.chain,
                self.tol)

    def _event(self, e: int) -> ImpactEvent:
        """The ImpactEvent of record ``e``: the recorded cluster with its problem, the step
        law on it and the certificate of the residuals the kernel checked."""
        head, res, dofs, contacts, um, up, vp, lam = self.buffers
        step, d0, c0, mc = (int(x) for x in head[e])
        end = head[e + 1, 1] if e + 1 < self.counts[0] else self.counts[1]
        d = slice(d0, int(end))
        c = contacts[c0:c0 + mc].copy()
        closed = np.zeros(self.system.n_contacts, dtype=bool)
        closed[c] = True
        (cl,) = self.step.solver.cache.clusters(closed)  # the Python loop's structures
        problem = ImpactProblem.from_structure(cl.structure, um[d].copy())
        law = MoreauJeanStep(self.law.step_restitution(c), vp[d].copy())
        cert = Certificate(dict(zip(RESIDUALS[:CHECKED], res[e].tolist())), self.tol)
        result = ImpactResult(problem, law.name, law.coefficients_for(problem), up[d].copy(),
                              lam[c0:c0 + mc].copy(), LOOP_BACKEND, cert, form="impulse",
                              impact_law=law, attempts=[f"{LOOP_BACKEND}: certified"])
        return ImpactEvent(self.step.t0 + step * self.step.h, "step", dofs[d].copy(), c,
                           result)
