"""The LZB model of a multiple impact in compiled code: its one definition (docs/theory.md §13).

The state of an impact is, per contact i of m, yᵢ = Eᵢ^(1/(ηᵢ+1)) (Eᵢ its stored energy),
the impulse Pᵢ and the dissipated energy Dᵢ, all dimensionless (the units of
:mod:`impactqp.laws.lzb.dynamics`). A piece is integrated in x = (z, P, D) (3m entries)
against time (primary ``k < 0``) or against the impulse Pₖ of the primary contact k, whose
slot zₖ then holds Eₖ itself. Everything the model defines is here, once, and both
integrations call it (the compiled stepper of :mod:`impactqp.kernels.lzb` and scipy's
reference in :mod:`impactqp.laws.lzb.integration`):

* :func:`rates`, the right-hand side,
* :func:`begin_piece`, :func:`piece_events`, :func:`piece_state`, :func:`event_value` and
  :func:`end_piece`, the piece-by-piece logic (primary contact, open contacts, the events
  that end a piece and what each does).

An open contact ("frozen" for a piece: y = 0, not approaching) has no rates at all, so a
piece integrates only the ``live`` contacts and watches only the events whose value can
change: a step costs O(live contacts and their rows of G), not O(m), along a chain.

G = WᵀM⁻¹W (scaled) travels in compressed rows (``indptr``, ``indices``, ``data``): a
right-hand side costs O(nnz(G)), O(m) for a chain. Per-contact constants travel as the rows
of ``law``: κ (scaled force coefficient), η, 1/(η+1), 1/e² (0 when e = 0) and 1 for a
plastic contact.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .jit import kernel

TINY = 1e-30
"""Floor of the primary contact's dimensionless force: its energy is zero only at the event
that ends a piece, and trial steps beyond that event must stay finite."""
ENERGY_LEVEL = 1e-6
"""Below this dimensionless energy in every contact (the start, the end, a restart) the
state is integrated against time; the primary impulse takes over when a contact's energy
rises to it and hands back when the primary's falls to half of it. With fixed steps the
level is raised to what a few steps can remove from the primary contact."""
VELOCITY_LEVEL = 1e-12
"""Dimensionless contact velocity below which an open contact counts as closing again, and
above which a plastic contact counts as no longer compressing."""
END_ENERGY = 1e-20
"""The impact is over when no contact approaches faster than VELOCITY_LEVEL and none stores
more than this dimensionless energy (which is reported as left in the contacts)."""
SWITCH_MARGIN = 1e-6
"""The primary contact changes when another contact stores this fraction more energy (a tie,
as in a symmetric impact, keeps the current primary)."""
PIECE_SPAN = 1e4
"""Longest piece, in dimensionless primary impulse or time, before it is restarted."""
FIRST_STEP = 1e-7
"""First adaptive step as a fraction of the piece's span (the solver's guess can jump far)."""

# rows of ``law``
KAPPA, ETA, POWER, EXPANSION, PLASTIC = 0, 1, 2, 3, 4
# the events that end a piece
CLOSE, OPEN, PLASTIC_STOP, TURN, SWITCH, LOW, HIGH = 0, 1, 2, 3, 4, 5, 6
# slots of ``istate`` (integers) and ``fstate`` (floats)
NEXT, PRIMARY, IN_TIME, SWITCHES, PIECES, STEPS, EVALUATIONS = 0, 1, 2, 3, 4, 5, 6
LEVEL, IMPULSE_VARIABLE, FIXED_STEP, ERROR = 0, 1, 2, 3
# what an integration returns
DONE, OUT_OF_STEPS, OUT_OF_PIECES, STEP_TOO_SMALL = 0, 1, 2, 3


class Impact(NamedTuple):
    """What the kernels take about an impact (dimensionless, docs/theory.md §13).

    Attributes
    ----------
    indptr, indices, data : int, int, float arrays
        G = WᵀM⁻¹W (scaled) in compressed rows.
    gamma0 : (m,) float array
        γ⁻, the contact velocities before the impact.
    law : (5, m) float array
        The per-contact constants, rows KAPPA, ETA, POWER, EXPANSION and PLASTIC.
    """

    indptr: np.ndarray
    indices: np.ndarray
    data: np.ndarray
    gamma0: np.ndarray
    law: np.ndarray


def new_state() -> tuple[np.ndarray, np.ndarray]:
    """Fresh ``istate`` (no primary, no next primary, starting against time) and ``fstate``."""
    istate = np.zeros(7, dtype=np.int64)
    istate[NEXT] = -1
    istate[PRIMARY] = -1
    istate[IN_TIME] = 1
    return istate, np.zeros(4)


@kernel(refcounted=False, internal=True)
def _gamma_row(indptr, indices, data, gamma0, P, i):
    """γᵢ = γ⁻ᵢ + (GP)ᵢ."""
    s = gamma0[i]
    for p in range(indptr[i], indptr[i + 1]):
        s += data[p] * P[indices[p]]
    return s


@kernel(refcounted=False, internal=True)
def _power(y, a):
    """y^a for y ≥ 0, without the general power where a is a Hertz or linear exponent."""
    if a == 1.0:
        return y
    if a == 0.5:
        return np.sqrt(y)
    if a == 1.5:
        return y * np.sqrt(y)
    if a == 2.0:
        return y * y
    if a == 2.5:
        return y * y * np.sqrt(y)
    return y ** a


@kernel(refcounted=False, internal=True)
def _energy(y, eta):
    """E = max(y, 0)^(η+1)."""
    return _power(y, eta + 1.0) if y > 0.0 else 0.0


@kernel(refcounted=False)
def contact_velocities(indptr, indices, data, gamma0, P, out):
    """γ = γ⁻ + GP into ``out``."""
    for i in range(gamma0.size):
        out[i] = _gamma_row(indptr, indices, data, gamma0, P, i)


@kernel(refcounted=False)
def rates(x, k, live, nlive, indptr, indices, data, gamma0, law, gamma, out):
    """dx of the state x = (z, P, D) against time (k < 0) or against the impulse of the
    primary contact k (docs/theory.md §13), for the contacts ``live[:nlive]`` into ``out``
    (γ into ``gamma``); an open contact left out has none (the caller keeps its zeros).

    Against time ẏᵢ = −sᵢγᵢκᵢ/(ηᵢ+1) (sᵢ = 1 in compression, 1/eᵢ² in expansion),
    Ṗᵢ = Fᵢ = κᵢ yᵢ^ηᵢ and Ḋᵢ = (1/eᵢ² − 1)γᵢFᵢ in expansion (a plastic contact, emptied by
    an event, has no expansion rate). Against Pₖ every rate is divided by Fₖ (floored at
    TINY), Ṗₖ = 1, and zₖ = Eₖ moves at −sₖγₖ. The primary k must be live."""
    m = gamma0.size
    P = x[m:2 * m]
    inv = 1.0
    if k >= 0:  # Fₖ = κₖ Eₖ^(ηₖ/(ηₖ+1))
        ek = max(x[k], 0.0)
        inv = 1.0 / max(law[KAPPA, k] * _power(ek, law[ETA, k] * law[POWER, k]), TINY)
    for a in range(nlive):
        i = live[a]
        g = _gamma_row(indptr, indices, data, gamma0, P, i)
        gamma[i] = g
        yi = x[i] if i != k else 0.0  # the primary's rates are set below
        force = law[KAPPA, i] * _power(yi, law[ETA, i]) if yi > 0.0 else 0.0
        compressing = g < 0.0
        s = 1.0 if compressing else law[EXPANSION, i]
        out[i] = -s * g * law[KAPPA, i] * law[POWER, i] * inv
        out[m + i] = force * inv
        dissipating = not compressing and law[PLASTIC, i] == 0.0
        out[2 * m + i] = (law[EXPANSION, i] - 1.0) * g * force * inv if dissipating else 0.0
    if k >= 0:
        out[m + k] = 1.0
        g = gamma[k]
        if g < 0.0:
            out[k] = -g
            out[2 * m + k] = 0.0
        elif law[PLASTIC, k] != 0.0:
            out[k] = 0.0
            out[2 * m + k] = 0.0
        else:
            out[k] = -law[EXPANSION, k] * g
            out[2 * m + k] = (law[EXPANSION, k] - 1.0) * g


@kernel(refcounted=False)
def begin_piece(y, P, D, frozen, gamma, istate, fstate, law, indptr, indices, data, gamma0):
    """Start the next piece: empty the plastic contacts past compression (their energy is
    dissipated), mark the open contacts ``frozen``, set the energy level and whether the
    piece runs against time, and choose the primary contact. Returns it, or −1 when the
    impact is over (every contact open: γᵢ > −VELOCITY_LEVEL, Eᵢ ≤ END_ENERGY)."""
    m = gamma0.size
    contact_velocities(indptr, indices, data, gamma0, P, gamma)
    over = True
    top, first, low, slowest, reach = 0.0, -1, np.inf, 0, 0.0
    for i in range(m):
        if law[PLASTIC, i] != 0.0 and gamma[i] > 0.0 and y[i] > 0.0:
            D[i] += _energy(y[i], law[ETA, i])
            y[i] = 0.0
        e = _energy(y[i], law[ETA, i])
        frozen[i] = y[i] <= 0.0 and gamma[i] > -0.5 * VELOCITY_LEVEL
        if gamma[i] <= -VELOCITY_LEVEL or e > END_ENERGY:
            over = False
        if e > top:
            top, first = e, i
        if gamma[i] < low:
            low, slowest = gamma[i], i
        reach = max(reach, abs(gamma[i]) * max(1.0, law[EXPANSION, i]))
    if over:
        return -1
    level = ENERGY_LEVEL
    if fstate[FIXED_STEP] > 0.0:  # what a few fixed steps can take out of the primary
        level = max(ENERGY_LEVEL, 4.0 * fstate[FIXED_STEP] * reach)
    fstate[LEVEL] = level
    if top < 0.5 * level:
        istate[IN_TIME] = 1
    k = istate[NEXT] if istate[NEXT] >= 0 else (first if top > 0.0 else slowest)
    istate[NEXT] = -1
    if istate[PRIMARY] >= 0 and k != istate[PRIMARY]:
        istate[SWITCHES] += 1
    istate[PRIMARY] = k
    istate[PIECES] += 1
    return k


@kernel(refcounted=False)
def piece_events(k, frozen, gamma, law, indptr, indices, kinds, contacts, directions, live):
    """The events that end a piece with primary k (k < 0: against time), into ``kinds``,
    ``contacts`` and ``directions`` (−1: the value falls through 0, +1: rises), and the
    contacts that are not frozen into ``live``; returns (events, live contacts). An open
    contact may close (watched only when its row of G meets a live contact: otherwise its
    γ cannot change); another may empty (open); a plastic one may stop compressing; a
    dissipative one may turn between compression and expansion (a kink of its rate); the
    primary may be overtaken (switch) or fall to half the energy level (low); against time,
    a contact's energy may rise to the level (high)."""
    m = gamma.size
    n, nlive = 0, 0
    for j in range(m):
        if frozen[j]:
            moving = False
            for p in range(indptr[j], indptr[j + 1]):
                moving = moving or not frozen[indices[p]]
            if moving:
                kinds[n], contacts[n], directions[n] = CLOSE, j, -1.0
                n += 1
            continue
        live[nlive] = j
        nlive += 1
        if j != k:
            kinds[n], contacts[n], directions[n] = OPEN, j, -1.0
            n += 1
        if law[PLASTIC, j] != 0.0:
            kinds[n], contacts[n], directions[n] = PLASTIC_STOP, j, 1.0
            n += 1
        elif law[EXPANSION, j] > 1.0 and abs(gamma[j]) > VELOCITY_LEVEL:
            kinds[n], contacts[n] = TURN, j
            directions[n] = -1.0 if gamma[j] > 0.0 else 1.0
            n += 1
    if k >= 0:
        kinds[n], contacts[n], directions[n] = SWITCH, k, 1.0
        kinds[n + 1], contacts[n + 1], directions[n + 1] = LOW, k, -1.0
        n += 2
    else:
        kinds[n], contacts[n], directions[n] = HIGH, -1, 1.0
        n += 1
    return n, nlive


