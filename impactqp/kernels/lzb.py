"""The LZB integration of one multiple impact in one compiled call (docs/theory.md §13).

:func:`integrate_impact` runs the piece-by-piece logic of :mod:`impactqp.kernels.lzb_model`
with its own stepper: DOP853 (Dormand–Prince 8(5,3), Hairer's coefficients as scipy ships
them, and scipy's step-size control) with error control at rtol = atol in the dimensionless
variables, or fixed steps of the primary impulse without error control; each step's sign
changes of the piece's events are located on the 7th-order dense output by Illinois' regula
falsi, and the piece ends at the earliest. Only the live contacts of a piece are stepped.
"""

from __future__ import annotations

import numpy as np

from .jit import inline_kernel, kernel
from .lzb_groups import Piece, PieceEvents, Stages
from .lzb_model import (
    DONE,
    ERROR,
    EVALUATIONS,
    FIRST_STEP,
    FIXED_STEP,
    IN_TIME,
    LEVEL,
    OUT_OF_PIECES,
    OUT_OF_STEPS,
    PIECE_SPAN,
    PIECES,
    PLASTIC_STOP,
    STEP_TOO_SMALL,
    STEPS,
    TURN,
    begin_piece,
    end_piece,
    event_value,
    piece_events,
    piece_state,
    rates,
)

EPS = float(np.finfo(float).eps)
KINK_ITERATIONS = 4
"""Secant steps that place the end of a piece on a kink of the rates."""


@inline_kernel
def _combine(K, coefficients, rows, comps, nc, out):
    """out = Σ_{q<rows} coefficients[q] K[q] on the components ``comps[:nc]`` (row by row,
    skipping the tableau's zeros)."""
    for c in range(nc):
        out[comps[c]] = 0.0
    for q in range(rows):
        a = coefficients[q]
        if a != 0.0:
            for c in range(nc):
                i = comps[c]
                out[i] += a * K[q, i]


@inline_kernel
def _stage(K, A, s, x, h, comps, nc, xs):
    """xs = x + h Σ_{q<s} A[s, q] K[q] on the components ``comps[:nc]``."""
    _combine(K, A[s], s, comps, nc, xs)
    for c in range(nc):
        i = comps[c]
        xs[i] = x[i] + h * xs[i]


@inline_kernel
def _interpolate(F, x_old, theta, comps, nc, out):
    """DOP853's dense output at θ ∈ [0, 1] of the step (scipy's Dop853DenseOutput)."""
    rows = F.shape[0]
    for c in range(nc):
        i = comps[c]
        v = 0.0
        for r in range(rows - 1, -1, -1):
            v += F[r, i]
            v *= theta if (rows - 1 - r) % 2 == 0 else 1.0 - theta
        out[i] = v + x_old[i]


@kernel
def _root(kind, j, ga, gb, F, x_old, piece, impact, xt):
    """θ ∈ [0, 1] where the event's value on the dense output crosses zero (Illinois' regula
    falsi until the bracket is 4 ulp wide), on the far side of the crossing."""
    k, live, nlive, comps, nc, level = piece
    indptr, indices, data, gamma0, law = impact
    if ga == 0.0:
        return 0.0
    if gb == 0.0:
        return 1.0
    a, b = 0.0, 1.0
    side = 0
    for _ in range(200):
        c = (a * gb - b * ga) / (gb - ga)
        if not a < c < b:
            c = 0.5 * (a + b)
        _interpolate(F, x_old, c, comps, nc, xt)
        gc = event_value(kind, j, k, xt, level, live, nlive, law, indptr, indices, data,
                         gamma0)
        if gc == 0.0:
            return c
        if (gc > 0.0) == (ga > 0.0):
            a, ga = c, gc
            if side == 1:
                gb *= 0.5
            side = 1
        else:
            b, gb = c, gc
            if side == -1:
                ga *= 0.5
            side = -1
        if b - a <= 4.0 * EPS:
            break
    return b


@kernel
def _rk_step(x, h, piece, impact, tableau, stages, out):
    """One DOP853 step of length h from x (K[0] = its rates) into ``out``, stages into K."""
    k, live, nlive, comps, nc = piece.k, piece.live, piece.nlive, piece.comps, piece.nc
    indptr, indices, data, gamma0, law = impact
    A, B = tableau.A, tableau.B
    K, xs, gamma = stages
    for s in range(1, 12):
        _stage(K, A, s, x, h, comps, nc, xs)
        rates(xs, k, live, nlive, indptr, indices, data, gamma0, law, gamma, K[s])
    _combine(K, B, 12, comps, nc, out)
    for c in range(nc):
        i = comps[c]
        out[i] = x[i] + h * out[i]


