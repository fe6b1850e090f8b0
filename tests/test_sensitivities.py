"""Derivatives through time (docs/theory.md §21): Moreau–Jean's discrete map against central
differences of the same map, event-driven's flow against the bouncing ball's closed forms and
central differences of the motion, the adjoint against the tangents, and the kinks."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.errors import InputError
from impactqp.simulation import LinearForce, LinearSystem

G = 9.81


def _final(tr: iq.Trajectory) -> np.ndarray:
    return np.concatenate([tr.q[-1], tr.v[-1]])


def _central(make, x: np.ndarray, d: float = 1e-6) -> np.ndarray:
    """Central differences of the final state of the run ``make(x)``, one column per entry."""
    cols = []
    for j in range(x.size):
        e = np.zeros_like(x)
        e[j] = d
        cols.append((_final(make(x + e)) - _final(make(x - e))) / (2 * d))
    return np.stack(cols, axis=1)


def test_bouncing_ball_flow_and_discrete_map_differ_and_say_so():
    ball = iq.simulation.bouncing_ball(q0=1.0)
    flow = iq.simulate(ball, iq.Newton(0.9), 1.0, scheme="event-driven", h=0.01,
                       sensitivities=("q0",))
    step = iq.simulate(ball, iq.Newton(0.9), 1.0, h=0.0005, sensitivities=("q0",))
    # the motion: q(T) = v⁺(T − t₁) − ½g(T − t₁)², t₁ = √(2q₀/g), v⁺ = e√(2gq₀)
    t1, vp = np.sqrt(2.0 / G), 0.9 * np.sqrt(2.0 * G)
    closed_form = 0.9 * G / np.sqrt(2 * G) * (1 - t1) + (G * (1 - t1) - vp) / (G * t1)
    assert flow.sensitivity_kind == "flow" and step.sensitivity_kind == "discrete-map"
    assert flow.sensitivity("q0")[-1, 0, 0] == pytest.approx(closed_form, rel=1e-9)
    assert flow.sensitivity("q0")[-1, 0, 0] == pytest.approx(1.40797, abs=1e-5)
    assert step.sensitivity("q0")[-1, 0, 0] == pytest.approx(1.0, abs=1e-12)
    assert flow.sensitivity().shape == (flow.t.size, 2, 1)


@pytest.mark.parametrize("k", [1, 2, 3])
def test_apex_after_k_bounces_against_its_closed_form(k):
    e, h0 = 0.9, 1.0
    v = [e ** j * np.sqrt(2 * G * h0) for j in range(1, k + 1)]
    apex = np.sqrt(2 * h0 / G) + sum(2 * vj / G for vj in v[:-1]) + v[-1] / G
    tr = iq.simulate(iq.simulation.bouncing_ball(q0=h0), iq.Newton(e), apex,
                     scheme="event-driven", h=0.05, sensitivities=("q0", "e"))
    assert tr.q[-1, 0] == pytest.approx(e ** (2 * k) * h0, rel=1e-9)
    assert tr.sensitivity("e")[-1, 0, 0] == pytest.approx(2 * k * e ** (2 * k - 1) * h0,
                                                           rel=1e-7)
    assert tr.sensitivity("q0")[-1, 0, 0] == pytest.approx(e ** (2 * k), rel=1e-7)
    assert tr.kinks == []


def _cradle(q0: np.ndarray) -> LinearSystem:
    base = iq.simulation.cradle_system(3, amplitude=0.1)
    return LinearSystem(base.M, q0, base.v0, base.linear_force, base.H, chain=base.chain)


CASES = [  # (name, x, run(x, **kw)): the law's parameter or the initial state
    ("q0", np.array([1.0]), lambda x, **kw: iq.simulate(
        iq.simulation.bouncing_ball(q0=float(x[0])), iq.Newton(0.9), 1.0, **kw)),
    ("eps", np.array([0.9]), lambda x, **kw: iq.simulate(
        iq.simulation.bouncing_ball(), iq.Moreau(float(x[0])), 1.0, **kw)),
    ("q0", np.array([-0.1, -1e-3, 2e-3]), lambda x, **kw: iq.simulate(
        _cradle(x), iq.Newton(0.8), 1.5, **kw)),
    ("e", np.array([0.8, 0.7]), lambda x, **kw: iq.simulate(
        _cradle(np.array([-0.1, 0, 0])), iq.Newton(x), 1.5, **kw)),
    ("E", np.array([0.8, 0.1, 0.05, 0.7]), lambda x, **kw: iq.simulate(
        _cradle(np.array([-0.1, 0, 0])), iq.Fremond(x.reshape(2, 2)), 1.5, **kw)),
]


@pytest.mark.parametrize("name, x, run", CASES)
@pytest.mark.parametrize("scheme, h", [("moreau-jean", 1e-3), ("event-driven", 0.01)])
def test_sensitivities_equal_central_differences(name, x, run, scheme, h):
    tr = run(x, scheme=scheme, h=h, sensitivities=(name,))
    fd = _central(lambda y: run(y, scheme=scheme, h=h), x)
    S = tr.sensitivity(name)[-1]
    assert np.abs(S - fd).max() <= 1e-6 * max(1.0, np.abs(fd).max())
    assert np.abs(fd).max() > 1e-3  # the run does depend on it


@pytest.mark.parametrize("scheme, h", [("moreau-jean", 1e-3), ("event-driven", 0.01)])
def test_adjoint_is_the_transposed_chain(scheme, h):
    tr = iq.simulate(_cradle(np.array([-0.1, 0.0, 0.0])), iq.Newton([0.8, 0.6]), 2.0,
                     scheme=scheme, h=h, sensitivities=("q0", "v0", "e"))
    rng = np.random.default_rng(3)
    wq, wv = rng.normal(size=tr.q.shape), rng.normal(size=tr.v.shape)
    grads = tr.vjp(q=wq, v=wv)
    S = tr.sensitivity()
    dense = np.einsum("ri,rik->k", np.hstack([wq, wv]), S)
    cols = tr.sensitivities.cols.slices
    for name in ("q0", "v0", "e"):
        assert np.allclose(grads[name], dense[cols[name]], rtol=1e-10, atol=1e-12)
    final = tr.vjp(q=wq[-1])  # a loss on the final state only
    assert np.allclose(final["e"], wq[-1] @ tr.sensitivity("e")[-1, :3], rtol=1e-10)


def test_grazing_and_zeno_are_flagged_never_nan():
    # a spring whose amplitude just reaches the wall: the gap 1 + cos t touches 0 at t = π
    spring = LinearSystem([[1.0]], [1.0], [0.0], LinearForce([[1.0]]), [[1.0]], [1.0])
    tr = iq.simulate(spring, iq.Newton(0.9), 5.0, scheme="event-driven", h=0.01,
                     sensitivities=("q0", "v0", "e"))
    assert [k.kind for k in tr.kinks] == ["grazing"]
    assert tr.kinks[0].time == pytest.approx(np.pi, abs=0.01)
    assert np.isfinite(tr.sensitivity()).all()
    # a bouncing ball comes to rest after t∞ = t₁(1 + 2e/(1 − e)) = 8.579 s
    ball = iq.simulate(iq.simulation.bouncing_ball(), iq.Newton(0.9), 12.0,
                       scheme="event-driven", h=0.01, sensitivities=("q0", "v0", "e"))
    zeno = [k for k in ball.kinks if k.kind == "zeno"]
    assert len(zeno) == 1 and zeno[0].time == pytest.approx(np.sqrt(2 / G) * 19, rel=1e-3)
    assert np.isfinite(ball.sensitivity()).all()
    assert np.all(ball.sensitivity()[-1] == 0.0)  # at rest: q(T) = 0 whatever the data
    step = iq.simulate(iq.simulation.bouncing_ball(), iq.Newton(0.9), 12.0, h=1e-3,
                       sensitivities=("q0", "v0", "e"))
    assert np.isfinite(step.sensitivity()).all() and np.isfinite(step.sensitivities.margin)


def test_activation_threshold_is_a_kink_of_the_discrete_map():
    # balls 2 and 3 touch at rest: g + ½hγ = 0 exactly, every step
    tr = iq.simulate(_cradle(np.array([-0.1, 0.0, 0.0])), iq.Newton(0.8), 0.2, h=1e-3,
                     sensitivities=("q0",))
    assert any(k.kind == "activation" and k.contacts == (1,) for k in tr.kinks)
    # and Λ₂ = 0 = w₂ in the step's LCP: a degenerate contact too
    assert any(k.kind == "degenerate" and k.contacts == (1,) for k in tr.kinks)
    assert all(type(k.time) is float for k in tr.kinks)
    assert tr.sensitivities.margin == 0.0


@pytest.mark.parametrize("law, kw, match", [
    (iq.SectorLaw(), {}, "complementarity"),
    (iq.Newton(0.9), {"sensitivities": ("q0", "mu")}, "distinct names"),
    (iq.Newton(0.9), {"sensitivities": "q0"}, "sequence of names"),
    (iq.Newton(0.9), {"sensitivities": ("q0", "q0")}, "distinct names"),
    (iq.Newton(0.9), {"sensitivities": ("q0",), "record_every": 2}, "record_every"),
])
def test_what_cannot_be_differentiated_is_refused_by_name(law, kw, match):
    kw = {"sensitivities": ("q0",), **kw}
    with pytest.raises(InputError, match=match):
        iq.simulate(iq.simulation.cradle_system(3), law, 1.0, **kw)


def test_callable_force_and_missing_sensitivities_are_refused():
    ball = LinearSystem([[1.0]], [1.0], [0.0], lambda t, q, v: np.array([-G]), [[1.0]])
    with pytest.raises(InputError, match="callable force"):
        iq.simulate(ball, iq.Newton(0.9), 1.0, sensitivities=("q0",))
    block = iq.simulation.block_on_incline(0.3, dim=2, speed=1.0)
    frictional = iq.simulate(block, iq.Coulomb(0.5, 0.0), 0.05, h=1e-2, sensitivities=("q0",))
    assert frictional.sensitivity_kind == "discrete-map"  # tests/test_sensitivity_coulomb.py
    tr = iq.simulate(iq.simulation.bouncing_ball(), iq.Newton(0.9), 0.1)
    assert tr.sensitivity_kind is None
    with pytest.raises(InputError, match="no sensitivities"):
        tr.vjp(q=[1.0])


def test_flow_jump_in_e_is_the_single_impact_derivative():
    """Before the first impact nothing depends on e, so across it ∂v/∂e jumps by ∂u⁺/∂e of
    that impact: the flow's LCP tangent against the impact's own certified derivative."""
    tr = iq.simulate(iq.simulation.cradle_system(3), iq.Newton(0.8), 1.0,
                     scheme="event-driven", h=0.01, sensitivities=("e",))
    event = tr.events[0]
    r = int(np.flatnonzero(tr.t == event.time)[-1])  # the post-impact record
    assert tr.t[r - 1] == event.time and np.all(tr.sensitivity("e")[r - 1] == 0.0)
    expected = event.result.derivative().jacobian("e")
    assert np.allclose(tr.sensitivity("e")[r, 3:, 0], expected, rtol=1e-10, atol=1e-12)
    assert np.abs(expected).max() > 0.1


def test_a_contact_closed_at_the_start_is_a_kink_of_the_flow():
    # balls 2 and 3 of the cradle touch at rest at t = 0
    tr = iq.simulate(_cradle(np.array([-0.1, 0.0, 0.0])), iq.Newton(0.8), 1.0,
                     scheme="event-driven", h=0.01, sensitivities=("q0",))
    assert tr.kinks[0] == (0.0, "degenerate", (1,), 0.0)
    assert tr.sensitivities.margin == 0.0 and np.isfinite(tr.sensitivity()).all()
    kinds = {k.kind for k in tr.kinks}
    assert kinds <= {"activation", "degenerate", "grazing", "zeno", "simultaneous"}


@pytest.mark.parametrize("law", [iq.Newton([0.8, 0.6]), iq.Fremond([[0.8, 0.1], [0.05, 0.7]])])
def test_both_loops_give_the_same_discrete_map_derivative(law):
    """The compiled loop and the Python loop (a named backend) record the same steps, so the
    derivative read back from either is the same."""
    system = iq.simulation.cradle_system(3, amplitude=0.1)
    wrt = ("q0", "v0", law.coefficient_key)
    compiled = iq.simulate(system, law, 0.8, h=1e-3, sensitivities=wrt)
    python = iq.simulate(system, law, 0.8, h=1e-3, sensitivities=wrt, backend="exact")
    assert (compiled.settings["loop"], python.settings["loop"]) == ("compiled", "python")
    assert np.allclose(compiled.sensitivity(), python.sensitivity(), rtol=1e-9, atol=1e-12)
    assert np.abs(compiled.sensitivity(law.coefficient_key)).max() > 0.01


def test_the_cost_benchmark_runs():
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from benchmarks.sensitivities import timings

    result = timings("moreau-jean", 200, 2)
    assert result["ratio (medians)"] > 0 and result["plain fastest s"] > 0
