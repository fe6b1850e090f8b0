"""Event-driven integration with any impact law (docs/theory.md §14).

Smooth phases under a constant force are flown in closed form (constant acceleration, the
first closing gap a root of a quadratic); others are integrated by scipy's
:func:`~scipy.integrate.solve_ivp` (DOP853 by default) with event location, a maximum step
from the system's own period and a search for gaps that dip below zero within one step. A
free contact closing (its gap falls through 0) or a held contact ceasing to push (its force λ
falls through −threshold) ends the phase. At an event:

1. closed contacts are those with gᵢ ≤ ``gap_tol``; each cluster of them with an approaching
   contact (γ⁻ᵢ < 0) is an impact problem (M, H_closed, u⁻), solved with the law through
   :func:`impactqp.solve` and recorded with its certificate;
2. closed contacts that separate slower than ``rest_velocity`` (γ⁺ᵢ ≤ rest_velocity) are
   settled: the velocity is projected onto γᵢ = 0 (the limit of an accumulation of ever
   smaller impacts, which would otherwise stall the integrator: a bouncing ball comes to
   rest instead of bouncing infinitely often before the accumulation time);
3. the acceleration LCP over the settled contacts decides which of them stay closed (held
   as bilateral constraints in the next phase) and which lift off.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from ..base.arrays import as_dense
from ..base.checks import DEFAULT_TOL
from ..errors import InputError, SolverError
from ..laws.base import ImpactLaw
from .clusters import ClusterCache
from .impacts import ImpactEvent, ImpactSolver
from .routing import check_frictionless
from .smooth import Phase, check_solved, contact_accelerations, first_closing
from .system import LinearSystem
from .trajectory import Trajectory

RELATIVE_THRESHOLD = 1e-9
"""Lift-off: a held contact is released when its force falls below −1e-9·F (F the largest
initial force component), and, at the start of a phase, when unloaded (λᵢ = 0) it accelerates
apart faster than 1e-12·F·Gᵢᵢ (a thousand times less than the acceleration at that release,
so that a released contact is not held again)."""

GAP_TOL = 1e-10
"""Default closing tolerance of a gap, relative to the system's length scale."""

REST_VELOCITY = 1e-7
"""Default rest velocity of a closed contact, relative to the system's velocity scale."""

MAX_STALL = 1000
"""Events in a row, each within 1e-12 (relative) of the last, before the run is abandoned."""


class _Recorder:
    """Growing lists of records."""

    def __init__(self, m: int) -> None:
        self.t: list[float] = []
        self.q: list[np.ndarray] = []
        self.v: list[np.ndarray] = []
        self.lam: list[np.ndarray] = []
        self.zero = np.zeros(m)

    def add(self, t: float, q: np.ndarray, v: np.ndarray, lam: np.ndarray | None = None) -> None:
        self.t.append(float(t))
        self.q.append(np.array(q, dtype=float))
        self.v.append(np.array(v, dtype=float))
        self.lam.append(self.zero if lam is None else lam)

    def arrays(self) -> tuple[np.ndarray, ...]:
        return (np.array(self.t), np.array(self.q), np.array(self.v), np.array(self.lam))