@kernel
def _step_to_kink(x, tau, kind, j, g0, piece, impact, tableau, stages, out, istate):
    """The state where a kink of the rates (a turn, a plastic stop) lies, into ``out``: the
    dense output of the step that crossed it is polluted by the stages past it, so the
    kink is reached by real steps from x, whose stages see only the rates before it; their
    length τ (first guess from the dense output) is refined by the secant method on the
    event's value (docs/theory.md §13)."""
    k, live, nlive, level = piece.k, piece.live, piece.nlive, piece.level
    indptr, indices, data, gamma0, law = impact
    t0, ga = 0.0, g0
    for _ in range(KINK_ITERATIONS):
        _rk_step(x, tau, piece, impact, tableau, stages, out)
        istate[EVALUATIONS] += 11
        g = event_value(kind, j, k, out, level, live, nlive, law, indptr, indices, data,
                        gamma0)
        if g == 0.0 or g == ga:
            return
        t0, ga, tau, last = tau, g, tau - g * (tau - t0) / (g - ga), tau
        if abs(tau - last) <= 4.0 * EPS * abs(last):
            return


@kernel
def _piece(x, k, live, nlive, events, rtol, fixed, max_steps, impact, tableau, istate, fstate,
           work):
    """Integrate one piece from x until its first event (against time when k < 0), x
    replaced by the state there. Returns (status, index of the event or −1 at the end of
    the span). DOP853 with scipy's step-size control at rtol = atol, or, with ``fixed``
    > 0, steps of that length without error control; every step's error estimate (scipy's
    RMS over all 3m components, relative to 1 + |x|) is added to fstate[ERROR]."""
    indptr, indices, data, gamma0, law = impact
    A, E3, E5, Dd = tableau.A, tableau.E3, tableau.E5, tableau.D
    kinds, contacts, directions, ne = events
    m = gamma0.size
    n = 3 * m
    K, xs, x_new, gamma, g_old, g_new, F, xt, comps, e5, e3 = work
    stages = Stages(K, xs, gamma)
    nc = 3 * nlive
    for a in range(nlive):
        for r in range(3):
            comps[3 * a + r] = r * m + live[a]
    K[:, :] = 0.0  # the frozen components' rates stay zero
    xs[:] = x
    x_new[:] = x
    xt[:] = x
    safety, min_factor, max_factor, exponent = 0.9, 0.2, 10.0, -1.0 / 8.0
    t = 0.0
    h_abs = fixed if fixed > 0.0 else FIRST_STEP * PIECE_SPAN
    rates(x, k, live, nlive, indptr, indices, data, gamma0, law, gamma, K[0])
    istate[EVALUATIONS] += 1
    level = fstate[LEVEL]
    piece = Piece(k, live, nlive, comps, nc, level)
    for e in range(ne):
        g_old[e] = event_value(kinds[e], contacts[e], k, x, level, live, nlive, law, indptr,
                               indices, data, gamma0)
    while True:
        if istate[STEPS] >= max_steps:
            return OUT_OF_STEPS, -1
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        h_abs = max(h_abs, min_step) if fixed <= 0.0 else fixed
        rejected = False
        while True:
            if h_abs < min_step:
                return STEP_TOO_SMALL, -1
            t_new = min(t + h_abs, PIECE_SPAN)
            h = t_new - t
            _rk_step(x, h, piece, impact, tableau, stages, x_new)
            rates(x_new, k, live, nlive, indptr, indices, data, gamma0, law, gamma, K[12])
            istate[EVALUATIONS] += 12
            _combine(K, E5, 13, comps, nc, e5)
            _combine(K, E3, 13, comps, nc, e3)
            err5, err3 = 0.0, 0.0
            for c in range(nc):
                i = comps[c]
                scale = 1.0 + max(abs(x[i]), abs(x_new[i]))
                err5 += (e5[i] / scale) ** 2
                err3 += (e3[i] / scale) ** 2
            unit = 0.0 if err5 == 0.0 and err3 == 0.0 else \
                h * err5 / np.sqrt((err5 + 0.01 * err3) * n)
            if fixed > 0.0:
                break
            norm = unit / rtol  # scipy's error norm, scale rtol·(1 + |x|)
            if norm < 1.0:
                factor = max_factor if norm == 0.0 else \
                    min(max_factor, safety * norm ** exponent)
                h_abs = h * (min(1.0, factor) if rejected else factor)
                break
            h_abs = h * max(min_factor, safety * norm ** exponent)
            rejected = True
        istate[STEPS] += 1
        fstate[ERROR] += unit
        first, first_theta, dense = -1, 2.0, False
        for e in range(ne):  # sign changes over the step, in the event's direction
            g_new[e] = event_value(kinds[e], contacts[e], k, x_new, level, live, nlive, law,
                                   indptr, indices, data, gamma0)
            up = g_old[e] <= 0.0 <= g_new[e]
            down = g_old[e] >= 0.0 >= g_new[e]
            if not ((up and directions[e] > 0.0) or (down and directions[e] < 0.0)):
                continue
            if not dense:  # the dense output of the step: three more stages
                for s in range(13, 16):
                    _stage(K, A, s, x, h, comps, nc, xs)
                    rates(xs, k, live, nlive, indptr, indices, data, gamma0, law, gamma, K[s])
                istate[EVALUATIONS] += 3
                for r in range(4):
                    _combine(K, Dd[r], 16, comps, nc, F[3 + r])
                for c in range(nc):
                    i = comps[c]
                    delta = x_new[i] - x[i]
                    F[0, i] = delta
                    F[1, i] = h * K[0, i] - delta
                    F[2, i] = 2.0 * delta - h * (K[12, i] + K[0, i])
                    for r in range(3, 7):
                        F[r, i] *= h
                dense = True
            theta = _root(kinds[e], contacts[e], g_old[e], g_new[e], F, x, piece, impact, xt)
            if theta < first_theta:
                first, first_theta = e, theta
        if first >= 0:
            if kinds[first] == TURN or kinds[first] == PLASTIC_STOP:
                _step_to_kink(x, h * first_theta, kinds[first], contacts[first], g_old[first],
                              piece, impact, tableau, stages, xt, istate)
            else:
                _interpolate(F, x, first_theta, comps, nc, xt)
            for c in range(nc):
                x[comps[c]] = xt[comps[c]]
            return DONE, first
        for c in range(nc):
            i = comps[c]
            x[i] = x_new[i]
            K[0, i] = K[12, i]
        for e in range(ne):
            g_old[e] = g_new[e]
        t = t_new
        if t >= PIECE_SPAN:
            return DONE, -1


