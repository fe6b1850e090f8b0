"""The event buffers of the compiled loops: one layout for every loop, filled by the kernels
and read back (and enlarged) by :class:`impactqp.simulation.compiled_driver.CompiledDriver`.

A record is one head row (step number k + 1, its first entry in ``ints``, its first entry in
``floats`` and two integers of the loop's own) and the integers and floats the loop appends
after it; a record's entries end where the next record's begin (or at ``counts``). Each loop
says how many entries one step may add at most (``worst``); a loop stops with its status
``FULL`` before a step that might not fit, so nothing is ever written out of bounds.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .jit import inline_kernel

HEAD = 5
"""Columns of a record's head: step k + 1, first int, first float, and two of the loop's."""


class Events(NamedTuple):
    """The event buffers of a run.

    Attributes
    ----------
    head : (E, HEAD) int array
    ints : (I,) int array
    floats : (F,) float array
    counts : (3,) int array
        Entries in use of (head, ints, floats), updated by the kernels.
    worst : (3,) int array
        Most entries of (head, ints, floats) one step may add.
    keep : bool
        Record the events (without it the buffers are empty and never written).
    """

    head: np.ndarray
    ints: np.ndarray
    floats: np.ndarray
    counts: np.ndarray
    worst: np.ndarray
    keep: bool


@inline_kernel
def full(events):
    """The next step might not fit in the buffers (never without ``keep``)."""
    if not events.keep:
        return False
    c, w = events.counts, events.worst
    return (c[0] + w[0] > events.head.shape[0] or c[1] + w[1] > events.ints.size
            or c[2] + w[2] > events.floats.size)


@inline_kernel
def mark(events):
    """The buffers' counts now, for :func:`rollback`."""
    return events.counts[0], events.counts[1], events.counts[2]


@inline_kernel
def rollback(events, at):
    """Forget the records made since :func:`mark` returned ``at``."""
    events.counts[0], events.counts[1], events.counts[2] = at


@inline_kernel
def open_record(events, step, a, b):
    """Start a record of step number ``step`` with the loop's integers ``a`` and ``b``."""
    e = events.counts[0]
    events.head[e, 0] = step
    events.head[e, 1] = events.counts[1]
    events.head[e, 2] = events.counts[2]
    events.head[e, 3] = a
    events.head[e, 4] = b
    events.counts[0] = e + 1


@inline_kernel
def put_ints(events, x):
    """Append the integers ``x`` to the open record."""
    start = events.counts[1]
    for i in range(x.size):
        events.ints[start + i] = x[i]
    events.counts[1] = start + x.size


@inline_kernel
def put_floats(events, x):
    """Append the floats ``x`` to the open record."""
    start = events.counts[2]
    for i in range(x.size):
        events.floats[start + i] = x[i]
    events.counts[2] = start + x.size
