"""The LZB integration of one multiple impact in one compiled call (docs/theory.md §13).

:func:`integrate_impact` runs the piece-by-piece logic of :mod:`impactqp.kernels.lzb_model`
with its own stepper (:mod:`impactqp.kernels.lzb_dop853`): DOP853 (Dormand–Prince 8(5,3),
Hairer's coefficients as scipy ships them) with error control at rtol = atol in the
dimensionless variables, or fixed steps of the primary impulse without error control; each
step's sign changes of the piece's events are located on the 7th-order dense output by
Illinois' regula falsi, and the piece ends at the earliest. Only the live contacts of a
piece are stepped. The step size follows scipy's control, and, against the primary impulse,
also Gustafsson's prediction from the last two steps' errors (the error grows steadily
towards the events that end a piece, where scipy's control alternates accepted and
rejected steps); a piece against the primary impulse starts with the step the last one
proposed, not with scipy's first guess again.
"""

from __future__ import annotations

import numpy as np

from .jit import inline_kernel, kernel
from .lzb_dop853 import dense_output, error_norm, evaluate, interpolate, rk_step, scatter
from .lzb_groups import Piece, PieceEvents
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
    event_values,
    piece_events,
    piece_state,
)

EPS = float(np.finfo(float).eps)
KINK_ITERATIONS = 4
"""Secant steps that place the end of a piece on a kink of the rates."""
SAFETY, MIN_FACTOR, MAX_FACTOR, EXPONENT = 0.9, 0.2, 10.0, -1.0 / 8.0
"""scipy's step-size control for DOP853 (error estimator of order 7)."""


