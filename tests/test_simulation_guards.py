"""Simulations refuse runs they cannot represent up front and never return a non-finite
state as a result."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq

SCHEMES = ["moreau-jean", "event-driven"]


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("t_end, h", [(10.0, 1e-12), (10.0, 1e-300), (1e308, 1.0),
                                      (1e308, None)])
def test_too_many_steps_are_refused_before_running(scheme, t_end, h):
    if h is None:  # the default h = t_end/1000 is fine; t0 = -1e308 makes the span overflow
        with pytest.raises(iq.InputError, match="too small"):
            iq.simulate(iq.simulation.bouncing_ball(), iq.Newton(0.9), t_end, scheme=scheme,
                        t0=-1e308, h=1e300)
        return
    with pytest.raises(iq.InputError, match="too small for t_end"):
        iq.simulate(iq.simulation.bouncing_ball(), iq.Newton(0.9), t_end, scheme=scheme, h=h)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_a_force_that_turns_nan_stops_the_run_with_its_time(scheme):
    def force(t, q, v):
        return np.array([-9.81 if t < 0.2 else np.nan])

    system = iq.LinearSystem([[1.0]], [1.0], [0.0], force, [[1.0]], [0.0])
    with pytest.raises(iq.SolverError) as info:
        iq.simulate(system, iq.Newton(0.9), 1.0, scheme=scheme, h=1e-3)
    assert "t = 0.2" in str(info.value)


def test_motion_beyond_the_float_range_is_a_named_error():
    system = iq.LinearSystem([[1.0]], [1.0], [1e300], [1e300], [[1.0]], [0.0])
    with pytest.raises(iq.errors.NonFiniteStateError, match="not finite at t ="):
        iq.simulate(system, iq.Newton(0.9), 1e10, scheme="moreau-jean", h=1e7)


def test_a_ball_at_rest_stays_finite_for_any_length_of_time():
    tr = iq.simulate(iq.simulation.bouncing_ball(), iq.Newton(0.9), 1e300, scheme="event-driven")
    assert np.isfinite(tr.q).all() and abs(tr.q[-1, 0]) < 1e-9 and tr.t[-1] == 1e300


def test_energy_beyond_the_floats_is_said_not_checked():
    """q and v stay finite under gravity 1e200 while ½v² overflows: the summary says the
    energy is beyond the floats instead of printing 'nan' beside 'certificates: all ok'."""
    import warnings

    from impactqp.simulation import bouncing_ball

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # the summary raises no overflow warning
        run = iq.simulate(bouncing_ball(gravity=1e200), iq.Newton(0.9), 1.0, h=0.01)
        assert np.all(np.isfinite(run.q)) and np.all(np.isfinite(run.v))
        text = run.summary()
    assert "energy: beyond the floats" in text and "nan" not in text
    calm = iq.simulate(bouncing_ball(), iq.Newton(0.9), 1.0, h=0.01).summary()
    assert "largest relative change" in calm and "beyond the floats" not in calm