def event_driven(system: LinearSystem, law: ImpactLaw, t_end: float, h: float | None = None,
                 *, t0: float = 0.0, backend: str = "auto", tol: float = DEFAULT_TOL,
                 gap_tol: float | None = None, rest_velocity: float | None = None,
                 method: str = "DOP853",
                 rtol: float = 1e-12, atol: float = 1e-14, max_events: int = 100_000,
                 keep_events: bool = True,
                 progress: Callable[[float], None] | None = None) -> Trajectory:
    """Integrate ``system`` from t0 to t_end event by event (docs/theory.md §14).

    Parameters
    ----------
    system : LinearSystem
    law : ImpactLaw
        Any impact law, applied to the pre-impact velocity of each cluster of closed contacts.
    t_end : float
        Final time.
    h : float, optional
        Interval of the output grid (states are also recorded just before and after every
        impact); (t_end − t0)/1000 when omitted.
    t0 : float
        Initial time.
    backend, tol : str, float
        Passed to :func:`impactqp.solve`.
    gap_tol : float, optional
        A contact whose gap is at most this (length units) counts as closed at an event;
        default 10⁻¹⁰ L, L the system's own length scale (:func:`motion_scales`).
    rest_velocity : float, optional
        A closed contact separating slower than this (velocity units) is settled; default
        10⁻⁷ V, V the system's own velocity scale (:func:`motion_scales`).
    method, rtol, atol : str, float, float
        :func:`scipy.integrate.solve_ivp` settings of the smooth phases (unused under a
        constant force, whose phases are exact).
    max_events : int
        Events after which integration stops with an error.
    keep_events : bool
        Keep every solved impact problem as an :class:`~.impacts.ImpactEvent`.
    progress : callable, optional
        Called with the current time after every phase.

    Returns
    -------
    Trajectory

    Raises
    ------
    InputError
        The initial state penetrates a contact (gap < −gap_tol); friction.
    SolverError
        The ODE solver failed, more than ``max_events`` events, or events accumulating
        at one time that settling does not resolve.
    """
    check_frictionless(system, law, "event-driven")
    n = system.n_dof
    cache = ClusterCache(system.M, system.H, system.chain)
    solver = ImpactSolver(cache, law, backend=backend, tol=tol)
    h = (t_end - t0) / 1000.0 if h is None else h
    grid = t0 + h * np.arange(1, int(np.floor((t_end - t0) / h + 1e-9)) + 1)
    force_scale = max(float(np.abs(system.force_at(t0, system.q0, system.v0)).max(initial=0.0)),
                      1e-300)
    lift_threshold = RELATIVE_THRESHOLD * force_scale
    acc_tol = 1e-3 * lift_threshold * system.structure.delassus_diagonal \
        if system.n_contacts else 0.0
    max_step = _max_step(system)
    length, speed = motion_scales(system, t0, t_end - t0)
    gap_tol = GAP_TOL * length if gap_tol is None else gap_tol
    rest_velocity = REST_VELOCITY * speed if rest_velocity is None else rest_velocity
    g = system.gaps(system.q0)
    if np.any(g < -gap_tol):
        worst = int(np.argmin(g))
        raise InputError(f"q0 penetrates contact {worst}: its gap is {g[worst]:.3g} < "
                         f"-gap_tol = {-gap_tol:.3g}")
    rec = _Recorder(system.n_contacts)
    t, q, v = t0, system.q0.copy(), system.v0.copy()
    rec.add(t, q, v)
    events: list[ImpactEvent] = []
    structures: dict[frozenset, tuple] = {}
    count, stall, last = 0, 0, t0
    while True:
        g, gamma = system.gaps(q), system.contact_velocities(v)
        closed = g <= gap_tol
        lam = None
        if np.any(closed & (gamma < 0)):
            v_new, lam, new = solver.solve(t, v, closed)
        else:
            v_new, new = v, []
        gamma_new = system.contact_velocities(v_new)
        rest = closed & (gamma_new <= rest_velocity)
        v_new = Phase(system, rest, structures).hold(v_new)[0] if rest.any() else v_new
        for e in new:
            e.settled = e.contacts[(gamma_new[e.contacts] > 0) & rest[e.contacts]]
        if keep_events:
            events.extend(new)
        if lam is not None or not np.array_equal(v_new, v):
            rec.add(t, q, v_new, lam)
        v = v_new
        if t >= t_end:
            break
        a, lam_acc = contact_accelerations(system, cache, t, q, v, rest, tol)
        Hta = system.contact_velocities(a)
        held = rest & ~((Hta > acc_tol) & (lam_acc <= lift_threshold))
        phase = Phase(system, held, structures)
        watched = np.flatnonzero(~held)
        near = g[watched] <= gap_tol
        t_eval = np.append(grid[(grid > t) & (grid < t_end)], t_end)
        if system.constant_force is not None:  # constant acceleration: the flight is exact
            a = phase.acceleration(t, q, v)[0]
            tau = first_closing(g[watched], gamma_new[watched],
                                system.contact_velocities(a)[watched], near)
            sol = _exact_flight(t, q, v, a, t_eval, t + tau if t + tau <= t_end else None)
        else:
            closing = phase.closing_event(watched, near, g[watched])
            liftoff = phase.liftoff_event(lift_threshold)
            first = _first_step(gamma_new[watched][near], Hta[watched][near], t_end - t)
            for _ in range(6):
                sol = solve_ivp(phase.rhs, (t, t_end), np.concatenate([q, v]), method=method,
                                t_eval=t_eval, events=[closing, liftoff], rtol=rtol, atol=atol,
                                first_step=first, max_step=max_step, dense_output=True)
                check_solved(sol.status, sol.message, t)
                if not _spurious(sol, system, t, gap_tol):
                    break
                first = min(first or 1e-6 * (t_end - t), t_end - t) / 100.0
            sol = _grazing(sol, system, watched, np.where(near, g[watched], 0.0))
        if len(sol.t):  # t_eval points before the event (solve_ivp gives [] for none)
            for k in range(len(sol.t)):
                rec.add(sol.t[k], sol.y[:n, k], sol.y[n:, k])
        if progress is not None:
            progress(t_end if sol.status != 1 else _event_time(sol))
        if sol.status != 1:
            break
        t = _event_time(sol)
        y = sol.y_events[0][0] if sol.t_events[0].size else sol.y_events[1][0]
        q, v = y[:n].copy(), y[n:].copy()
        rec.add(t, q, v)
        count += 1
        stall = stall + 1 if t - last <= 1e-12 * max(1.0, abs(t)) else 0
        last = t
        if count > max_events or stall > MAX_STALL:
            why = "more than max_events events" if count > max_events else \
                f"{MAX_STALL} events at the same time"
            raise SolverError(f"event-driven integration stopped at t = {t:.12g}: {why}; "
                              "raise rest_velocity or gap_tol, or use time-stepping")
    T, Q, V, L = rec.arrays()
    settings = {"h": h, "t0": t0, "t_end": t_end, "backend": backend, "tol": tol,
                "gap_tol": gap_tol, "rest_velocity": rest_velocity, "method": method,
                "rtol": rtol, "atol": atol, "events": count, "keep_events": keep_events}
    return Trajectory(system, law, "event-driven", T, Q, V, L, events, settings)


