"""What the two compiled Moreau–Jean loops share (docs/theory.md §14, §17): the calls of the
kernel over a run, resumed after a step the kernel hands back to the Python loop's step (its
certificate failed) or after the event buffers were enlarged, the rows kept for the
trajectory, and the pieces of the event list (kernel records or the Python step's events)."""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import Any

import numpy as np

from ..kernels.moreau_jean import DONE, FAILED


class CompiledDriver(ABC):
    """A run through a compiled loop ``kernel(q, v, k, stop, row, h, θ, *data, kept, Q, V, L,
    keep, *buffers, counts) -> (status, k, row)``.

    A subclass sets ``kernel``, ``step`` (the Python loop's step: ``h``, ``theta``, ``t0`` and
    ``step(k, q, v) -> (q, v, Λ, events)``), ``q0``, ``v0``, ``keep``, ``buffers``, ``counts``
    and ``pieces`` (empty), and defines :meth:`kernel_data`, :meth:`_room`, :meth:`_used`
    and :meth:`_event`.
    """

    kernel: Callable[..., tuple[int, int, int]]
    step: Any
    q0: np.ndarray
    v0: np.ndarray
    keep: bool
    buffers: tuple[np.ndarray, ...]
    counts: np.ndarray
    pieces: list

    @abstractmethod
    def kernel_data(self) -> tuple:
        """The kernel's arguments between θ and ``kept``."""

    @abstractmethod
    def _buffers(self, *sizes: int) -> tuple[np.ndarray, ...]:
        """Empty event buffers of the given sizes."""

    @abstractmethod
    def _room(self, *counts: int) -> tuple[int, ...]:
        """Buffer sizes for the recorded ``counts`` and what the next steps may add."""

    @abstractmethod
    def _used(self, *counts: int) -> tuple[int, ...]:
        """The entries of each buffer in use for the recorded ``counts``."""

    @abstractmethod
    def _event(self, e: int) -> Any:
        """The event of the kernel's record ``e``."""

    def _grow(self) -> None:
        """More room in every event buffer (:meth:`_room`), keeping what is recorded."""
        counts = [int(x) for x in self.counts]
        new = self._buffers(*self._room(*counts))
        for old, fresh, used in zip(self.buffers, new, self._used(*counts), strict=True):
            fresh[:used] = old[:used]
        self.buffers = new

    def _events(self) -> list:
        """The run's events, in order: the Python steps' as they are, the kernel's records
        built by :meth:`_event`."""
        out: list = []
        for piece in self.pieces:
            out.extend(piece if isinstance(piece, list) else map(self._event, range(*piece)))
        return out

    def _close(self, first: int) -> None:
        """Mark the kernel's events since ``first`` as the next piece of the list."""
        if self.keep and self.counts[0] > first:
            self.pieces.append((first, int(self.counts[0])))

    def run(self, steps: int, kept: np.ndarray, Q: np.ndarray, V: np.ndarray, L: np.ndarray,
            report: int, progress: Callable[[float], None] | None,
            ) -> Callable[[], list] | list:
        """Fill Q, V, L (rows ``kept``) over ``steps`` steps; returns the events (a builder
        called on first read) or [] without ``keep``."""
        step, h, t0 = self.step, self.step.h, self.step.t0
        q, v = self.q0.copy(), self.v0.copy()
        data = self.kernel_data()
        k, row, first, reported = 0, 1, 0, 0
        while k < steps:
            stop = steps if progress is None else min(steps, (k // report + 1) * report)
            status, k, row = self.kernel(q, v, k, stop, row, h, step.theta, *data, kept,
                                         Q, V, L, self.keep, *self.buffers, self.counts)
            if status == FAILED:  # the Python loop's step, whose solve raises what it raises
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
