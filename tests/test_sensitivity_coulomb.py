"""Sensitivities through time of Moreau–Jean runs with Coulomb friction (docs/theory.md §21):
the discrete map's derivative against central differences of the same map (a sphere thrown
with spin onto a floor, a block sliding across an incline in space, a box on four corners),
∂/∂μ exactly 0 while rolling or flying, a stick→slide threshold flagged with its one-sided
derivatives, steps the law leaves undetermined flagged, the adjoint against the tangents,
and what is refused."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.errors import InputError
from impactqp.simulation import LinearForce, LinearSystem
from impactqp.simulation.contact_states import contact_states

NAMES = ("q0", "v0", "mu", "restitution")


def _final(tr: iq.Trajectory) -> np.ndarray:
    return np.concatenate([tr.q[-1], tr.v[-1]])


def _central(run, data: dict, name: str, d: float = 1e-6) -> np.ndarray:
    """Central differences of the final state of ``run(data)`` in each entry of data[name]."""
    cols = []
    for j in range(data[name].size):
        step = np.zeros_like(data[name])
        step[j] = d
        plus, minus = dict(data), dict(data)
        plus[name], minus[name] = data[name] + step, data[name] - step
        cols.append((_final(run(plus)) - _final(run(minus))) / (2 * d))
    return np.stack(cols, axis=1)


THROWN = {"q0": np.array([0.0, 0.3, 0.0]), "v0": np.array([1.0, -1.0, 20.0]),
          "mu": np.array([0.1]), "restitution": np.array([0.5])}
"""A sphere (radius 0.1) thrown down at 1 m/s with backspin 20 rad/s onto a floor: it
bounces sliding, slides, then rolls."""


def _thrown(data: dict, **kw) -> iq.Trajectory:
    base = iq.simulation.rolling_sphere()
    system = LinearSystem(base.M, data["q0"], data["v0"], base.constant_force, base.H,
                          base.b, contact_dim=2)
    law = iq.Coulomb(float(data["mu"][0]), float(data["restitution"][0]))
    return iq.simulate(system, law, 1.5, h=1e-3, **kw)


def test_the_thrown_sphere_bounces_slides_and_rolls():
    codes, names = contact_states(_thrown(THROWN))
    assert names == ("open", "stick", "slide")
    closed = codes[codes[:, 0] > 0, 0]
    assert (closed == 2).sum() > 100 and (closed == 1).sum() > 100  # slides, then rolls
    assert codes[-1, 0] == 1 and np.count_nonzero(np.diff((codes[:, 0] > 0).astype(int))) > 6


@pytest.mark.parametrize("name", NAMES)
def test_thrown_sphere_equals_central_differences_of_the_discrete_map(name):
    tr = _thrown(THROWN, sensitivities=NAMES)
    assert tr.sensitivity_kind == "discrete-map" and tr.kinks == []
    assert tr.sensitivities.margin > 0.0
    fd = _central(_thrown, THROWN, name)
    S = tr.sensitivity(name)[-1]
    assert np.abs(fd).max() > 1e-2  # the run does depend on it
    assert np.abs(S - fd).max() <= 1e-6 * max(1.0, np.abs(fd).max())


@pytest.mark.parametrize("mass", [1e-12, 1e12])
def test_the_derivative_and_its_kinks_do_not_depend_on_the_unit_of_mass(mass):
    """Under gravity and friction the motion is the same for every mass, and so are its
    derivative and the modes read in contact units."""
    def run(data: dict, **kw) -> iq.Trajectory:
        base = iq.simulation.rolling_sphere(mass=mass)
        system = LinearSystem(base.M, data["q0"], data["v0"], base.constant_force, base.H,
                              base.b, contact_dim=2)
        law = iq.Coulomb(float(data["mu"][0]), float(data["restitution"][0]))
        return iq.simulate(system, law, 1.5, h=1e-3, **kw)

    tr, unit = run(THROWN, sensitivities=NAMES), _thrown(THROWN, sensitivities=NAMES)
    assert tr.kinks == [] and tr.sensitivities.margin == pytest.approx(
        unit.sensitivities.margin, rel=1e-6)
    assert np.abs(tr.sensitivity() - unit.sensitivity()).max() <= 1e-8 * np.abs(
        unit.sensitivity()).max()


def test_both_frictional_loops_give_the_same_derivative():
    compiled = _thrown(THROWN, sensitivities=NAMES)
    python = _thrown(THROWN, sensitivities=NAMES, backend="nsgs")
    assert (compiled.settings["loop"], python.settings["loop"]) == ("friction-compiled",
                                                                    "friction")
    S = compiled.sensitivity()
    assert np.abs(python.sensitivity() - S).max() <= 1e-7 * np.abs(S).max()


SLIDING = {"v0": np.array([0.98, 0.7, 0.2]), "mu": np.array([0.3]),
           "restitution": np.array([0.2])}
"""A block on an incline (α = 0.2) in space, sent up the slope and across it: its slip
direction turns as it slides (∂t/∂U_T ≠ 0) until it stops and sticks."""


def _sliding(data: dict, **kw) -> iq.Trajectory:
    base = iq.simulation.block_on_incline(0.2, dim=3, gap=-1e-9, twist=0.3)
    system = LinearSystem(base.M, base.q0, data["v0"], base.constant_force, base.H, base.b,
                          contact_dim=3)
    law = iq.Coulomb(float(data["mu"][0]), float(data["restitution"][0]))
    return iq.simulate(system, law, 0.5, h=1e-3, **kw)


@pytest.mark.parametrize("name", ["v0", "mu"])
def test_sliding_in_space_equals_central_differences(name):
    tr = _sliding(SLIDING, sensitivities=("v0", "mu", "restitution"))
    codes, _ = contact_states(tr)
    assert (codes[1:, 0] == 2).sum() > 100 and codes[-1, 0] == 1  # slides, then stops
    assert tr.kinks == []
    fd = _central(_sliding, SLIDING, name)
    assert np.abs(fd).max() > 1e-2
    assert np.abs(tr.sensitivity(name)[-1] - fd).max() <= 1e-7 * max(1.0, np.abs(fd).max())


def _rolling(height: float | None = None) -> LinearSystem:
    return iq.simulation.rolling_sphere(velocity=1.0, spin=-10.0, gap=-1e-9, height=height)


def test_mu_derivative_is_exactly_zero_while_rolling_or_flying():
    rolling = iq.simulate(_rolling(), iq.Coulomb(0.3, 0.5), 0.5, h=1e-3,
                          sensitivities=("q0", "v0", "mu", "restitution"))
    slip = rolling.v @ _rolling().H[:, 1]
    assert (rolling.impulses[1:, 0] > 0).all() and np.abs(slip).max() <= 1e-12  # it sticks
    assert np.all(rolling.sensitivity("mu") == 0.0)
    assert np.abs(rolling.sensitivity("v0")).max() > 0.1
    fd = [(_final(iq.simulate(_rolling(), iq.Coulomb(mu + 1e-6, 0.5), 0.5, h=1e-3))
           - _final(iq.simulate(_rolling(), iq.Coulomb(mu - 1e-6, 0.5), 0.5, h=1e-3))) / 2e-6
          for mu in (0.3,)]
    assert np.abs(fd[0]).max() <= 1e-8
    flying = iq.simulate(_rolling(height=2.0), iq.Coulomb(0.3, 0.5), 0.5, h=1e-3,
                         sensitivities=("mu", "restitution", "q0"))
    assert flying.events == [] and flying.kinks == []
    assert np.all(flying.sensitivity("mu") == 0.0)
    assert np.all(flying.sensitivity("restitution") == 0.0)


def _spring_sphere() -> LinearSystem:
    """A rolling sphere pulled back by a horizontal spring: the friction it needs to roll
    grows with its distance, until it slides."""
    base = iq.simulation.rolling_sphere()
    force = LinearForce(np.diag([20.0, 0.0, 0.0]), [0.0, -9.81, 0.0])
    return LinearSystem(base.M, [0.0, 0.1 - 1e-9, 0.0], [1.0, 0.0, -10.0], force, base.H,
                        base.b, contact_dim=2)


def test_a_step_on_the_stick_slide_threshold_is_a_kink_with_one_sided_derivatives():
    def run(mu: float, **kw) -> iq.Trajectory:
        return iq.simulate(_spring_sphere(), iq.Coulomb(mu, 0.0), 0.3, h=1e-3, **kw)

    ratio = np.abs(run(10.0).impulses[1:, 1]) / run(10.0).impulses[1:, 0]
    assert np.all(np.diff(ratio[:250]) > 0)  # the grip it needs grows, step after step
    mu = float(ratio[149])  # μ of the step ending at t = 0.15: on the edge of its cone
    tr = run(mu, sensitivities=("q0", "v0", "mu"))
    assert [(k.kind, k.contacts) for k in tr.kinks] == [("stick-slide", (0,))]
    assert tr.kinks[0].time == pytest.approx(0.15, abs=1e-12)
    assert tr.sensitivities.margin == 0.0 and np.isfinite(tr.sensitivity()).all()
    codes, _ = contact_states(tr)
    assert (codes[1:150, 0] == 1).all() and (codes[151:, 0] == 2).all()  # stick → slide
    d = 1e-7
    ahead = (_final(run(mu + d)) - _final(tr)) / d  # the step sticks
    behind = (_final(tr) - _final(run(mu - d))) / d  # the step slides
    S = tr.sensitivity("mu")[-1, :, 0]
    assert np.abs(S - ahead).max() <= 1e-5 * np.abs(ahead).max()  # the mode it was read in
    assert np.abs(ahead - behind).max() > 1e-3 * np.abs(ahead).max()
    for nearby in (mu - 1e-3, mu + 1e-3):  # crossing between steps: no kink
        assert run(nearby, sensitivities=("mu",)).kinks == []


BOX = iq.simulation.box_on_floor(dim=3, velocity=(1.0, 0.5), gap=-1e-9)
"""A box sliding flat on its four lower corners (twelve contact rows, six dofs)."""


def _box(data: dict, **kw) -> iq.Trajectory:
    system = LinearSystem(BOX.M, BOX.q0, data["v0"], BOX.constant_force, BOX.H, BOX.b,
                          contact_dim=3)
    return iq.simulate(system, iq.Coulomb(0.3, 0.0), 0.3, h=1e-3, **kw)


def test_redundant_contacts_differentiated_or_flagged():
    # sliding flat: how the weight splits over the corners is not fixed, the motion is
    flat = {"v0": BOX.v0}
    tr = _box(flat, sensitivities=("v0",))
    assert tr.kinks == []
    fd = _central(_box, flat, "v0")
    assert np.abs(tr.sensitivity("v0")[-1] - fd).max() <= 1e-7 * np.abs(fd).max()
    # sliding and spinning: the split sets the friction's torque, which the law leaves open
    spinning = _box({"v0": BOX.v0 + np.array([0, 0, 0, 0, 0, 0.3])}, sensitivities=("v0",))
    kinks = spinning.kinks
    assert kinks and {k.kind for k in kinks} == {"indeterminate"}
    assert kinks[0].contacts == (0, 1, 2, 3) and np.isfinite(spinning.sensitivity()).all()
    assert spinning.sensitivities.margin == 0.0


def test_adjoint_is_the_transposed_chain():
    tr = _thrown(THROWN, sensitivities=NAMES)
    rng = np.random.default_rng(5)
    wq, wv = rng.normal(size=tr.q.shape), rng.normal(size=tr.v.shape)
    grads = tr.vjp(q=wq, v=wv)
    dense = np.einsum("ri,rik->k", np.hstack([wq, wv]), tr.sensitivity())
    for name in NAMES:
        part = dense[tr.sensitivities.cols.slices[name]]
        assert np.allclose(np.atleast_1d(grads[name]), part, rtol=1e-10, atol=1e-12)
    final = tr.vjp(q=wq[-1], v=wv[-1])  # a loss on the final state
    S = tr.sensitivity()[-1]
    for name in NAMES:
        expected = np.concatenate([wq[-1], wv[-1]]) @ S[:, tr.sensitivities.cols.slices[name]]
        assert np.allclose(np.atleast_1d(final[name]), expected, rtol=1e-10, atol=1e-12)
    assert isinstance(final["mu"], float) and final["q0"].shape == (3,)


SPUN = {"mu": np.array([0.2, 0.4]), "restitution": np.array([0.1, 0.3])}
"""One μ and one e per corner of a box in the plane, dropped sliding and turning."""


def _spun(data: dict, **kw) -> iq.Trajectory:
    base = iq.simulation.box_on_floor(dim=2, velocity=1.0, gap=0.05)
    system = LinearSystem(base.M, base.q0, base.v0 + np.array([0.0, 0.0, 1.0]),
                          base.constant_force, base.H, base.b, contact_dim=2)
    return iq.simulate(system, iq.Coulomb(data["mu"], data["restitution"]), 0.4, h=1e-3,
                       **kw)


@pytest.mark.parametrize("name", ["mu", "restitution"])
def test_per_contact_coefficients_have_one_column_each(name):
    tr = _spun(SPUN, sensitivities=("mu", "restitution"))
    assert tr.sensitivity(name).shape == (tr.t.size, 6, 2)
    grads = tr.vjp(q=np.ones(3))
    assert grads["mu"].shape == (2,) and grads["restitution"].shape == (2,)
    # where the box stops, one corner's grip saturates and the other holds the rest
    assert {k.kind for k in tr.kinks} == {"stick-slide"}
    fd = _central(_spun, SPUN, name)
    assert np.abs(fd).max() > 0.05
    assert np.abs(tr.sensitivity(name)[-1] - fd).max() <= 1e-7 * np.abs(fd).max()


@pytest.mark.parametrize("kw, match", [
    ({"scheme": "event-driven"}, "no Coulomb friction"),
    ({"sensitivities": ("q0", "e")}, "distinct names"),
    ({"sensitivities": ("mu", "mu")}, "distinct names"),
    ({"record_every": 2}, "record_every"),
])
def test_what_cannot_be_differentiated_is_refused_by_name(kw, match):
    kw = {"sensitivities": ("q0", "mu"), **kw}
    with pytest.raises(InputError, match=match):
        iq.simulate(iq.simulation.rolling_sphere(), iq.Coulomb(0.3, 0.5), 0.1, **kw)


def test_the_flow_of_a_frictional_run_is_refused_by_name():
    from impactqp.simulation.through_time import check

    system = iq.simulation.rolling_sphere()
    with pytest.raises(InputError, match="discrete map"):
        check(system, iq.Coulomb(0.3), "event-driven", ("q0",), {})