@kernel
def integrate_impact(impact, tableau, rtol, max_steps, max_pieces, y, P, D, left, istate,
                     fstate, primaries):
    """Integrate one multiple ``impact`` (:class:`~impactqp.kernels.lzb_model.Impact`) with
    DOP853's ``tableau`` (:class:`~impactqp.kernels.lzb_groups.Tableau`) piece by piece
    until every contact is open (docs/theory.md §13): y, P, D and ``left`` (energy still
    stored when a contact opened) updated in place, the primary contact of each piece into
    ``primaries`` (max_pieces + 1 entries), counters into ``istate``/``fstate``
    (:func:`impactqp.kernels.lzb_model.new_state`). fstate[FIXED_STEP] > 0 takes fixed
    steps of that (dimensionless) length in the primary impulse, the pieces against time
    staying adaptive. Returns DONE, OUT_OF_STEPS (``max_steps`` accepted steps spent),
    OUT_OF_PIECES or STEP_TOO_SMALL."""
    indptr, indices, data, gamma0, law = impact
    m = gamma0.size
    n = 3 * m
    work = (np.zeros((16, n)), np.empty(n), np.empty(n), np.zeros(m), np.empty(3 * m + 3),
            np.empty(3 * m + 3), np.zeros((7, n)), np.empty(n), np.empty(n, dtype=np.int64),
            np.empty(n), np.empty(n))
    frozen = np.zeros(m, dtype=np.bool_)
    live = np.empty(m, dtype=np.int64)
    gamma = np.empty(m)
    kinds = np.empty(3 * m + 3, dtype=np.int64)
    contacts = np.empty(3 * m + 3, dtype=np.int64)
    directions = np.empty(3 * m + 3)
    x = np.empty(n)
    while True:
        primary = begin_piece(y, P, D, frozen, gamma, istate, fstate, law, indptr, indices,
                              data, gamma0)
        if primary < 0:
            return DONE
        if istate[PIECES] > max_pieces:
            return OUT_OF_PIECES
        primaries[istate[PIECES] - 1] = primary
        k = -1 if istate[IN_TIME] != 0 else primary
        ne, nlive = piece_events(k, frozen, gamma, law, indptr, indices, kinds, contacts,
                                 directions, live)
        piece_state(y, P, D, k, law, x)
        before = P[primary]
        fixed = fstate[FIXED_STEP] if k >= 0 else 0.0
        status, fired = _piece(x, k, live, nlive, PieceEvents(kinds, contacts, directions, ne),
                               rtol, fixed, max_steps, impact, tableau, istate, fstate, work)
        if status != DONE:
            return status
        kind = kinds[fired] if fired >= 0 else -1
        j = contacts[fired] if fired >= 0 else -1
        end_piece(kind, j, k, primary, before, x, y, P, D, left, istate, fstate, law)
