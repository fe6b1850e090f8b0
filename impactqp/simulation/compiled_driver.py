"""What the two compiled Moreau–Jean loops share (docs/theory.md §14, §17): the calls of the
kernel over a run, resumed after a step the kernel hands back to the Python loop's step (its
certificate failed) or after the event buffers were enlarged, the rows kept for the
trajectory, and the pieces of the event list (kernel records or the Python step's events).

The buffers have the one layout of :mod:`impactqp.kernels.events`: a loop says only how
many entries one step may add (``worst``) and how one record reads back
(:meth:`CompiledDriver._event`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..kernels.events import HEAD, Events
from ..kernels.moreau_jean import DONE, FAILED
from ..kernels.step import Record, end_step

SLACK = 8
"""Steps' worst case of room the event buffers get beyond twice what is in use."""


def compressed_rows(H: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Hᵀ in compressed rows (ptr, idx, val), the indices of each row ascending: the form
    :class:`impactqp.kernels.step.Contacts` holds H in."""
    Ht = sp.csr_matrix(np.asarray(H, dtype=float).T)
    Ht.sort_indices()
    return Ht.indptr.astype(np.int64), Ht.indices.astype(np.int64), Ht.data.astype(float)


class CompiledDriver(ABC):
    """A run through a compiled loop ``kernel(q, v, k, stop, row, *data, record, events)
    -> (status, k, row)``.

    Parameters
    ----------
    step : Step
        The Python loop's step (:class:`impactqp.simulation.time_stepping.Step`): its system,
        scheme and t0, and the step that solves what the kernel does not certify.
    kernel : callable
        The compiled loop.
    keep : bool
        Keep the events.
    worst : (3,) int array
        Most (records, ints, floats) one step adds.

    A subclass defines :meth:`kernel_data` and :meth:`_event`.
    """

    def __init__(self, step: Any, kernel: Callable[..., tuple[int, int, int]], keep: bool,
                 worst: np.ndarray) -> None:
        self.step, self.kernel, self.keep = step, kernel, keep
        self.events = Events(np.empty((0, HEAD), dtype=np.int64), np.empty(0, dtype=np.int64),
                             np.empty(0), np.zeros(3, dtype=np.int64), worst, bool(keep))
        if keep:
            self._grow()
        self.pieces: list[tuple[int, int] | list] = []

    @abstractmethod
    def kernel_data(self) -> tuple:
        """The kernel's arguments between ``row`` and ``record``."""

    @abstractmethod
    def _event(self, step: int, a: int, b: int, ints: np.ndarray, floats: np.ndarray) -> Any:
        """The event of a kernel record: step number k + 1, the loop's two head integers,
        its integers and its floats."""

    def _grow(self) -> None:
        """More room in every event buffer (twice what is used plus :data:`SLACK` steps'
        worst case), keeping what is recorded."""
        old = self.events
        used = [int(x) for x in old.counts]
        size = [2 * u + SLACK * int(w) for u, w in zip(used, old.worst, strict=True)]
        head = np.empty((size[0], HEAD), dtype=np.int64)
        ints, floats = np.empty(size[1], dtype=np.int64), np.empty(size[2])
        head[:used[0]], ints[:used[1]], floats[:used[2]] = \
            old.head[:used[0]], old.ints[:used[1]], old.floats[:used[2]]
        self.events = old._replace(head=head, ints=ints, floats=floats)

    def _record(self, e: int) -> Any:
        """The event of record ``e`` (its entries end where the next record's begin)."""
        ev = self.events
        step, i0, f0, a, b = (int(x) for x in ev.head[e])
        last = e + 1 >= ev.counts[0]
        i1 = int(ev.counts[1] if last else ev.head[e + 1, 1])
        f1 = int(ev.counts[2] if last else ev.head[e + 1, 2])
        return self._event(step, a, b, ev.ints[i0:i1], ev.floats[f0:f1])

    def _events(self) -> list:
        """The run's events, in order: the Python steps' as they are, the kernel's records
        built by :meth:`_event`."""
        out: list = []
        for piece in self.pieces:
            out.extend(piece if isinstance(piece, list) else map(self._record, range(*piece)))
        return out

    def _close(self, first: int) -> None:
        """Mark the kernel's events since ``first`` as the next piece of the list."""
        if self.keep and self.events.counts[0] > first:
            self.pieces.append((first, int(self.events.counts[0])))

    def run(self, steps: int, kept: np.ndarray, Q: np.ndarray, V: np.ndarray, L: np.ndarray,
            report: int, progress: Callable[[float], None] | None,
            ) -> Callable[[], list] | list:
        """Fill Q, V, L (rows ``kept``) over ``steps`` steps; returns the events (a builder
        called on first read) or [] without ``keep``."""
        step, h, t0 = self.step, self.step.h, self.step.t0
        q, v = step.system.q0.copy(), step.system.v0.copy()
        record = Record(kept, Q, V, L)
        data = self.kernel_data()
        k, row, first, reported = 0, 1, 0, 0
        while k < steps:
            stop = steps if progress is None else min(steps, (k // report + 1) * report)
            status, k, row = self.kernel(q, v, k, stop, row, *data, record, self.events)
            if status == FAILED:  # the Python loop's step, whose solve raises what it raises
                self._close(first)
                v_next, lam, new = step(k, q, v)
                row = end_step(q, v, v_next, lam, h, step.theta, k, row, *record)
                if self.keep:
                    self.pieces.append(new)
                first = int(self.events.counts[0])
                k += 1
            elif status != DONE:  # the event buffers are full
                self._grow()
            if progress is not None and k % report == 0 and k > reported:
                progress(t0 + k * h)
                reported = k
        self._close(first)
        return self._events if self.keep else []