@kernel(refcounted=False)
def event_value(kind, j, k, x, level, live, nlive, law, indptr, indices, data, gamma0):
    """The function whose zero is event ``kind`` of contact j, at state x of a piece with
    primary k (k < 0: against time) and contacts ``live[:nlive]`` (the others store
    nothing)."""
    m = gamma0.size
    if kind == OPEN:
        return x[j]
    if kind == LOW:
        return x[k] - 0.5 * level
    if kind == SWITCH:  # −1 while no other contact stores energy
        top = 0.0
        for a in range(nlive):
            i = live[a]
            if i != k and x[i] > 0.0:
                top = max(top, _power(x[i], law[ETA, i] + 1.0))
        return top - (1.0 + SWITCH_MARGIN) * x[k] if top > 0.0 else -1.0
    if kind == HIGH:
        top = 0.0
        for a in range(nlive):
            i = live[a]
            top = max(top, _energy(x[i], law[ETA, i]))
        return top - level
    g = _gamma_row(indptr, indices, data, gamma0, x[m:2 * m], j)
    if kind == CLOSE:
        return g + VELOCITY_LEVEL
    if kind == PLASTIC_STOP:
        return g - VELOCITY_LEVEL
    return g  # TURN


@kernel(refcounted=False, internal=True)
def event_values(events, k, x, level, live, nlive, impact, out):
    """out[e] = :func:`event_value` of each of a piece's ``events``
    (:class:`~impactqp.kernels.lzb_groups.PieceEvents`) at x."""
    indptr, indices, data, gamma0, law = impact
    for e in range(events.n):
        out[e] = event_value(events.kinds[e], events.contacts[e], k, x, level, live, nlive,
                             law, indptr, indices, data, gamma0)


