"""The compiled frictional Moreau–Jean loop (docs/theory.md §17, "The compiled loop"): the
arrays of :func:`impactqp.kernels.friction_loop.run`, formed once per run, the calls of the
kernel (resumed after a step solved by the Python loop's
:class:`~impactqp.simulation.friction_step.FrictionStep`, or after enlarging the event
buffers) and the :class:`~impactqp.simulation.friction_step.FrictionEvent` s built from what
the kernel recorded, on first read."""

from __future__ import annotations

from collections.abc import Callable
from functools import partial

import numpy as np

from ..kernels.friction_loop import HEAD, run
from ..kernels.moreau_jean import DONE, FAILED
from ..laws.friction import FrictionResult
from ..model.friction import FrictionContactProblem, certify_friction
from .friction_step import FrictionEvent, FrictionStep

LOOP_BACKEND = "compiled frictional loop"
"""What answered a step solved inside the compiled loop (its events' ``result.backend``)."""

SWEEPS = 500
"""Most Gauss–Seidel sweeps per step before the step goes to :func:`impactqp.solve_friction`."""

TARGET = 1e-4
"""The sweeps aim at ‖F‖/‖q‖ ≤ TARGET·tol, so that the answers sit well inside the
certificate (and, on well-conditioned steps, at round-off)."""


class CompiledFriction:
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
        self.step, self.keep = step, keep
        system, free = step.system, step.free
        d, m = step.d, system.n_contacts
        _, H, MinvH, G = step.local(np.arange(m))
        self.geometry = (np.ascontiguousarray(H[:, ::d].T), system.b, np.ascontiguousarray(H.T))
        self.force = free.kernel_arrays(step.t0)
        self.products = (MinvH, np.ascontiguousarray(G))
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

    def _grow(self) -> None:
        """More room in every event buffer, keeping what is recorded."""
        e, c, r, u = (int(x) for x in self.counts)
        new = self._buffers(*self._room(e, c, r, u))
        for old, fresh, used in zip(self.buffers, new, (e, c, r, r, u, u)):
            fresh[:used] = old[:used]
        self.buffers = new

    def run(self, steps: int, kept: np.ndarray, Q: np.ndarray, V: np.ndarray, L: np.ndarray,
            report: int, progress: Callable[[float], None] | None,
            ) -> Callable[[], list[FrictionEvent]] | list[FrictionEvent]:
        """Fill Q, V, L (rows ``kept``) over ``steps`` steps; returns the events (a builder
        called on first read) or [] without ``keep``."""
        step, h, t0 = self.step, self.step.h, self.step.t0
        q, v = step.system.q0.copy(), step.system.v0.copy()
        k, row, first, reported = 0, 1, 0, 0
        while k < steps:
            stop = steps if progress is None else min(steps, (k // report + 1) * report)
            status, k, row = run(q, v, k, stop, row, h, step.theta, *self.geometry,
                                 *self.force, *self.products, *self.coefficients, kept,
                                 Q, V, L, self.keep, *self.buffers, self.counts)
            if status == FAILED:  # the Python step: solve_friction, which raises if it must
                self._close(first)
                q_next, v_next, lam, new = step(k, q, v)
                q[:], v[:] = q_next, v_next
                if self.keep:
                    self.pieces.append(new)
                first = int(self.counts[0])
                k += 1
                if row < kept.size and kept[row] == k:
                    Q[row], V[row] = q, v
                    L[row] = 0.0 if lam is None else lam
                    row += 1
            elif status != DONE:  # the event buffers are full
                self._grow()
            if progress is not None and k % report == 0 and k > reported:
                progress(t0 + k * h)
                reported = k
        self._close(first)
        return self._events if self.keep else []

    def _close(self, first: int) -> None:
        """Mark the kernel's events since ``first`` as the next piece of the list."""
        if self.keep and self.counts[0] > first:
            self.pieces.append((first, int(self.counts[0])))

    def _events(self) -> list[FrictionEvent]:
        """The FrictionEvents of the run, in order, each with the certificate of
        :func:`impactqp.model.friction.certify_friction` recomputed from its (W, q, μ, r)."""
        head, contacts, qs, rs, ums, ups = self.buffers
        step, n, d = self.step, self.step.system.n_dof, self.step.d
        out: list[FrictionEvent] = []
        for piece in self.pieces:
            if isinstance(piece, list):
                out.extend(piece)
                continue
            for e in range(*piece):
                k1, c0, a, r0, u0, sweeps = (int(x) for x in head[e])
                closed = contacts[c0:c0 + a].copy()
                cols = (closed[:, None] * d + np.arange(d)).ravel()
                W = self.products[1][np.ix_(cols, cols)]  # what the kernel gathered
                problem = FrictionContactProblem(W, qs[r0:r0 + a * d].copy(), step.mu[closed],
                                                 contact_dim=d)
                r = rs[r0:r0 + a * d].copy()
                u = problem.velocity(r)
                cert = certify_friction(problem, r, u, tol=step.tol)
                result = FrictionResult(r, u, cert.error, cert, sweeps, 0.0, LOOP_BACKEND)
                um, up = ums[u0:u0 + n].copy(), ups[u0:u0 + n].copy()
                verdict = partial(step.membership, closed, um, up, r)
                out.append(FrictionEvent(step.t0 + k1 * step.h, closed, problem, result, um,
                                         up, verdict))
        return out