class _Flight(NamedTuple):
    """A phase flown in closed form, read like the result of ``solve_ivp`` with one
    terminal event."""

    t: np.ndarray
    y: np.ndarray
    status: int
    t_events: list[np.ndarray]
    y_events: list[np.ndarray]


def _exact_flight(t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, t_eval: np.ndarray,
                  t_event: float | None) -> _Flight:
    """States q + vτ + ½aτ², v + aτ at the output times before ``t_event`` (all of them when
    no contact closes) and at the event itself (docs/theory.md §14)."""
    times = t_eval if t_event is None else t_eval[t_eval < t_event]
    tau = times - t
    with np.errstate(over="ignore", invalid="ignore"):  # a state that overflows is refused
        # (0.5a·τ)·τ: a body at rest (a = 0, v = 0) stays put for any τ, even τ² = ∞
        y = np.concatenate([q[:, None] + v[:, None] * tau + (0.5 * a)[:, None] * tau * tau,
                            v[:, None] + a[:, None] * tau])
    if t_event is None:
        return _Flight(times, y, 0, [np.zeros(0)], [np.zeros((0, 2 * q.size))])
    tau = t_event - t
    y_event = np.concatenate([q + v * tau + (0.5 * a * tau) * tau, v + tau * a])
    return _Flight(times, y, 1, [np.array([t_event])], [y_event[None, :]])


def motion_scales(system: LinearSystem, t0: float, span: float) -> tuple[float, float]:
    """(L, V): the length and velocity scales of the system's own motion, which the default
    event thresholds are relative to, so that the same motion in other units has the same
    events (docs/theory.md §14).

    L is the largest initial gap; V the largest of the initial contact speeds and √(2LA),
    A the largest initial contact acceleration |Hᵀ M⁻¹ f(t0)| (the speed of falling through
    L).
    Where the gaps are all closed, L = V²/A (or V·span without acceleration); where nothing
    moves or pushes, 1.
    """
    if system.n_contacts == 0:
        return 1.0, 1.0
    q0, v0 = system.q0, system.v0
    gap = float(np.abs(system.gaps(q0)).max())
    speed = float(np.abs(system.contact_velocities(v0)).max())
    accel = system.structure.solve_mass(system.force_at(t0, q0, v0))
    push = float(np.abs(system.contact_velocities(accel)).max())
    if gap > 0:
        speed = max(speed, float(np.sqrt(2.0 * gap * push)))
        return gap, speed if speed > 0 else gap / span
    if speed > 0:
        return (speed * speed / push if push > 0 else speed * span), speed
    return 1.0, 1.0


