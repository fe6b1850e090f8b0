"""Moreau–Jean time-stepping with any impact law (docs/theory.md §14).

One step from (q_k, v_k) at t_k to t_{k+1} = t₀ + (k+1)h, in the order Siconos' MoreauJeanOSI
uses, as :mod:`impactqp.kernels.step` specifies it for every loop:

1. closed contacts: gᵢ(q_k) + ½h γᵢ(v_k) ≤ 0 (the gap predicted half a step ahead);
2. free velocity: v_free = v_k + Ŵ⁻¹ h((1 − θ)f_k + θf_{k+1} − Kq_k − hθKv_k), with the
   iteration matrix Ŵ = M + h²θ²K of a :class:`~impactqp.simulation.system.LinearForce`
   (Ŵ = M and K = 0 otherwise; a callable force is evaluated at (t_k, q_k, v_k) and at
   (t_{k+1}, q_k + hv_k, v_k));
3. the closed contacts' problem in step form, with q = H_Cᵀv_free + Eγ_k: for the
   frictionless laws each cluster (Ŵ, H_closed, u⁻ = v_free) solved through
   :func:`impactqp.solve` (complementarity laws in the step form
   ``0 ≤ Λ ⟂ γ_{k+1} + Eγ_k``, :class:`~.impacts.ImpactSolver`), for Coulomb's law the
   local frictional problem of the closed set in contact units
   (:class:`~.friction_step.FrictionSolver`), giving v_{k+1};
4. q_{k+1} = q_k + h((1 − θ)v_k + θv_{k+1}).

The Python loop runs :class:`Step` (1., 2., the solver's 3.) and
:func:`impactqp.kernels.step.end_step` (4.) step after step; its two kinds differ only in
the solver the step calls. Two compiled loops run the same steps, chosen by
:func:`route`: a :class:`~impactqp.laws.coulomb.Coulomb` law on a system with
``contact_dim`` 2 or 3 takes the compiled frictional loop
(:class:`~impactqp.simulation.friction_loop.CompiledFriction`, docs/theory.md §17) under the
conditions of the compiled loop below, else the Python loop; a Coulomb law on a
frictionless system or another law on a frictional system are refused by name. The
compiled loop (:func:`impactqp.kernels.moreau_jean.run`) takes a run when
:func:`compiled_applies` says so: a built-in complementarity law (Moreau, Newton, Frémond,
by exact type), a constant or linear force, ``backend="auto"`` and a system small enough to
be held dense. Every other run — a callable force, any other law (the sector and reflection
laws, LZB, a user's law), a named backend, a large system — takes the Python loop. A step
whose compiled certificate fails is solved again by the Python loop's step (which raises
what it raises), and the compiled loop resumes after it.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from ..base.checks import DEFAULT_TOL
from ..kernels.moreau_jean import CHECKED, Chain, Impacts, run, worst_step
from ..kernels.residuals import RESIDUALS
from ..kernels.step import Contacts, Force, Record, Scheme, activation, end_step
from ..kernels.units import contact_units
from ..laws.base import ImpactLaw
from ..laws.certificate import Certificate
from ..laws.result import ImpactResult
from ..model.problem import ImpactProblem
from ..model.residuals import restitution_matrix
from ..model.structure import ImpactStructure
from .clusters import ClusterCache
from .compiled_driver import CompiledDriver, compressed_rows
from .friction_loop import CompiledFriction
from .friction_step import FrictionEvent, FrictionSolver
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

    def kernel_force(self, t0: float) -> Force:
        """The force as the compiled loops take it: a linear force, or a constant one with
        Ŵ⁻¹r formed once."""
        n = self.system.n_dof
        if self.K is not None:
            K = self.K.toarray() if sp.issparse(self.K) else self.K
            return Force(np.ascontiguousarray(self.solver.cholesky_factor),
                         np.ascontiguousarray(K, dtype=float),
                         self.constant, np.zeros(n), True)
        shift = self.solver.solve_mass(self.residual(t0, self.system.q0, self.system.v0))
        return Force(np.zeros((0, 0)), np.zeros((0, 0)), np.zeros(0), shift, False)


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
    solver: ImpactSolver | FrictionSolver
    if loop.startswith("friction"):
        solver = FrictionSolver(system, free, law, backend=backend, tol=tol)
    else:
        cache = ClusterCache(free.metric, system.H, system.chain)
        solver = ImpactSolver(cache, law, backend=backend, tol=tol)
    step = Step(system, free, solver, Scheme(float(h), float(theta), float(tol)), t0)
    events: list[ImpactEvent | FrictionEvent] | Callable[[], list]
    if loop == "compiled":
        events = _CompiledLoop(step, law, keep_events).run(steps, kept, Q, V, L, report,
                                                           progress)
    elif loop == "friction-compiled":
        events = CompiledFriction(step, keep_events).run(steps, kept, Q, V, L, report,
                                                         progress)
    else:
        events = _python_loop(step, steps, Record(kept, Q, V, L), keep_events, report,
                              progress)
    settings = {"h": h, "theta": theta, "t0": t0, "t_end": t_end, "steps": steps,
                "backend": backend, "tol": tol, "record_every": record_every,
                "keep_events": keep_events,
                "activation": "g + h/2 γ <= 0", "loop": loop}
    return Trajectory(system, law, "moreau-jean", T, Q, V, L, events, settings)




def _python_loop(step: Step, steps: int, record: Record, keep: bool, report: int,
                 progress: Callable[[float], None] | None) -> list:
    """The Python loop: ``step`` and :func:`impactqp.kernels.step.end_step` step after step;
    returns the events (none without ``keep``)."""
    events: list = []
    q, v = step.system.q0.copy(), step.system.v0.copy()
    row = 1
    for k in range(steps):
        v_next, lam, new = step(k, q, v)
        row = end_step(q, v, v_next, lam, step.h, step.theta, k, row, *record)
        if keep:
            events.extend(new)
        if progress is not None and (k + 1) % report == 0:
            progress(step.t0 + (k + 1) * step.h)
    return events


class Step:
    """Steps 1–3 of the Python loop (docs/theory.md §14, §17): (v_{k+1}, impulses, events)
    from (q_k, v_k), by the rules of :mod:`impactqp.kernels.step`.

    Parameters
    ----------
    system : LinearSystem
        It hands the step its gaps g(q_k), normal velocities γ_k and (through ``free``)
        v_free.
    free : _FreeVelocity
        v_free of the θ-method, with Ŵ and its factorization.
    solver : ImpactSolver or FrictionSolver
        The closed contacts' problem in step form (q = H_Cᵀv_free + Eγ_k): the frictionless
        laws cluster by cluster through :func:`impactqp.solve`, Coulomb's law as one local
        problem in contact units; the only difference between the two kinds of run.
    scheme : Scheme
        h, θ and the tolerance.
    t0 : float
    """

    def __init__(self, system: LinearSystem, free: _FreeVelocity,
                 solver: ImpactSolver | FrictionSolver, scheme: Scheme, t0: float) -> None:
        self.system, self.free, self.solver = system, free, solver
        self.scheme, self.h, self.theta, self.t0 = scheme, scheme.h, scheme.theta, t0

    def __call__(self, k: int, q: np.ndarray, v: np.ndarray,
                 ) -> tuple[np.ndarray, np.ndarray, list]:
        system, h = self.system, self.h
        gamma = np.ascontiguousarray(system.contact_velocities(v), dtype=float)
        closed = np.empty(gamma.size, dtype=bool)
        count = activation(np.ascontiguousarray(system.gaps(q), dtype=float), gamma, h, closed)
        v_free = self.free(self.t0 + k * h, q, v)
        if count == 0:
            return v_free, np.zeros(system.H.shape[1]), []
        return self.solver.solve(self.t0 + (k + 1) * h, v_free, closed, v_previous=v,
                                 gamma_previous=gamma)


class _CompiledLoop(CompiledDriver):
    """The arrays of :func:`impactqp.kernels.moreau_jean.run`, formed once per run, and the
    events built from what the kernel recorded; the calls of the kernel are the driver's."""

    def __init__(self, step: Step, law: ImpactLaw, keep: bool) -> None:
        system, free = step.system, step.free
        n, m = system.n_dof, system.n_contacts
        super().__init__(step, run, keep, worst_step(n, m))
        self.law = law
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
        G = np.ascontiguousarray(G, dtype=float)
        pairs = np.argwhere(np.triu(Wh != 0.0, 1))
        self.contacts = Contacts(*compressed_rows(H), system.b, 1, Wh,
                                 np.ascontiguousarray(pairs[:, 0], dtype=np.int64),
                                 np.ascontiguousarray(pairs[:, 1], dtype=np.int64),
                                 np.ascontiguousarray(MinvH), G,
                                 contact_units(np.diag(G).copy(), 1))
        self.force = free.kernel_force(step.t0)
        E = law.step_restitution(np.arange(m))
        if np.ndim(E) < 2:
            e, matrix = np.array(np.broadcast_to(E, (m,)), dtype=float), np.zeros((0, 0))
        else:
            e, matrix = np.zeros(0), np.ascontiguousarray(restitution_matrix(E, m))
        self.impacts = Impacts(e, matrix, np.zeros(m, dtype=bool))
        if cache.chain is not None and np.ndim(E) == 0:  # runs of balls: isotonic
            chain = cache.chain
            # masses a fresh writable copy in both branches (one compiled loop), as an
            # impact's chain holds them: the loop's projection compiles once with it
            self.chain = Chain(True, np.array(cache.diagonal, dtype=float), 1.0 / cache.diagonal,
                               bool(chain.left_wall), bool(chain.right_wall), float(E))
        else:
            self.chain = Chain(False, np.zeros(0), np.zeros(0), False, False, 0.0)

    def kernel_data(self) -> tuple:
        return self.contacts, self.force, self.step.scheme, self.impacts, self.chain

    def _event(self, step: int, a: int, b: int, ints: np.ndarray,
               floats: np.ndarray) -> ImpactEvent:
        """The ImpactEvent of a recorded cluster (``a`` contacts, ``b`` dofs): its problem,
        the step law on it and the certificate of the residuals the kernel checked."""
        mc, nc = a, b
        dofs, c = ints[:nc].copy(), ints[nc:nc + mc].copy()
        res = floats[:CHECKED]
        um, up, vp = (floats[CHECKED + i * nc:CHECKED + (i + 1) * nc].copy() for i in range(3))
        lam = floats[CHECKED + 3 * nc:CHECKED + 3 * nc + mc].copy()
        closed = np.zeros(self.step.system.n_contacts, dtype=bool)
        closed[c] = True
        (cl,) = self.step.solver.cache.clusters(closed)  # the Python loop's structures
        problem = ImpactProblem.from_structure(cl.structure, um)
        law = MoreauJeanStep(self.law.step_restitution(c), vp)
        cert = Certificate(dict(zip(RESIDUALS[:CHECKED], res.tolist())), self.step.scheme.tol)
        result = ImpactResult(problem, law.name, law.coefficients_for(problem), up, lam,
                              LOOP_BACKEND, cert, form="impulse", impact_law=law,
                              attempts=[f"{LOOP_BACKEND}: certified"])
        return ImpactEvent(self.step.t0 + step * self.step.h, "step", dofs, c, result)
