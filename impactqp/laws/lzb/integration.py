"""The integration of the LZB model (docs/theory.md §13) with scipy's ODE solvers.

The impact is integrated piece by piece, each piece until its first event, located on the
solver's dense output. While every contact stores little energy (below ``ENERGY_LEVEL``:
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
:mod:`impactqp.laws.lzb.dynamics`; a fixed ``step`` uses RK45 steps of that length in the
primary impulse (error control off), the low-energy pieces against time staying adaptive.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from ...errors import CertificateError
from .dynamics import LZBDynamics

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
MAX_PIECES = 20_000
"""Budget of pieces of one integration."""
MAX_EVALUATIONS = 1_000_000
"""Budget of right-hand-side evaluations of one integration (about a minute)."""
PIECE_SPAN = 1e4
"""Longest piece, in dimensionless primary impulse or time, before it is restarted."""
FIRST_STEP = 1e-7
"""First adaptive step as a fraction of the piece's span (the solver's guess can jump far)."""


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
        ``"DOP853, rtol=…"`` or ``"fixed step …"``.
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


class _Budget(Exception):
    """Raised inside the right-hand side when the evaluation budget is spent."""


def _event(fun, direction: float, kind: str, contact: int):
    fun.terminal, fun.direction, fun.kind, fun.contact = True, direction, kind, contact
    return fun


class _Run:
    """One integration: the state (y, P, D), the primary contact and the counters."""

    def __init__(self, dyn: LZBDynamics, rtol: float, step: float | None) -> None:
        self.dyn, self.rtol, m = dyn, rtol, dyn.m
        self.step = None if step is None else step / dyn.scales.impulse
        self.y, self.P, self.D = np.zeros(m), np.zeros(m), np.zeros(m)
        self.left = np.zeros(m)
        self.primary: int | None = None
        self.next_primary: int | None = None
        self.in_time = True
        self.level = ENERGY_LEVEL
        self.record = LZBRecord(np.zeros(m), np.zeros(m), np.zeros(m), dyn.gamma0.copy())

    def _level(self, gamma: np.ndarray) -> float:
        """The energy below which pieces run against time: ENERGY_LEVEL, or with fixed steps
        at least the energy that a few steps can take out of the primary contact."""
        if self.step is None:
            return ENERGY_LEVEL
        reach = float(np.max(np.abs(gamma))) * max(1.0, self.dyn.expansion.max())
        return max(ENERGY_LEVEL, 4.0 * self.step * reach)

    def _events(self, k: int | None, frozen: np.ndarray) -> list:
        """The events that end a piece with primary k (None: a piece against time)."""
        dyn, m = self.dyn, self.dyn.m
        gamma = dyn.gamma(self.P)
        events = []
        for j in range(m):
            if frozen[j]:  # an open contact that starts to approach again
                events.append(_event(lambda t, x, j=j: dyn.gamma(x[m:2 * m])[j]
                                     + VELOCITY_LEVEL, -1.0, "close", j))
                continue
            if j != k:  # a contact that empties
                events.append(_event(lambda t, x, j=j: x[j], -1.0, "open", j))
            if dyn.plastic[j]:  # a plastic contact that stops compressing
                events.append(_event(lambda t, x, j=j: dyn.gamma(x[m:2 * m])[j]
                                     - VELOCITY_LEVEL, 1.0, "plastic", j))
            elif dyn.restitution[j] < 1 and abs(gamma[j]) > VELOCITY_LEVEL:
                # compression turns to expansion or back: the rate of yⱼ has a kink there
                events.append(_event(lambda t, x, j=j: dyn.gamma(x[m:2 * m])[j],
                                     -np.sign(gamma[j]), "turn", j))
        if k is not None:
            others = np.arange(m) != k
            power = dyn.eta[others] + 1.0

            def overtaken(t, x):  # −1 while no other contact stores energy
                top = np.max(np.maximum(x[:m][others], 0.0) ** power, initial=0.0)
                return top - (1.0 + SWITCH_MARGIN) * x[k] if top > 0 else -1.0

            events.append(_event(overtaken, 1.0, "switch", k))
            low = 0.5 * self.level
            events.append(_event(lambda t, x: x[k] - low, -1.0, "low", k))
        else:
            power = dyn.eta + 1.0
            events.append(_event(lambda t, x: np.max(np.maximum(x[:m], 0.0) ** power)
                                 - self.level, 1.0, "high", -1))
        return events

    def _solve(self, fun, span: tuple[float, float], z: np.ndarray, k: int | None,
               frozen: np.ndarray, fixed: bool) -> None:
        """Integrate one piece from (z, P, D) until its first event; apply the event."""
        def counted(t, x):
            self.record.evaluations += 1
            if self.record.evaluations > MAX_EVALUATIONS:
                raise _Budget
            with np.errstate(over="ignore", invalid="ignore"):  # trial steps past an event
                return fun(t, x)

        events = self._events(k, frozen)
        if fixed:  # error control off: every step has the length self.step
            options = dict(method="RK45", first_step=self.step, max_step=self.step, rtol=1e3,
                           atol=1e3)
        else:
            options = dict(method="DOP853", rtol=self.rtol, atol=self.rtol,
                           first_step=FIRST_STEP * (span[1] - span[0]))
        with np.errstate(over="ignore", invalid="ignore"):
            sol = solve_ivp(counted, span, np.concatenate([z, self.P, self.D]), events=events,
                            **options)
        if sol.status < 0:
            raise CertificateError(f"the LZB integration failed: {sol.message}")
        self.record.steps += len(sol.t) - 1
        m, x = self.dyn.m, sol.y[:, -1]
        self.y, self.P, self.D = x[:m].copy(), x[m:2 * m], x[2 * m:]
        if k is not None:
            self.y[k] = max(x[k], 0.0) ** self.dyn.power[k]
        self._handle([ev for ev, times in zip(events, sol.t_events) if len(times)])
        self.y = np.maximum(self.y, 0.0)

    def time_piece(self, frozen: np.ndarray) -> None:
        """Integrate against time while every contact stores little energy."""
        dyn, m = self.dyn, self.dyn.m

        def fun(t, x):
            ydot, pdot, ddot, _ = dyn.time_rates(x[:m], x[m:2 * m], frozen)
            return np.concatenate([ydot, pdot, ddot])

        self._solve(fun, (0.0, PIECE_SPAN), self.y, None, frozen, False)

    def impulse_piece(self, k: int, frozen: np.ndarray) -> None:
        """Integrate against the impulse of the primary contact k."""
        dyn, m = self.dyn, self.dyn.m
        z = self.y.copy()
        z[k] = dyn.energy(self.y)[k]

        def fun(t, x):
            return np.concatenate(dyn.impulse_rates(x[:m], x[m:2 * m], k, frozen))

        self._solve(fun, (0.0, PIECE_SPAN), z, k, frozen, self.step is not None)

    def _handle(self, fired: list) -> None:
        """Apply the events that ended a piece."""
        dyn = self.dyn
        for ev in fired:
            j = ev.contact
            if ev.kind == "open":
                self.left[j] += dyn.energy(self.y)[j]
                self.y[j] = 0.0
            elif ev.kind == "plastic":
                self.D[j] += dyn.energy(self.y)[j]
                self.y[j] = 0.0
            elif ev.kind in ("high", "low"):
                self.in_time = ev.kind == "low"
            elif ev.kind == "switch":
                energy = np.where(np.arange(dyn.m) == j, 0.0, dyn.energy(self.y))
                if energy.max() > 0:
                    self.next_primary = int(np.argmax(energy))

    def run(self) -> LZBRecord:
        """Integrate piece by piece until every contact is open."""
        dyn, rec = self.dyn, self.record
        try:
            while True:
                gamma = dyn.gamma(self.P)
                spent = dyn.plastic & (gamma > 0) & (self.y > 0)  # plastic, past compression
                self.D[spent] += dyn.energy(self.y)[spent]
                self.y[spent] = 0.0
                energy = dyn.energy(self.y)
                frozen = (self.y <= 0) & (gamma > -0.5 * VELOCITY_LEVEL)
                if np.all(gamma > -VELOCITY_LEVEL) and np.all(energy <= END_ENERGY):
                    break
                self.level = self._level(gamma)
                self.in_time |= energy.max() < 0.5 * self.level
                k = self.next_primary if self.next_primary is not None else \
                    int(np.argmax(energy)) if np.any(energy > 0) else int(np.argmin(gamma))
                self.next_primary = None
                rec.primary_switches += self.primary is not None and k != self.primary
                self.primary = k
                rec.primary_contacts.append(k)
                rec.pieces += 1
                if rec.pieces > MAX_PIECES:
                    raise CertificateError(f"the LZB integration did not end within "
                                           f"{MAX_PIECES} pieces")
                before = self.P[k]
                if self.in_time:
                    self.time_piece(frozen)
                else:
                    self.impulse_piece(k, frozen)
                rec.impulse_variable += self.P[k] - before
        except _Budget:
            raise CertificateError(
                f"the LZB integration did not end within {MAX_EVALUATIONS} evaluations (an "
                "elastic impact where no velocity separates every contact, T_C = {0}, never "
                "ends)") from None
        s = dyn.scales
        rec.impulses = self.P * s.impulse
        rec.potential_energy = (self.left + dyn.energy(self.y)) * s.energy
        rec.dissipated = self.D * s.energy
        rec.gamma = dyn.gamma(self.P) * s.velocity
        rec.impulse_variable *= s.impulse
        rec.method = f"DOP853, rtol={self.rtol:g}" if self.step is None else \
            f"fixed step {self.step * s.impulse:g}"
        return rec


def integrate(dyn: LZBDynamics, *, rtol: float, step: float | None) -> LZBRecord:
    """Integrate one multiple impact of the LZB model until every contact is open.

    Parameters
    ----------
    dyn : LZBDynamics
        The impact's contacts, G and γ⁻ (with at least one γ⁻ᵢ < 0).
    rtol : float
        Tolerance of the adaptive solver (dimensionless variables).
    step : float or None
        Fixed step in the primary impulse (physical units), or None for adaptive steps.

    Returns
    -------
    LZBRecord

    Raises
    ------
    CertificateError
        The integration failed or did not end within its budget.
    """
    return _Run(dyn, rtol, step).run()
