"""The backend a result reports is a backend the same call takes back, and that call gives
the same answer: every built-in law, a user's closed form, solve_friction and a frictional
simulation (issue 25, "the name a result reports is a name the caller can pass back")."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.errors import BackendUnsuitableError
from impactqp.laws.coulomb import Coulomb
from impactqp.laws.friction import FRICTION_BACKENDS
from impactqp.simulation.builders import box_on_floor
from impactqp.simulation.friction_loop import LOOP_BACKEND
from impactqp.simulation.simulate import simulate


class Sorted(iq.ImpactLaw):
    """A user's law of one closed form."""

    def closed_form(self, problem):
        return np.sort(problem.u_minus)


LAWS = {
    "moreau": lambda: iq.Moreau(0.5),
    "newton": lambda: iq.Newton(0.5),
    "fremond": lambda: iq.Fremond(0.5 * np.eye(2)),
    "sector": iq.SectorLaw,
    "reflection": iq.ReflectionLaw,
    "lzb": lambda: iq.LZB(1e6),
    "user": Sorted,
}


def _cradle(moving: bool) -> iq.ImpactProblem:
    p = iq.newtons_cradle(3, 1.0)
    return p if moving else p.with_u_minus(np.zeros(p.n_dof))


@pytest.mark.parametrize("moving", [True, False], ids=["impact", "at-rest"])
@pytest.mark.parametrize("name", LAWS)
def test_each_law_takes_back_the_backend_it_reports(name, moving):
    law, p = LAWS[name](), _cradle(moving)
    first = iq.solve(p, law)
    again = iq.solve(p, law, backend=first.backend)
    assert again.backend == first.backend and again.certificate.ok
    np.testing.assert_allclose(again.u_plus, first.u_plus, rtol=0, atol=1e-12)
    np.testing.assert_allclose(again.impulses, first.impulses, rtol=0, atol=1e-12)


def test_coulomb_takes_back_the_backend_it_reports():
    p = iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0])
    first = iq.solve(p, iq.Coulomb(0.3))
    again = iq.solve(p, iq.Coulomb(0.3), backend=first.backend)
    assert again.backend == first.backend and again.certificate.ok
    np.testing.assert_allclose(again.u_plus, first.u_plus, rtol=0, atol=1e-10)


@pytest.mark.parametrize("name", ["moreau", "sector", "user"])
def test_none_answers_only_the_impact_at_rest(name):
    """``"none"`` (u⁺ = u⁻, Λ = 0) is refused by name where u⁻ ≠ 0: it never answers a moving
    impact with a wrong u⁺."""
    with pytest.raises(BackendUnsuitableError, match="'none'"):
        iq.solve(_cradle(True), LAWS[name](), backend="none")


@pytest.mark.parametrize("scale", [1.0, 1e-8, 1e8])
def test_solve_friction_takes_back_the_backend_it_reports(scale):
    W = scale * np.array([[1.0, 0.1, 0.0], [0.1, 2.0, 0.0], [0.0, 0.0, 2.0]])
    p = iq.FrictionContactProblem(W, np.array([-1.0, 0.5, 0.0]), 0.3)
    first = iq.solve_friction(p)
    again = iq.solve_friction(p, backend=first.backend)
    assert again.backend == first.backend and again.certificate.ok
    np.testing.assert_allclose(again.r, first.r, rtol=1e-8, atol=0)


def test_a_frictional_simulation_takes_back_the_backend_its_events_report():
    """The compiled loop reports the registry's NSGS, whose sweeps it runs; simulating with
    that backend (the Python loop, each step through solve_friction) gives the same run."""
    system = box_on_floor(3, velocity=(2.0, 1.0), gap=0.02)
    first = simulate(system, Coulomb(0.4, 0.3), 0.1, h=1e-3)
    names = {ev.result.backend for ev in first.events}
    assert first.settings["loop"] == "friction-compiled" and LOOP_BACKEND in names
    assert first.events and names <= set(FRICTION_BACKENDS)
    for name in names:
        again = simulate(system, Coulomb(0.4, 0.3), 0.1, h=1e-3, backend=name)
        assert again.certified and len(again.events) == len(first.events)
        assert {ev.result.backend for ev in again.events} == {name}
        assert np.abs(again.v - first.v).max() < 1e-8
        assert np.abs(again.q - first.q).max() < 1e-8
