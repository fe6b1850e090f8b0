"""The compiled frictional Moreau–Jean loop (docs/theory.md §17, "The compiled loop"): the
arrays of :func:`impactqp.kernels.friction_loop.run`, formed once per run, and the
:class:`~impactqp.simulation.friction_step.FrictionEvent` s built from what the kernel
recorded, on first read; the calls of the kernel (resumed after a step solved by the Python
loop's step, or after enlarging the event buffers) are the shared driver's."""

from __future__ import annotations

from functools import partial
from typing import Any

import numpy as np

from ..kernels.friction_loop import Friction, run, worst_step
from ..kernels.step import Contacts, gather_local
from ..laws.friction import FrictionResult
from ..model.friction import FrictionContactProblem, certify_friction
from .compiled_driver import CompiledDriver, compressed_rows
from .friction_step import FrictionEvent

LOOP_BACKEND = "nsgs"
"""What answered a step solved inside the compiled loop (its events' ``result.backend``): the
registry's projected Gauss–Seidel (the loop runs its compiled sweeps,
:func:`impactqp.kernels.friction.nsgs`), a name :func:`impactqp.simulate` takes back as
``backend=`` (the Python loop then solves each step with it)."""

SWEEPS = 500
"""Most Gauss–Seidel sweeps per step before the step goes to :func:`impactqp.solve_friction`."""

TARGET = 1e-4
"""The sweeps aim at ‖F‖/‖q‖ ≤ TARGET·tol, so that the answers sit well inside the
certificate (and, on well-conditioned steps, at round-off)."""


class CompiledFriction(CompiledDriver):
    """A frictional run through :func:`impactqp.kernels.friction_loop.run`.

    Parameters
    ----------
    step : Step
        The Python loop's step (:class:`impactqp.simulation.time_stepping.Step`) with a
        :class:`~impactqp.simulation.friction_step.FrictionSolver`: its system, free
        velocity, coefficients and tolerance, and the step that solves what the kernel does
        not certify.
    keep : bool
        Keep the events.
    """

    def __init__(self, step: Any, keep: bool) -> None:
        solver = self.solver = step.solver
        system, d, m = step.system, solver.d, step.system.n_contacts
        super().__init__(step, run, keep, worst_step(system.n_dof, m, d))
        _, H, MinvH, G, units = solver.local(np.arange(m))
        self.contacts = Contacts(*compressed_rows(H), system.b, d, np.zeros((0, 0)),
                                 np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64),
                                 MinvH, np.ascontiguousarray(G), units)
        self.force = step.free.kernel_force(step.t0)
        self.friction = Friction(solver.mu, solver.e, TARGET * solver.tol, SWEEPS)

    def kernel_data(self) -> tuple:
        return self.contacts, self.force, self.step.scheme, self.friction

    def _event(self, step: int, a: int, b: int, ints: np.ndarray,
               floats: np.ndarray) -> FrictionEvent:
        """The FrictionEvent of a recorded step (``a`` closed contacts, ``b`` sweeps), with
        the certificate of :func:`impactqp.model.friction.certify_friction` recomputed from
        its (W, q, μ, r)."""
        solver, n, d = self.solver, self.step.system.n_dof, self.solver.d
        closed = ints[:a].copy()
        na = a * d
        cols = (closed[:, None] * d + np.arange(d)).ravel()
        s = self.contacts.units[cols]  # the kernel's problem, in contact units
        W, _ = gather_local(self.contacts.G, self.contacts.units, cols, np.zeros(na),
                            np.empty((na, na)), np.empty(na))
        problem = FrictionContactProblem(W, floats[:na].copy(), solver.mu[closed],
                                         contact_dim=d)
        r = floats[na:2 * na].copy()
        u = problem.velocity(r)
        cert = certify_friction(problem, r, u, tol=solver.tol)
        result = FrictionResult(r, u, cert.error, cert, b, 0.0, LOOP_BACKEND)
        um, up = floats[2 * na:2 * na + n].copy(), floats[2 * na + n:2 * na + 2 * n].copy()
        verdict = partial(solver.membership, closed, um, up, r / s)
        return FrictionEvent(self.step.t0 + step * self.step.h, closed, problem, result, s, um,
                             up, verdict)