@kernel(refcounted=False)
def piece_state(y, P, D, k, law, x):
    """x = (z, P, D) at the start of a piece: z = y, with zₖ = Eₖ against Pₖ (k ≥ 0)."""
    m = y.size
    for i in range(m):
        x[i] = y[i]
        x[m + i] = P[i]
        x[2 * m + i] = D[i]
    if k >= 0:
        x[k] = _energy(y[k], law[ETA, k])


@kernel(refcounted=False)
def end_piece(kind, j, k, primary, before, x, y, P, D, left, istate, fstate, law):
    """Take the state x at the end of a piece with rates against ``k`` (−1: time) and apply
    the event ``kind`` of contact j that ended it (−1: none): an opened contact keeps the
    energy it still stored as left over, a plastic one dissipates it, the energy level
    crossings switch between time and impulse, a switch names the next primary contact."""
    m = y.size
    for i in range(m):
        y[i] = x[i]
        P[i] = x[m + i]
        D[i] = x[2 * m + i]
    if k >= 0:
        y[k] = _power(max(x[k], 0.0), law[POWER, k])
    if kind == OPEN:
        left[j] += _energy(y[j], law[ETA, j])
        y[j] = 0.0
    elif kind == PLASTIC_STOP:
        D[j] += _energy(y[j], law[ETA, j])
        y[j] = 0.0
    elif kind == HIGH:
        istate[IN_TIME] = 0
    elif kind == LOW:
        istate[IN_TIME] = 1
    elif kind == SWITCH:
        top, best = 0.0, -1
        for i in range(m):
            if i != j:
                e = _energy(y[i], law[ETA, i])
                if e > top:
                    top, best = e, i
        if best >= 0:
            istate[NEXT] = best
    for i in range(m):
        y[i] = max(y[i], 0.0)
    fstate[IMPULSE_VARIABLE] += P[primary] - before


@kernel(refcounted=False)
def stored_energies(y, law, out):
    """out += Eᵢ = max(yᵢ, 0)^(ηᵢ+1): what the contacts still store at the end."""
    for i in range(y.size):
        out[i] += _energy(y[i], law[ETA, i])
