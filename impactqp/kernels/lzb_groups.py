"""The grouped arguments of the LZB stepper :mod:`impactqp.kernels.lzb` (docs/theory.md §13):
DOP853's coefficients, the piece being integrated, its events and a step's scratch, each
unpacked once per call by the kernels that take them. What the kernels take about the impact
itself is :class:`impactqp.kernels.lzb_model.Impact`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.integrate._ivp import dop853_coefficients as _dop853


class Tableau(NamedTuple):
    """DOP853's coefficients (the stage times C are not needed: the rates do not depend on
    the independent variable).

    Attributes
    ----------
    A : (16, 16) float array
        The stages' coefficients (the last three for the dense output).
    B : (12,) float array
        The step's weights.
    E3, E5 : (13,) float arrays
        The 3rd- and 5th-order error estimators.
    D : (4, 16) float array
        The dense output's coefficients.
    """

    A: np.ndarray
    B: np.ndarray
    E3: np.ndarray
    E5: np.ndarray
    D: np.ndarray


class Piece(NamedTuple):
    """The piece being integrated, as its steps and events see it.

    Attributes
    ----------
    k : int
        The primary contact, or −1 against time.
    live, nlive : int array, int
        The contacts ``live[:nlive]`` that are stepped (the others are open).
    comps, nc : int array, int
        Their components ``comps[:nc]`` of x = (z, P, D).
    level : float
        The energy level of the piece (fstate[LEVEL]).
    """

    k: int
    live: np.ndarray
    nlive: int
    comps: np.ndarray
    nc: int
    level: float


class PieceEvents(NamedTuple):
    """The events that end a piece (:func:`impactqp.kernels.lzb_model.piece_events`).

    Attributes
    ----------
    kinds, contacts, directions : int, int, float arrays
        Each event's kind, contact and direction (−1: its value falls through 0, +1: rises).
    n : int
        How many there are.
    """

    kinds: np.ndarray
    contacts: np.ndarray
    directions: np.ndarray
    n: int


class Stages(NamedTuple):
    """Scratch of one DOP853 step of a piece. The step works on the piece's components
    c < nc (contiguous, ``comps[c]`` their places in x = (z, P, D)); the rates read and
    write the full 3m entries.

    Attributes
    ----------
    K : (16, 3m) float array
        The stages' rates on the components, K[q, c] (K[0] the rates at the step's start).
    xs : (3m,) float array
        The full state of the stage being evaluated (the frozen components stay x's).
    gamma : (m,) float array
        The contact velocities of the last evaluation.
    xc : (3m,) float array
        The components of the stage being evaluated.
    rate : (3m,) float array
        The full rates of the last evaluation.
    """

    K: np.ndarray
    xs: np.ndarray
    gamma: np.ndarray
    xc: np.ndarray
    rate: np.ndarray


class PieceWork(NamedTuple):
    """Scratch of one piece (:func:`impactqp.kernels.lzb.integrate_impact` allocates it once
    per impact): the step's :class:`Stages`, then, on the piece's components c < nc,
    the state, the step's end, a trial state and the dense output, and, in full, the states
    the events read.

    Attributes
    ----------
    stages : Stages
    x, x_new, x_try : (3m,) float arrays
        The state at the step's start and end, a state inside the step (components).
    e5, e3 : (3m,) float arrays
        The step's error estimates (components).
    F : (7, 3m) float array
        The step's dense output (components).
    full_new, full_try : (3m,) float arrays
        x_new and x_try in full, for the events.
    g_old, g_new : (3m + 3,) float arrays
        The events' values at the step's start and end.
    comps : (3m,) int array
        The places of the components in x.
    """

    stages: Stages
    x: np.ndarray
    x_new: np.ndarray
    x_try: np.ndarray
    e5: np.ndarray
    e3: np.ndarray
    F: np.ndarray
    full_new: np.ndarray
    full_try: np.ndarray
    g_old: np.ndarray
    g_new: np.ndarray
    comps: np.ndarray


def piece_work(m: int) -> PieceWork:
    """The :class:`PieceWork` of an impact of m contacts."""
    n = 3 * m
    stages = Stages(np.zeros((16, n)), np.empty(n), np.zeros(m), np.empty(n), np.zeros(n))
    return PieceWork(stages, np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n),
                     np.zeros((7, n)), np.empty(n), np.empty(n), np.empty(n + 3),
                     np.empty(n + 3), np.empty(n, dtype=np.int64))


class PieceBuffers(NamedTuple):
    """What the piece-by-piece logic of :func:`impactqp.kernels.lzb.integrate_impact` keeps
    between pieces (:mod:`impactqp.kernels.lzb_model`).

    Attributes
    ----------
    frozen : (m,) bool array
        The open contacts.
    live : (m,) int array
        The others, ``live[:nlive]``.
    gamma : (m,) float array
        The contact velocities at the start of the piece.
    kinds, contacts, directions : (3m + 3,) int, int, float arrays
        The piece's events (:class:`PieceEvents`).
    x : (3m,) float array
        The state x = (z, P, D) of the piece.
    """

    frozen: np.ndarray
    live: np.ndarray
    gamma: np.ndarray
    kinds: np.ndarray
    contacts: np.ndarray
    directions: np.ndarray
    x: np.ndarray


def piece_buffers(m: int) -> PieceBuffers:
    """The :class:`PieceBuffers` of an impact of m contacts."""
    return PieceBuffers(np.zeros(m, dtype=np.bool_), np.empty(m, dtype=np.int64), np.empty(m),
                        np.empty(3 * m + 3, dtype=np.int64),
                        np.empty(3 * m + 3, dtype=np.int64), np.empty(3 * m + 3),
                        np.empty(3 * m))


def dop853_tableau() -> Tableau:
    """DOP853's :class:`Tableau`, as :func:`impactqp.kernels.lzb.integrate_impact` takes it."""
    return Tableau(*(np.ascontiguousarray(a, dtype=float) for a in
                     (_dop853.A, _dop853.B, _dop853.E3, _dop853.E5, _dop853.D)))
