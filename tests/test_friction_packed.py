"""A problem of a few contacts solved again (impactqp/laws/friction_small.py,
impactqp/kernels/friction_packed.py's pack and solve_packed): its second solve packs it, later
ones start from the pack, every solve gives the first one's answer, which the general route
and certify_friction confirm; the pack is the problem posed as the model poses it; a
problem whose q or W is replaced is packed again."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import impactqp as iq
from benchmarks import friction_data
from benchmarks.friction_tiny import ONE_SWEEP, TINY
from impactqp.kernels.friction_packed import (
    PACKED_HEADER,
    answer_size,
    iterations_at,
    pack,
    solve_packed,
)
from impactqp.kernels.friction_tiny import CERTIFIED, NEEDS_SCALING
from impactqp.laws import friction_small
from impactqp.laws.friction_small import SmallFrictionResult
from impactqp.model.friction import certify_friction

TOL = 1e-8


def kept(problem: iq.FrictionContactProblem):
    """What the route keeps on ``problem`` (None before its first solve)."""
    return problem.__dict__.get(friction_small._KEPT)


@pytest.mark.parametrize("name", [*TINY, *ONE_SWEEP])
def test_solves_again_give_the_first_answer(name: str) -> None:
    problem = friction_data.load(name).problem
    assert kept(problem) is None
    first = iq.solve_friction(problem, tol=TOL)
    packed = kept(problem).packed  # the first solve keeps its pack
    assert packed is not None
    second = iq.solve_friction(problem, tol=TOL)
    third = iq.solve_friction(problem, tol=TOL)
    assert kept(problem).packed is packed  # packed once
    for again in (second, third):
        assert type(again) is SmallFrictionResult and again.backend == first.backend
        np.testing.assert_array_equal(again.r, first.r)
        np.testing.assert_array_equal(again.u, first.u)
        assert again.iterations == first.iterations
        assert again.attempts == first.attempts
    cert = certify_friction(problem, third.r, third.u, tol=TOL)  # recomputed apart
    assert cert.ok and cert.error == pytest.approx(third.error, rel=1e-6, abs=1e-14)
    general = iq.solve_friction(problem, tol=TOL, backend="nsgs")
    scale = max(np.linalg.norm(problem.q), np.abs(third.u).max())
    np.testing.assert_allclose(third.u, general.u, atol=1e3 * TOL * scale)


@pytest.mark.parametrize("name", ["LMGC-00046", "FC2D-00374", "Confeti-ex13-4c", "CubeH8"])
def test_the_pack_is_the_problem_in_its_contacts_units(name: str) -> None:
    """The arrays of pack against the model's own posing
    (FrictionContactProblem.in_contact_units): the same units, q̂ and W̃ (dense, rebuilt
    from the packed rows), and W̃'s diagonal blocks."""
    problem = friction_data.load(name).problem
    small = problem.n_contacts <= 32
    floats, ints = pack(*friction_small._given(problem), friction_small._budgets(small))
    units = problem.in_contact_units()
    n, d, m = problem.q.size, problem.contact_dim, problem.n_contacts
    assert tuple(ints[:4]) == (n, d, m, ints[PACKED_HEADER + n]) and ints[5] == 1
    assert bool(ints[4]) == bool(np.any(units.s != 1.0))
    indptr = ints[PACKED_HEADER:PACKED_HEADER + n + 1]
    entries = indptr[-1]
    indices = ints[PACKED_HEADER + n + 1:]
    assert indices.size == entries
    np.testing.assert_allclose(floats[:n], units.s, rtol=1e-15)
    np.testing.assert_allclose(floats[n:2 * n], units.problem.q, rtol=1e-15)
    np.testing.assert_array_equal(floats[2 * n:2 * n + m], problem.mu)
    data = floats[floats.size - entries:]
    W = sp.csr_matrix((data, indices, indptr), shape=(n, n)).toarray()
    expected = units.problem.dense_W()
    np.testing.assert_allclose(W, expected, rtol=1e-14, atol=1e-300)
    blocks = floats[2 * n + 2 * m:2 * n + 2 * m + m * d * d].reshape(m, d, d)
    for c in range(m):
        np.testing.assert_allclose(blocks[c], expected[c * d:c * d + d, c * d:c * d + d],
                                   rtol=1e-14)


def test_a_replaced_q_is_packed_again() -> None:
    """The pack is kept for the W and q objects it was made from: a problem given a new q
    is solved for that q (certified apart, the general route's answer)."""
    problem = friction_data.load("Confeti-ex13-4c").problem
    for _ in range(3):
        old = iq.solve_friction(problem, tol=TOL)
    problem.q = problem.q * np.repeat([1.0, -1.0, 1.0, 2.0], 3)
    new = iq.solve_friction(problem, tol=TOL)
    assert certify_friction(problem, new.r, new.u, tol=TOL).ok
    assert not np.allclose(new.u, old.u)
    general = iq.solve_friction(problem, tol=TOL, backend="newton")
    np.testing.assert_allclose(new.u, general.u, atol=1e-6 * np.abs(general.u).max())
    again = iq.solve_friction(problem, tol=TOL)  # packed for the new q
    np.testing.assert_array_equal(again.u, new.u)


