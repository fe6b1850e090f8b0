"""What a law can do is declared on its class (``family``, ``restitution_per_contact``,
``frictional``, ``compliant``) and read by every fast path; a user's law that declares a
family takes the fast paths and is answered exactly as the built-in law, one that does not
takes the general path. And the one :class:`~impactqp.laws.planner.Route` the planner gives
``solve``, ``solve_batch`` and ``simulate``."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import impactqp as iq
from impactqp.laws.base import COMPLEMENTARITY_FAMILY, MOREAU_FAMILY
from impactqp.laws.catalogue import FRICTIONAL_LAWS, LAWS
from impactqp.laws.planner import Route, Stepping, plan
from impactqp.simulation.routing import compiled_applies, plan_run

COMPILED = "kernel (compiled): certified"
"""The attempts of an impact answered by the compiled single-impact path."""


class DeclaredNewton(iq.Newton):
    """A user's local Newton law that says it is of the complementarity family."""

    family = COMPLEMENTARITY_FAMILY
    restitution_per_contact = True


class PlainNewton(iq.Newton):
    """A user's subclass that says nothing: it may have changed the law."""


class DeclaredMoreau(iq.Moreau):
    family = MOREAU_FAMILY
    restitution_per_contact = True


class PlainMoreau(iq.Moreau):
    pass


def test_built_in_laws_declare_their_capabilities():
    declared = {law.name: (law.family, law.restitution_per_contact, law.frictional,
                           law.compliant) for law in (*LAWS, *FRICTIONAL_LAWS)}
    assert declared == {
        "moreau": ("moreau", True, False, False),
        "newton": ("complementarity", True, False, False),
        "fremond": ("complementarity", False, False, False),
        "sector": (None, False, False, False),
        "reflection": (None, False, False, False),
        "lzb": (None, False, False, True),
        "coulomb": (None, False, True, False),
    }
    # declared per class: a subclass that does not say so is of no family
    assert PlainNewton.family is None and not PlainNewton.restitution_per_contact
    assert PlainMoreau.family is None and iq.ImpactLaw.family is None


def test_a_declared_user_law_is_solved_exactly_as_the_built_in_one():
    p = iq.random_impact(6, 4, seed=3)
    e = [0.2, 0.4, 0.6, 0.8]
    built_in, declared, plain = (iq.solve(p, law) for law in
                                 (iq.Newton(e), DeclaredNewton(e), PlainNewton(e)))
    assert built_in.attempts == declared.attempts == [COMPILED]
    np.testing.assert_array_equal(declared.u_plus, built_in.u_plus)
    np.testing.assert_array_equal(declared.impulses, built_in.impulses)
    assert plain.attempts != [COMPILED] and plain.certificate.ok  # the general path
    np.testing.assert_allclose(plain.u_plus, built_in.u_plus, atol=1e-9)
    assert plan(p, DeclaredNewton(e)).path == "compiled"
    assert plan(p, PlainNewton(e)).path == "programs"


def test_a_declared_moreau_law_takes_the_compiled_and_chain_paths():
    p = iq.newtons_cradle(4, 1.0)
    for form, path in (("auto", "isotonic (compiled): certified"), ("impulse", COMPILED)):
        one = iq.solve(p, DeclaredMoreau(0.3), form=form)  # the chain's call, the dense one
        ref = iq.solve(p, iq.Moreau(0.3), form=form)
        assert one.attempts == ref.attempts == [path]
        np.testing.assert_array_equal(one.u_plus, ref.u_plus)
        np.testing.assert_allclose(one.z, ref.z)  # the family's projection
    U = np.random.default_rng(1).standard_normal((50, 4))
    rows = iq.solve_batch(p, DeclaredMoreau(0.3), U)
    same = iq.solve_batch(p, iq.Moreau(0.3), U)
    assert rows.backend == same.backend == "isotonic"
    np.testing.assert_array_equal(rows.u_plus, same.u_plus)
    plain = iq.solve_batch(p, PlainMoreau(0.3), U)
    assert plan(p, PlainMoreau(0.3), mode="batch").path == "programs" and plain.ok.all()
    np.testing.assert_allclose(plain.u_plus, same.u_plus, atol=1e-9)


def test_batches_of_a_declared_law_take_the_compiled_rows():
    p = iq.random_impact(6, 4, seed=1, redundant=1)
    U = np.random.default_rng(5).standard_normal((30, 6))
    e = [0.2, 0.4, 0.6, 0.8]
    declared = iq.solve_batch(p, DeclaredNewton(e), U)
    built_in = iq.solve_batch(p, iq.Newton(e), U)
    np.testing.assert_array_equal(declared.u_plus, built_in.u_plus)
    assert plan(p, DeclaredNewton(e), mode="batch").path == "compiled"
    plain = iq.solve_batch(p, PlainNewton(e), U)  # the programs' vectorised fast path
    assert plan(p, PlainNewton(e), mode="batch").path == "programs" and plain.ok.all()
    np.testing.assert_allclose(plain.u_plus, built_in.u_plus, atol=1e-9)