@kernel(refcounted=False, internal=True)
def _root(kind, j, ga, gb, F, x_old, piece, impact, xt, full):
    """θ ∈ [0, 1] where the event's value on the dense output crosses zero (Illinois' regula
    falsi until the bracket is 4 ulp wide), on the far side of the crossing; ``xt`` and
    ``full`` are scratch (components, full state)."""
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
        interpolate(F, x_old, c, nc, xt)
        scatter(xt, comps, nc, full)
        gc = event_value(kind, j, k, full, level, live, nlive, law, indptr, indices, data,
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


@kernel(refcounted=False, internal=True)
def _step_to_kink(x, tau, kind, j, g0, piece, impact, tableau, stages, out, full, istate):
    """The state where a kink of the rates (a turn, a plastic stop) lies, into ``out``
    (components; ``full`` the full state): the dense output of the step that crossed it is
    polluted by the stages past it, so the kink is reached by real steps from x, whose
    stages see only the rates before it; their length τ (first guess from the dense output)
    is refined by the secant method on the event's value (docs/theory.md §13)."""
    k, live, nlive, level = piece.k, piece.live, piece.nlive, piece.level
    indptr, indices, data, gamma0, law = impact
    t0, ga = 0.0, g0
    for _ in range(KINK_ITERATIONS):
        rk_step(x, tau, piece, impact, tableau, stages, out)
        scatter(out, piece.comps, piece.nc, full)
        istate[EVALUATIONS] += 11
        g = event_value(kind, j, k, full, level, live, nlive, law, indptr, indices, data,
                        gamma0)
        if g == 0.0 or g == ga:
            return
        t0, ga, tau, last = tau, g, tau - g * (tau - t0) / (g - ga), tau
        if abs(tau - last) <= 4.0 * EPS * abs(last):
            return


@inline_kernel
def _next_step(h, norm, rejected, predict, h_prev, norm_prev):
    """The next step after an accepted one of length h and error ``norm`` (< 1): scipy's
    factor, and, with ``predict`` and an accepted step (h_prev, norm_prev) before it in the
    piece, no more than Gustafsson's predictive factor (the error's growth along the piece
    extrapolated from the two steps)."""
    factor = MAX_FACTOR if norm == 0.0 else min(MAX_FACTOR, SAFETY * norm ** EXPONENT)
    if predict and norm > 0.0 and norm_prev > 0.0:
        factor = min(factor, max(MIN_FACTOR, SAFETY * norm ** EXPONENT * (h / h_prev)
                                 * (norm_prev / norm) ** (-EXPONENT)))
    return h * (min(1.0, factor) if rejected else factor)


@inline_kernel
def _piece(x, k, live, nlive, events, rtol, fixed, h_start, max_steps, impact, tableau,
           istate, fstate, work):
    """Integrate one piece from x until its first event (against time when k < 0), x
    replaced by the state there. Returns (status, index of the event or −1 at the end of
    the span, the step proposed next). DOP853 at rtol = atol (scipy's error norm, scale
    rtol·(1 + |x|), step control :func:`_next_step`) from h_start (0: scipy's first guess),
    or, with ``fixed`` > 0, steps of that length without error control; every step's error
    estimate is added to fstate[ERROR]."""
    kinds, contacts, directions, ne = events
    m = impact.gamma0.size
    n = 3 * m
    stages, xc, x_new, x_try, e5, e3, F, full_new, full_try, g_old, g_new, comps = work
    K = stages.K
    nc = 3 * nlive
    for a in range(nlive):
        for r in range(3):
            comps[3 * a + r] = r * m + live[a]
    for i in range(n):  # the frozen components, which the rates and events read, stay x's
        stages.xs[i] = x[i]
        full_new[i] = x[i]
        full_try[i] = x[i]
    for c in range(nc):
        xc[c] = x[comps[c]]
    t = 0.0
    h_abs = fixed if fixed > 0.0 else (h_start if h_start > 0.0 else FIRST_STEP * PIECE_SPAN)
    h_prev, norm_prev = 0.0, 0.0
    piece = Piece(k, live, nlive, comps, nc, fstate[LEVEL])
    evaluate(xc, piece, impact, stages, K[0])
    istate[EVALUATIONS] += 1
    event_values(events, k, x, piece.level, live, nlive, impact, g_old)
    while True:
        if istate[STEPS] >= max_steps:
            return OUT_OF_STEPS, -1, h_abs
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        h_abs = max(h_abs, min_step) if fixed <= 0.0 else fixed
        rejected = False
        while True:
            if h_abs < min_step:
                return STEP_TOO_SMALL, -1, h_abs
            t_new = min(t + h_abs, PIECE_SPAN)
            h = t_new - t
            rk_step(xc, h, piece, impact, tableau, stages, x_new)
            evaluate(x_new, piece, impact, stages, K[12])
            istate[EVALUATIONS] += 12
            unit = error_norm(xc, x_new, h, nc, n, tableau, K, e5, e3)
            if fixed > 0.0:
                break
            norm = unit / rtol
            if norm < 1.0:
                h_abs = _next_step(h, norm, rejected, k >= 0, h_prev, norm_prev)
                h_prev, norm_prev = h, norm
                break
            h_abs = h * max(MIN_FACTOR, SAFETY * norm ** EXPONENT)
            rejected = True
        istate[STEPS] += 1
        fstate[ERROR] += unit
        scatter(x_new, comps, nc, full_new)
        event_values(events, k, full_new, piece.level, live, nlive, impact, g_new)
        first, first_theta, dense = -1, 2.0, False
        for e in range(ne):  # sign changes over the step, in the event's direction
            up = g_old[e] <= 0.0 <= g_new[e]
            down = g_old[e] >= 0.0 >= g_new[e]
            if not ((up and directions[e] > 0.0) or (down and directions[e] < 0.0)):
                continue
            if not dense:
                dense_output(xc, x_new, h, piece, impact, tableau, stages, F)
                istate[EVALUATIONS] += 3
                dense = True
            theta = _root(kinds[e], contacts[e], g_old[e], g_new[e], F, xc, piece, impact,
                          x_try, full_try)
            if theta < first_theta:
                first, first_theta = e, theta
        if first >= 0:
            if kinds[first] == TURN or kinds[first] == PLASTIC_STOP:
                _step_to_kink(xc, h * first_theta, kinds[first], contacts[first], g_old[first],
                              piece, impact, tableau, stages, x_try, full_try, istate)
            else:
                interpolate(F, xc, first_theta, nc, x_try)
            scatter(x_try, comps, nc, x)
            return DONE, first, h_abs
        for c in range(nc):
            xc[c] = x_new[c]
            K[0, c] = K[12, c]
        for e in range(ne):
            g_old[e] = g_new[e]
        t = t_new
        if t >= PIECE_SPAN:
            scatter(xc, comps, nc, x)
            return DONE, -1, h_abs


@kernel(refcounted=False)
def integrate_impact(impact, tableau, rtol, max_steps, max_pieces, y, P, D, left, istate,
                     fstate, primaries, buffers, work):
    """Integrate one multiple ``impact`` (:class:`~impactqp.kernels.lzb_model.Impact`) with
    DOP853's ``tableau`` (:class:`~impactqp.kernels.lzb_groups.Tableau`) piece by piece
    until every contact is open (docs/theory.md §13): y, P, D and ``left`` (energy still
    stored when a contact opened) updated in place, the primary contact of each piece into
    ``primaries`` (max_pieces + 1 entries), counters into ``istate``/``fstate``
    (:func:`impactqp.kernels.lzb_model.new_state`), ``buffers`` and ``work`` the pieces'
    scratch (:func:`impactqp.kernels.lzb_groups.piece_buffers`, :func:`piece_work
    <impactqp.kernels.lzb_groups.piece_work>`). fstate[FIXED_STEP] > 0 takes fixed
    steps of that (dimensionless) length in the primary impulse, the pieces against time
    staying adaptive. Returns DONE, OUT_OF_STEPS (``max_steps`` accepted steps spent),
    OUT_OF_PIECES or STEP_TOO_SMALL."""
    indptr, indices, data, gamma0, law = impact
    frozen, live, gamma, kinds, contacts, directions, x = buffers
    h_next, k_last = 0.0, -1
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
        start = h_next if k >= 0 and k_last >= 0 else 0.0
        status, fired, h_next = _piece(x, k, live, nlive,
                                       PieceEvents(kinds, contacts, directions, ne), rtol, fixed,
                                       start, max_steps, impact, tableau, istate, fstate, work)
        k_last = k
        if status != DONE:
            return status
        kind = kinds[fired] if fired >= 0 else -1
        j = contacts[fired] if fired >= 0 else -1
        end_piece(kind, j, k, primary, before, x, y, P, D, left, istate, fstate, law)