def test_a_packed_problem_beyond_the_floats_is_not_solved() -> None:
    """q in contact units beyond 1e±100 (the scale-first rule): the pack says so and
    solve_packed answers NEEDS_SCALING without solving; the route then hands the problem to
    the general route, which certifies it."""
    W = np.array([[2.0, 0.1, 0.0], [0.1, 1.5, 0.0], [0.0, 0.0, 1.5]])
    problem = iq.FrictionContactProblem(W, np.array([-1.0, 0.4, 0.2]) * 1e150, 0.3)
    floats, ints = pack(*friction_small._given(problem), friction_small._budgets(True))
    assert ints[5] == 0
    out = np.empty(answer_size(3))
    assert solve_packed(floats, ints, TOL, out) == NEEDS_SCALING
    assert out[iterations_at(3)] == 0
    for _ in range(3):
        res = iq.solve_friction(problem, tol=TOL)
        assert res.ok and type(res) is not SmallFrictionResult
        assert certify_friction(problem, res.r, res.u, tol=TOL).ok


def test_one_contact_in_each_of_its_cases() -> None:
    """A single contact solved by its cases (apart, sticking, sliding in 2-D and 3-D):
    the packed call's answer is certified apart and is the general route's."""
    W3 = np.array([[2.0, 0.1, 0.2], [0.1, 1.5, 0.0], [0.2, 0.0, 1.2]])
    W2 = W3[:2, :2].copy()
    cases = [(W3, [1.0, 0.3, 0.2]), (W3, [-1.0, 0.01, 0.02]), (W3, [-1.0, 2.0, -1.0]),
             (W2, [1.0, 0.3]), (W2, [-1.0, 0.01]), (W2, [-1.0, 2.0]), (W2, [-1.0, -2.0])]
    for W, q in cases:
        d = len(q)
        problem = iq.FrictionContactProblem(W, np.array(q), 0.3, contact_dim=d)
        floats, ints = pack(*friction_small._given(problem), friction_small._budgets(True))
        out = np.empty(answer_size(d))
        outcome = solve_packed(floats, ints, TOL, out)
        assert outcome == CERTIFIED and out[iterations_at(d)] == 1
        cert = certify_friction(problem, out[:d], out[d:2 * d], tol=1e-13)
        assert cert.ok
        general = iq.solve_friction(problem, tol=1e-12, backend="newton")
        np.testing.assert_allclose(out[:d], general.r, atol=1e-10)


def _fresh(problem: iq.FrictionContactProblem, backend: str = "auto"):
    """The answer of a new problem holding ``problem``'s present arrays."""
    again = iq.FrictionContactProblem(problem.W.copy(), problem.q.copy(), problem.mu.copy(),
                                      contact_dim=problem.contact_dim)
    return iq.solve_friction(again, tol=TOL, backend=backend)


@pytest.mark.parametrize("backend", ["auto", "newton", "nsgs"])
def test_a_q_rewritten_in_place_is_solved_as_it_now_is(backend) -> None:
    """A simulator may reuse one problem and rewrite q in place at each step: neither the
    kept pack nor the kept contact units may answer for the q they were made from (they did:
    a certified answer of the old q)."""
    problem = friction_data.load("Confeti-ex13-4c").problem
    rng = np.random.default_rng(3)
    for _step in range(4):
        for _ in range(3):  # packed from the second solve on
            r = iq.solve_friction(problem, tol=TOL, backend=backend)
        fresh = _fresh(problem, backend)
        assert certify_friction(problem, r.r, r.u, tol=TOL).ok
        np.testing.assert_allclose(r.u, fresh.u, atol=1e-6 * np.abs(fresh.u).max())
        units = problem.in_contact_units()
        np.testing.assert_allclose(units.problem.q * 2.0 ** units.k * units.s, problem.q,
                                   rtol=1e-15, atol=0.0)
        problem.q[:] = problem.q * rng.uniform(0.5, 1.5, problem.q.size)  # in place


def test_a_replaced_mu_is_solved_as_it_now_is() -> None:
    problem = friction_data.load("Confeti-ex13-4c").problem
    for _ in range(3):
        iq.solve_friction(problem, tol=TOL)
    problem.mu = np.full(problem.n_contacts, 0.05)
    problem.mu.setflags(write=False)
    r = iq.solve_friction(problem, tol=TOL)
    np.testing.assert_allclose(r.u, _fresh(problem).u, atol=1e-6 * np.abs(r.u).max())
    assert problem.holds(problem.state()) and not problem.holds(None)
