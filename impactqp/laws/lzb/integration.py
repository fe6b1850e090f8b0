"""The integration of the LZB model (docs/theory.md §13): the compiled stepper of
:mod:`impactqp.kernels.lzb`, and scipy's DOP853 as the reference it is tested against.

The impact is integrated piece by piece, each piece until its first event, located on the
stepper's dense output. While every contact stores little energy (below ``ENERGY_LEVEL``:
the start, the end, a restart) the state is integrated against time, where it is regular.
Otherwise the primary contact k is the one storing the most potential energy, and the state
is integrated against its impulse Pₖ with the distributing law dPᵢ/dPₖ = Fᵢ/Fₖ. Events:
another contact's energy overtakes the primary's (a switch of the primary contact), a
contact empties while separating (it opens), an open contact approaches again (it closes),
a plastic contact (e = 0) stops compressing (its energy is dissipated at once), a
dissipative contact turns from compression to expansion or back (a kink of its rate), and
the crossings of the energy level between the two parametrizations. The impact is over when
every contact is open: no stored energy and γᵢ ≥ 0.

Adaptive integration uses DOP853 at tolerance ``rtol`` in the dimensionless variables of
:mod:`impactqp.laws.lzb.dynamics`; a fixed ``step`` takes DOP853 steps of that length in the
primary impulse (error control off), the low-energy pieces against time staying adaptive.
Both run in one compiled call (:func:`impactqp.kernels.lzb.integrate_impact`); the
reference (``reference=True``) runs every piece with scipy's ``solve_ivp`` on the same
compiled rates, events and piece logic. Either stops within a budget of steps derived from
the options and the number of contacts (:func:`step_budget`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from ...errors import CertificateError, IntegrationBudgetError
from ...kernels import lzb_model as kl
from ...kernels.lzb import integrate_impact
from ...kernels.lzb_groups import dop853_tableau, piece_buffers, piece_work
from .dynamics import LZBDynamics

MAX_PIECES = 20_000
"""Budget of pieces of one integration."""
MAX_WORK = 20_000_000
"""Budget of one integration in steps × (contacts + STEP_OVERHEAD): a few seconds of the
compiled stepper."""
STEP_OVERHEAD = 10
"""What a step costs beyond its contacts (stages, error norm, events), in contacts."""
STEPS_PER_IMPULSE = 2.0
"""Dimensionless primary impulse per contact an impact takes at most, for the estimate of
the steps a fixed ``step`` needs (chains of 10 and 100 balls take 1.3–1.4)."""


def step_budget(m: int) -> int:
    """The most accepted steps an integration of m contacts may take:
    MAX_WORK / (m + STEP_OVERHEAD)."""
    return MAX_WORK // (m + STEP_OVERHEAD)


@dataclass
class LZBRecord:
    """What one LZB integration did and where it ended (physical units).

    Attributes
    ----------
    impulses : (m,) ndarray
        Λ, the impulse every contact transmitted.
    potential_energy : (m,) ndarray
        Potential energy left in each contact at the end: what it still stored when the
        event that opened it was located (zero up to the solver's root finding).
    dissipated : (m,) ndarray
        Energy dissipated by restitution at each contact, Σ (1/eᵢ² − 1)∫γᵢ dPᵢ over its
        expansion phases (all of the stored energy for a plastic contact).
    gamma : (m,) ndarray
        The contact velocities γ⁻ + GΛ carried by the integration at its end.
    primary_switches : int
        How often the primary contact changed.
    primary_contacts : list of int
        The primary contact of each piece, in order.
    steps, evaluations, pieces : int
        Accepted solver steps, right-hand-side evaluations and integration pieces.
    impulse_variable : float
        The impulse gathered by the primary contact of each piece, summed over the pieces
        (the model's independent variable).
    method : str
        ``"DOP853, rtol=…"`` or ``"fixed step …"`` (``", scipy"`` for the reference).
    error_estimate : float
        Sum over the accepted steps of the stepper's local error estimate, relative to
        1 + abs(x) in the dimensionless variables (compiled stepper; the reference reports
        rtol × steps): the integration error the certificate allows for (docs/theory.md §13).
    stored_dimensionless, left_dimensionless : float
        Σ(Eᵢ + Dᵢ) and ΣEᵢ at the end in units of VΠ: what the energy balance adds to T⁺
        and the potential energy left, free of overflow at any velocity scale.
    energy_unit : tuple of float
        (V, g): the energy unit is V²/g.
    """

    impulses: np.ndarray
    potential_energy: np.ndarray
    dissipated: np.ndarray
    gamma: np.ndarray
    primary_switches: int = 0
    primary_contacts: list = field(default_factory=list)
    steps: int = 0
    evaluations: int = 0
    pieces: int = 0
    impulse_variable: float = 0.0
    method: str = ""
    error_estimate: float = 0.0
    stored_dimensionless: float = 0.0
    left_dimensionless: float = 0.0
    energy_unit: tuple = (1.0, 1.0)


def _prepare(dyn: LZBDynamics, step: float | None) -> tuple[float, int]:
    """The dimensionless fixed step (0: adaptive) and the step budget; refuses a step so
    small that the budget cannot hold the steps it needs."""
    budget = step_budget(dyn.m)
    if step is None:
        return 0.0, budget
    s = dyn.scales
    h = step / s.velocity * s.delassus  # step / Π, without forming Π
    need = STEPS_PER_IMPULSE * dyn.m / h if h > 0 else np.inf
    if not np.isfinite(h) or need > budget:
        raise IntegrationBudgetError(
            f"step={step:g} N·s is {h:.3g} of this impact's impulse scale Π = V/g "
            f"= {s.impulse:.3g} N·s: its {dyn.m} contacts need about {need:.3g} fixed steps, "
            f"more than the budget of {budget}; take step ≥ "
            f"{STEPS_PER_IMPULSE * dyn.m / budget * s.impulse:.3g} N·s or adaptive steps "
            "(step=None)")
    return h, budget


def _budget_error(status: int, budget: int, dyn: LZBDynamics, step: float | None,
                  rtol: float) -> CertificateError:
    options = f"rtol={rtol:g}" if step is None else f"step={step:g} N·s"
    spread = 1.0 / float(np.min(dyn.law[kl.KAPPA]))
    if spread > 1e6:  # contacts whose time scales differ that much make the impact stiff
        options += (f"; the contacts' scaled force coefficients span {spread:.1e}, check the "
                    "stiffness ratios")
    never = ("an elastic impact where no velocity separates every contact, T_C = {0}, "
             "never ends; give some contact restitution < 1")
    if status == kl.OUT_OF_STEPS:
        return IntegrationBudgetError(
            f"the LZB integration did not end within its budget of {budget} steps for "
            f"{dyn.m} contacts ({options}): the contacts kept exchanging energy ({never})")
    if status == kl.OUT_OF_PIECES:
        return IntegrationBudgetError(
            f"the LZB integration did not end within its budget of {MAX_PIECES} pieces "
            f"({options}): the primary contact or the open contacts kept changing ({never})")
    return CertificateError(f"the LZB integration failed: the step size fell below the "
                            f"spacing of floating-point numbers ({options})")


def _record(dyn: LZBDynamics, y: np.ndarray, P: np.ndarray, D: np.ndarray,
            left: np.ndarray, istate: np.ndarray, fstate: np.ndarray, primaries: list,
            method: str) -> LZBRecord:
    """The record of a finished integration, in physical units."""
    s = dyn.scales
    kl.stored_energies(y, dyn.law, left)
    with np.errstate(over="ignore", under="ignore"):  # energies V²/g may leave the range
        return LZBRecord(
            impulses=P * s.impulse, potential_energy=left * s.velocity * s.impulse,
            dissipated=D * s.velocity * s.impulse,
            gamma=dyn.gamma(P) * s.velocity, primary_switches=int(istate[kl.SWITCHES]),
            primary_contacts=[int(k) for k in primaries], steps=int(istate[kl.STEPS]),
            evaluations=int(istate[kl.EVALUATIONS]), pieces=int(istate[kl.PIECES]),
            impulse_variable=float(fstate[kl.IMPULSE_VARIABLE]) * s.impulse, method=method,
            error_estimate=float(fstate[kl.ERROR]),
            stored_dimensionless=float(np.sum(left) + np.sum(D)),
            left_dimensionless=float(np.sum(left)),
            energy_unit=(s.velocity, s.delassus))


def _reference(dyn: LZBDynamics, rtol: float, h: float, budget: int, y, P, D, left, istate,
               fstate) -> tuple[int, list]:
    """The same integration with scipy's solve_ivp (DOP853) for every piece, on the compiled
    rates, events and piece logic; returns (status, primary contacts)."""
    m, args = dyn.m, dyn.structure
    indptr, indices, data, gamma0, law = args
    frozen, gamma, live = np.zeros(m, dtype=np.bool_), np.empty(m), np.empty(m, dtype=np.int64)
    kinds, contacts = np.empty(3 * m + 3, dtype=np.int64), np.empty(3 * m + 3, dtype=np.int64)
    directions, x = np.empty(3 * m + 3), np.empty(3 * m)
    primaries: list = []
    while True:
        primary = kl.begin_piece(y, P, D, frozen, gamma, istate, fstate, law, *args[:4])
        if primary < 0:
            return kl.DONE, primaries
        if istate[kl.PIECES] > MAX_PIECES:
            return kl.OUT_OF_PIECES, primaries
        primaries.append(primary)
        k = -1 if istate[kl.IN_TIME] else primary
        ne, nlive = kl.piece_events(k, frozen, gamma, law, indptr, indices, kinds, contacts,
                                    directions, live)
        kl.piece_state(y, P, D, k, law, x)
        level, before = float(fstate[kl.LEVEL]), P[primary]

        def fun(t, z, k=k, nlive=nlive):
            out = np.zeros(3 * m)
            kl.rates(z, k, live, nlive, indptr, indices, data, gamma0, law, np.empty(m), out)
            istate[kl.EVALUATIONS] += 1
            return out

        events = []
        for e in range(ne):
            def event(t, z, kind=int(kinds[e]), j=int(contacts[e]), k=k, nlive=nlive,
                      level=level):
                return kl.event_value(kind, j, k, z, level, live, nlive, law, indptr, indices,
                                      data, gamma0)
            event.terminal, event.direction = True, float(directions[e])
            events.append(event)
        if h > 0 and k >= 0:
            options = dict(first_step=h, max_step=h, rtol=1e3, atol=1e3)
        else:
            options = dict(rtol=rtol, atol=rtol, first_step=kl.FIRST_STEP * kl.PIECE_SPAN)
        with np.errstate(over="ignore", invalid="ignore"):  # trial steps past an event
            sol = solve_ivp(fun, (0.0, kl.PIECE_SPAN), x, method="DOP853", events=events,
                            **options)
        if sol.status < 0:
            return kl.STEP_TOO_SMALL, primaries
        istate[kl.STEPS] += len(sol.t) - 1
        fstate[kl.ERROR] += rtol * (len(sol.t) - 1) if not (h > 0 and k >= 0) else 0.0
        if istate[kl.STEPS] > budget:
            return kl.OUT_OF_STEPS, primaries
        fired = [e for e, times in enumerate(sol.t_events) if len(times)]
        x[:] = sol.y[:, -1]
        kind, j = (int(kinds[fired[0]]), int(contacts[fired[0]])) if fired else (-1, -1)
        kl.end_piece(kind, j, k, primary, before, x, y, P, D, left, istate, fstate, law)


def integrate(dyn: LZBDynamics, *, rtol: float, step: float | None,
              reference: bool = False) -> LZBRecord:
    """Integrate one multiple impact of the LZB model until every contact is open.

    Parameters
    ----------
    dyn : LZBDynamics
        The impact's contacts, G and γ⁻ (with at least one γ⁻ᵢ < 0).
    rtol : float
        Tolerance of the adaptive steps (dimensionless variables).
    step : float or None
        Fixed step in the primary impulse (physical units), or None for adaptive steps.
    reference : bool
        Integrate each piece with scipy's ``solve_ivp`` (DOP853) instead of the compiled
        stepper: the slow reference the tests compare against.

    Returns
    -------
    LZBRecord

    Raises
    ------
    IntegrationBudgetError
        A fixed step too small for the budget, or the budget of steps or pieces spent.
    CertificateError
        The step size collapsed.
    """
    m = dyn.m
    h, budget = _prepare(dyn, step)
    y, P, D, left = np.zeros(m), np.zeros(m), np.zeros(m), np.zeros(m)
    istate, fstate = kl.new_state()
    fstate[kl.FIXED_STEP] = h
    if reference:
        status, primaries = _reference(dyn, rtol, h, budget, y, P, D, left, istate, fstate)
    else:
        buffer = np.empty(MAX_PIECES + 1, dtype=np.int64)
        status = integrate_impact(dyn.structure, dop853_tableau(), rtol, budget, MAX_PIECES,
                                  y, P, D, left, istate, fstate, buffer, piece_buffers(m),
                                  piece_work(m))
        primaries = buffer[:min(int(istate[kl.PIECES]), MAX_PIECES)].tolist()
    if status != kl.DONE:
        raise _budget_error(status, budget, dyn, step, rtol)
    method = f"DOP853, rtol={rtol:g}" if step is None else f"fixed step {step:g}"
    return _record(dyn, y, P, D, left, istate, fstate, primaries,
                   method + (", scipy" if reference else ""))