def test_parallel_contacts_collapse_by_the_declared_restitution():
    W = np.tile([[-1.0], [1.0]], (1, 50))
    W[:, 25:] *= 3.0
    p = iq.ImpactProblem(np.eye(2), W, [1.0, 0.0])
    declared = iq.solve(p, DeclaredNewton(0.5))
    assert "groups of parallel ones" in declared.attempts[0]
    assert plan(p, DeclaredNewton(0.5)).groups is not None
    assert plan(p, PlainNewton(0.5)).groups is None
    assert plan(p, iq.Fremond(0.5 * np.eye(50))).groups is None  # a full E: not per contact
    unequal = np.full(50, 0.5)
    unequal[30] = 0.7  # one member of a group with its own coefficient
    assert plan(p, iq.Newton(unequal)).groups is None
    plain = iq.solve(p, PlainNewton(0.5))
    np.testing.assert_allclose(plain.u_plus, declared.u_plus, atol=1e-9)


def test_simulations_take_the_compiled_loop_by_family():
    ball = iq.simulation.bouncing_ball()
    assert compiled_applies(ball, DeclaredNewton(0.9), "auto")
    assert not compiled_applies(ball, PlainNewton(0.9), "auto")
    fast = iq.simulate(ball, DeclaredNewton(0.9), 0.5, h=0.005)
    slow = iq.simulate(ball, PlainNewton(0.9), 0.5, h=0.005)
    ref = iq.simulate(ball, iq.Newton(0.9), 0.5, h=0.005)
    assert (fast.settings["loop"], slow.settings["loop"]) == ("compiled", "python")
    np.testing.assert_array_equal(fast.q, ref.q)
    np.testing.assert_allclose(slow.q, ref.q, atol=1e-10)


def test_a_family_without_its_methods_or_an_unknown_family_is_refused():
    with pytest.raises(iq.InputError, match="restitution"):
        type("Half", (iq.ImpactLaw,), {"family": COMPLEMENTARITY_FAMILY})
    with pytest.raises(iq.InputError, match="projection"):
        type("HalfMoreau", (iq.Newton,), {"family": MOREAU_FAMILY})
    with pytest.raises(iq.InputError, match="family"):
        type("Fast", (iq.Newton,), {"family": "fast"})


def test_a_compliant_law_is_what_compare_laws_takes():
    class NotCompliant(iq.ImpactLaw):
        def closed_form(self, problem):
            return problem.u_minus

    for law in (iq.Moreau(0.5), NotCompliant()):
        with pytest.raises(iq.InputError, match="compliant"):
            iq.verification.compare_laws(iq.newtons_cradle(3), law)


def test_the_route_of_one_impact_says_units_collapse_and_path():
    p = iq.newtons_cradle(3)
    r = plan(p, iq.Moreau(0.5))
    assert r == Route("single", "compiled") and r.scale == 1.0 and r.groups is None
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.path = "programs"
    far = p.with_u_minus(p.u_minus * 1e-150)
    tiny = plan(far, iq.Moreau(0.5))
    assert tiny.scale == pytest.approx(1e-150) and tiny.path == "compiled"
    assert iq.solve(far, iq.Moreau(0.5)).attempts[0].startswith("solved in units")
    assert plan(p, iq.SectorLaw()).path == "closed_form"
    assert plan(p, iq.Moreau(0.5), "clarabel").path == "programs"
    assert plan(p, iq.Moreau(0.5), mode="batch").path == "chain"
    assert plan(p, iq.Newton(0.5), mode="batch").path == "compiled"
    with pytest.raises(iq.InputError, match="mode"):
        plan(p, iq.Moreau(0.5), mode="run")  # a run needs its Stepping


def test_the_route_of_a_run_is_its_loop():
    ball, cradle = iq.simulation.bouncing_ball(), iq.simulation.cradle_system(3)
    assert plan_run(ball, iq.Moreau(0.5), "auto") == Route("run", "compiled")
    assert plan_run(cradle, iq.SectorLaw(), "auto").path == "python"
    assert plan_run(ball, iq.Moreau(0.5), "auto", compiled=False).path == "python"
    sphere = iq.LinearSystem(np.eye(3), [0.0, 0.0, 1.0], [1.0, 0.0, -1.0], [0.0, 0.0, -9.81],
                             np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]).T,
                             [0.0], contact_dim=3)
    assert plan_run(sphere, iq.Coulomb(0.3), "auto").path == "friction-compiled"
    assert plan_run(sphere, iq.Coulomb(0.3), "clarabel").path == "friction"
    problem = iq.ImpactProblem.from_structure(ball.structure, np.zeros(1))
    with pytest.raises(iq.InputError, match="compiled loop"):
        plan(problem, iq.SectorLaw(), mode="run", stepping=Stepping(True, compiled=True))