def _max_step(system: LinearSystem) -> float:
    """An eighth of the shortest period of a linear force's oscillations, 2π/ω_max with
    ω²_max the largest eigenvalue of (K, M), so that a gap has at most one minimum between two
    accepted steps (docs/theory.md §14); unbounded for other forces."""
    K = system.linear_force.stiffness if system.linear_force is not None else None
    if K is None:
        return np.inf
    K = K.toarray() if sp.issparse(K) else np.asarray(K)
    if not K.any():
        return np.inf
    w2 = float(sla.eigh(K, as_dense(system.M), eigvals_only=True)[-1])
    return np.inf if w2 <= 0.0 else 2.0 * np.pi / np.sqrt(w2) / 8.0


def _grazing(sol: Any, system: LinearSystem, watched: np.ndarray, offset: np.ndarray) -> Any:
    """``sol`` ended at the first watched contact whose gap gᵢ − offsetᵢ (offset: the gap at
    the start for contacts near closed, as in :meth:`Phase.closing_event`) dips below zero
    and back between two accepted steps: a grazing impact that the sign test at the steps
    does not see.

    On a step where the gap is positive at both ends while γᵢ turns from negative to
    positive, its minimum is where γᵢ = 0 on the solver's dense output; if the gap is
    negative there, the contact closed at the root of the gap before it (docs/theory.md §14).
    """
    if watched.size == 0 or sol.sol is None:
        return sol
    n = system.n_dof
    ts = sol.sol.ts
    Y = sol.sol(ts)
    G = system.gaps(Y[:n].T)[:, watched] - offset
    Gam = system.contact_velocities(Y[n:].T)[:, watched]
    dips = (G[:-1] > 0) & (G[1:] > 0) & (Gam[:-1] < 0) & (Gam[1:] > 0)
    def speed(s: float, h: np.ndarray, b: float) -> float:
        return float(h @ sol.sol(s)[n:])

    def gap(s: float, h: np.ndarray, b: float) -> float:
        return float(h @ sol.sol(s)[:n] + b)

    found = None
    for j, i in zip(*np.nonzero(dips)):  # steps in time order
        if found is not None and ts[j] >= found:
            break
        h = system.H[:, watched[i]]
        h = h.toarray().ravel() if sp.issparse(h) else np.asarray(h).ravel()
        b = system.b[watched[i]] - offset[i]
        t_min = brentq(speed, ts[j], ts[j + 1], args=(h, b))
        if gap(t_min, h, b) < 0:
            t_in = brentq(gap, ts[j], t_min, args=(h, b))
            found = t_in if found is None else min(found, t_in)
    if found is None:
        return sol
    keep = sol.t < found
    return _Flight(sol.t[keep], sol.y[:, keep], 1, [np.array([found])],
                   [sol.sol(found)[None, :]])


def _event_time(sol) -> float:
    return float(sol.t_events[0][0] if sol.t_events[0].size else sol.t_events[1][0])


def _first_step(gamma: np.ndarray, accel: np.ndarray, span: float) -> float | None:
    """A first step shorter than the flight of any contact that just separated (γ > 0)
    and decelerates (Hᵀa < 0), so that the solver sees it open before it closes again."""
    back = (gamma > 0) & (accel < 0)
    if not back.any():
        return None
    return float(min(0.1 * np.min(2.0 * gamma[back] / -accel[back]), span))


def _spurious(sol, system: LinearSystem, t: float, gap_tol: float) -> bool:
    """A closing event found at the start of the phase, with nothing approaching: the first
    step was too long to see a separating contact open."""
    if sol.status != 1 or not sol.t_events[0].size:
        return False
    if sol.t_events[0][0] - t > 1e-12 * max(1.0, abs(t)):
        return False
    y = sol.y_events[0][0]
    n = system.n_dof
    closed = system.gaps(y[:n]) <= gap_tol
    return not np.any(system.contact_velocities(y[n:])[closed] < 0)
