"""The compiled frictional Moreau–Jean loop (docs/theory.md §17, "The compiled loop"): the
arrays of :func:`impactqp.kernels.friction_loop.run`, formed once per run, the calls of the
kernel (resumed after a step solved by the Python loop's
:class:`~impactqp.simulation.friction_step.FrictionStep`, or after enlarging the event
buffers) and the :class:`~impactqp.simulation.friction_step.FrictionEvent` s built from what
the kernel recorded, on first read."""

from __future__ import annotations

from functools import partial

import numpy as np

from ..kernels.friction_loop import HEAD, run
from ..laws.friction import FrictionResult
from ..model.friction import FrictionContactProblem, certify_friction
from .compiled_driver import CompiledDriver
from .friction_step import FrictionEvent, FrictionStep

LOOP_BACKEND = "compiled frictional loop"
"""What answered a step solved inside the compiled loop (its events' ``result.backend``)."""

SWEEPS = 500
"""Most Gauss–Seidel sweeps per step before the step goes to :func:`impactqp.solve_friction`."""

TARGET = 1e-4
"""The sweeps aim at ‖F‖/‖q‖ ≤ TARGET·tol, so that the answers sit well inside the
certificate (and, on well-conditioned steps, at round-off)."""


class CompiledFriction(CompiledDriver):
    """A frictional run through :func:`impactqp.kernels.friction_loop.run`.

    Parameters
    ----------
    step : FrictionStep
        The Python loop's step: its system, free velocity, coefficients and tolerance, and
        the step that solves what the kernel does not certify.
    keep : bool
        Keep the events.
    """

    def __init__(self, step: FrictionStep, keep: bool) -> None:
        self.step, self.keep, self.kernel = step, keep, run
        system, free = step.system, step.free
        self.q0, self.v0 = system.q0, system.v0
        d, m = step.d, system.n_contacts
        _, H, MinvH, G, units = step.local(np.arange(m))
        self.units = units
        self.geometry = (np.ascontiguousarray(H[:, ::d].T), system.b, np.ascontiguousarray(H.T))
        self.force = free.kernel_arrays(step.t0)
        self.products = (MinvH, np.ascontiguousarray(G), units)
        self.coefficients = (step.mu, step.e, d, step.tol, TARGET * step.tol, SWEEPS)
        self.buffers = self._buffers(*(self._room(0, 0, 0, 0) if keep else (0, 0, 0, 0)))
        self.counts = np.zeros(4, dtype=np.int64)
        self.pieces: list[tuple[int, int] | list[FrictionEvent]] = []

    @staticmethod
    def _buffers(events: int, contacts: int, entries: int, dofs: int) -> tuple[np.ndarray, ...]:
        """(head, contacts, q, r, u⁻, u⁺) for ``events`` recorded steps."""
        return (np.empty((events, HEAD), dtype=np.int64), np.empty(contacts, dtype=np.int64),
                np.empty(entries), np.empty(entries), np.empty(dofs), np.empty(dofs))

    def _room(self, events: int, contacts: int, entries: int,
              dofs: int) -> tuple[int, int, int, int]:
        """Twice what is used plus 64 steps' worst case."""
        n, m, d = self.step.system.n_dof, self.step.system.n_contacts, self.step.d
        return (2 * events + 64, 2 * contacts + 64 * m, 2 * entries + 64 * m * d,
                2 * dofs + 64 * n)

    @staticmethod
    def _used(events: int, contacts: int, entries: int, dofs: int) -> tuple[int, ...]:
        """Entries in use of (head, contacts, q, r, u⁻, u⁺)."""
        return events, contacts, entries, entries, dofs, dofs

    def kernel_data(self) -> tuple:
        return (*self.geometry, *self.force, *self.products, *self.coefficients)

    def _event(self, e: int) -> FrictionEvent:
        """The FrictionEvent of record ``e``, with the certificate of
        :func:`impactqp.model.friction.certify_friction` recomputed from its (W, q, μ, r)."""
        head, contacts, qs, rs, ums, ups = self.buffers
        step, n, d = self.step, self.step.system.n_dof, self.step.d
        k1, c0, a, r0, u0, sweeps = (int(x) for x in head[e])
        closed = contacts[c0:c0 + a].copy()
        cols = (closed[:, None] * d + np.arange(d)).ravel()
        s = self.units[cols]  # the kernel's problem, in contact units
        W = self.products[1][np.ix_(cols, cols)] / np.outer(s, s)
        problem = FrictionContactProblem(W, qs[r0:r0 + a * d].copy(), step.mu[closed],
                                         contact_dim=d)
        r = rs[r0:r0 + a * d].copy()
        u = problem.velocity(r)
        cert = certify_friction(problem, r, u, tol=step.tol)
        result = FrictionResult(r, u, cert.error, cert, sweeps, 0.0, LOOP_BACKEND)
        um, up = ums[u0:u0 + n].copy(), ups[u0:u0 + n].copy()
        verdict = partial(step.membership, closed, um, up, r / s)
        return FrictionEvent(step.t0 + k1 * step.h, closed, problem, result, s, um, up,
                             verdict)
