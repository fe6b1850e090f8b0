"""Event-driven integration: phases under a constant force flown in closed form against the
ODE path, and grazing impacts of oscillating systems against their closed forms
(docs/theory.md §14)."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.simulation.smooth import first_closing


def _as_callable(system: iq.LinearSystem) -> iq.LinearSystem:
    """The same system with its constant force given as a callable (the ODE path)."""
    f = system.constant_force.copy()
    return iq.LinearSystem(system.M, system.q0, system.v0, lambda t, q, v: f, system.H,
                           system.b, chain=system.chain)


@pytest.mark.parametrize("system, law", [
    (iq.simulation.bouncing_ball(q0=1.0), iq.Newton(0.9)),
    (iq.simulation.bouncing_ball(mass=3.0, q0=0.2, v0=1.5, gravity=1.62, radius=0.05),
     iq.Newton(0.5)),
])
def test_exact_flight_matches_the_ode_path(system, law):
    exact = iq.simulate(system, law, 10.0, scheme="event-driven")
    ode = iq.simulate(_as_callable(system), law, 10.0, scheme="event-driven")
    t_exact = np.array([e.time for e in exact.events])
    t_ode = np.array([e.time for e in ode.events])
    assert t_exact.size == t_ode.size > 10
    np.testing.assert_allclose(t_exact, t_ode, rtol=1e-9)
    np.testing.assert_allclose(exact.q[-1], ode.q[-1], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(exact.v[-1], ode.v[-1], atol=1e-9)
    assert all(e.certified for e in exact.events)


@pytest.mark.parametrize("n, law", [(3, iq.Newton(0.8)), (4, iq.Moreau(0.5))])
def test_exact_flight_of_a_bead_column_starts_like_the_ode_path(n, law):
    """A falling column's micro-impacts are sensitive to round-off after a few events; its
    first ones agree."""
    system = iq.simulation.bead_chain(n)
    exact = iq.simulate(system, law, 0.45, scheme="event-driven")
    ode = iq.simulate(_as_callable(system), law, 0.45, scheme="event-driven")
    for a, b in zip(exact.events[:3], ode.events[:3]):
        assert a.time == pytest.approx(b.time, rel=1e-10)
        np.testing.assert_array_equal(a.contacts, b.contacts)
        np.testing.assert_allclose(a.u_plus, b.u_plus, rtol=1e-8, atol=1e-10)


def test_a_falling_ball_lands_when_the_closed_form_says():
    q0, g, e = 1.0, 9.81, 0.9
    tr = iq.simulate(iq.simulation.bouncing_ball(q0=q0, gravity=g), iq.Newton(e), 3.5,
                     scheme="event-driven")
    t1 = np.sqrt(2 * q0 / g)
    k = np.arange(1, 6)
    expected = t1 + (2 * g * t1 / g) * e * (1 - e ** (k - 1)) / (1 - e)
    np.testing.assert_allclose([ev.time for ev in tr.events[:5]], expected, rtol=1e-14)


def test_first_closing_is_the_first_downward_root():
    rng = np.random.default_rng(3)
    for _ in range(200):
        m = 6
        g, gamma = rng.uniform(0, 1, m), rng.normal(size=m)
        alpha, near = rng.normal(size=m) * 5, rng.random(m) < 0.3
        tau = first_closing(g, gamma, alpha, near)
        g0 = np.where(near, 0.0, g)
        s = np.linspace(0, 50, 200_001)[1:]
        path = g0[:, None] + gamma[:, None] * s + 0.5 * alpha[:, None] * s**2
        below = np.nonzero((path <= 0).any(axis=0))[0]
        if near.any() and (gamma[near] < 0).any():
            assert tau == 0.0
        elif below.size == 0:
            assert tau > 50 or np.isinf(tau)
        else:
            assert s[below[0] - 1] <= tau <= s[below[0]] + 1e-12


@pytest.mark.parametrize("m, k, c", [(1.0, 4.0, 2.0), (2.0, 50.0, 3.0), (1e-3, 1e3, 1.0)])
@pytest.mark.parametrize("v0", [0.3, 0.0175, 1e-3, 1e-4])
def test_grazing_impacts_are_found(m, k, c, v0):
    """A mass on a spring that presses it towards a wall it starts at, leaving slowly: the
    gap dips below zero for a short while near every return, which the sign test at the
    integrator's steps alone misses. q(t) = (c/k)(1 − cos ωt) + (v₀/ω) sin ωt returns at
    t₁ = (2/ω)(π − arctan(v₀k/(ωc))), and with e = 1 every t₁ after."""
    w = np.sqrt(k / m)
    t1 = (2 / w) * (np.pi - np.arctan(v0 * k / (w * c)))
    system = iq.LinearSystem([[m]], [0.0], [v0], iq.LinearForce([[k]], [c]), [[1.0]], [0.0])
    tr = iq.simulate(system, iq.Newton(1.0), 3.5 * t1, scheme="event-driven")
    np.testing.assert_allclose([e.time for e in tr.events], t1 * np.arange(1, 4), rtol=1e-8)
    assert tr.q.min() > -1e-12 * c / k  # never inside the wall


@pytest.mark.parametrize("scale", [1e-9, 1e-3, 1e3, 1e6])
def test_the_same_motion_in_other_units_has_the_same_events(scale):
    """A ball dropped from q₀ = s under the same g: lengths scale by s, times by √s,
    velocities by √s; the default thresholds follow the system's own scales."""
    unit = iq.simulate(iq.simulation.bouncing_ball(q0=1.0), iq.Newton(0.9), 10.0,
                       scheme="event-driven")
    scaled = iq.simulate(iq.simulation.bouncing_ball(q0=scale), iq.Newton(0.9),
                         10.0 * np.sqrt(scale),
                         scheme="event-driven")
    assert len(scaled.events) == len(unit.events) > 100
    np.testing.assert_allclose(scaled.impact_times / np.sqrt(scale), unit.impact_times,
                               rtol=1e-12)
    assert scaled.certified


@pytest.mark.parametrize("length", [1e-3, 1e3])
def test_a_cradle_in_other_length_units_has_the_same_events(length):
    """Newton's cradle with lengths (amplitude and pendulum) in other units: the same
    impacts at the same times (the period √(L/g) scales with L)."""
    unit = iq.simulate(iq.simulation.cradle_system(3, amplitude=0.1), iq.SectorLaw(), 3.0,
                       scheme="event-driven")
    other = iq.simulate(iq.simulation.cradle_system(3, amplitude=0.1 * length, length=length,
                                         gravity=9.81 * length), iq.SectorLaw(), 3.0,
                        scheme="event-driven")
    np.testing.assert_allclose(other.impact_times, unit.impact_times, rtol=1e-9)
    np.testing.assert_allclose(other.q[-1] / length, unit.q[-1], rtol=1e-7, atol=1e-12)
