"""The general friction route's own speed-ups (docs/theory.md §15): the arrays derived from W
and μ kept on the problem between solves (and rebuilt where W or μ is replaced, or where q is
rewritten and the problem is posed again in its units), and the over-relaxed sweeps of planar
problems. Every answer is judged by the independent certificate and compared with a solve of a
fresh problem of the same data."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from cone_reference import project_onto_cone

import impactqp as iq
from benchmarks.friction_data import load
from impactqp.kernels.friction import nsgs_contacts, project_cones, relax_contact, relaxation
from impactqp.model.friction import certify_friction
from impactqp.qp.friction import methods as friction_methods
from impactqp.qp.friction.data import FrictionData, ProblemArrays
from impactqp.qp.friction.methods import (
    NEWTON_STALL,
    QUICK_PROBE,
    RELAX_PLANAR,
    SOCP_WARM,
    STALL_NEAR,
    nsgs_route,
)
from impactqp.qp.friction.newton import NEWTON_STEPS, _slow, newton

TOL = 1e-8


def planar_pile(m: int, seed: int, mu: float = 0.5) -> iq.FrictionContactProblem:
    """A planar problem of m contacts, W = H Hᵀ + 10⁻³I of a random sparse H (each contact
    couples to a few others), all contacts pressed (q_n < 0)."""
    rng = np.random.default_rng(seed)
    n = 2 * m
    H = sp.random(n, n, density=4.0 / n, random_state=rng) + sp.eye(n)
    W = sp.csr_matrix(H @ H.T + 1e-3 * sp.eye(n))
    q = rng.normal(size=n)
    q[0::2] = -np.abs(q[0::2]) - 0.1
    return iq.FrictionContactProblem(W, q, mu, contact_dim=2)




def test_arrays_are_kept_on_the_problem_between_solves() -> None:
    p = planar_pile(60, 1)
    first = iq.solve_friction(p, tol=TOL)
    posed = p.in_contact_units().problem
    kept = posed._arrays
    assert isinstance(kept, ProblemArrays) and kept.holds(posed)
    assert kept.contacts is not None and kept.steps is not None  # the sweeps built them
    again = iq.solve_friction(p, tol=TOL)
    assert posed._arrays is kept  # not rebuilt
    np.testing.assert_array_equal(again.r, first.r)
    assert certify_friction(p, again.r, again.u, tol=TOL).ok


def test_arrays_are_rebuilt_when_W_or_mu_is_replaced() -> None:
    p = planar_pile(50, 2)
    iq.solve_friction(p, tol=TOL)
    old = p.in_contact_units().problem._arrays
    W2 = sp.csr_matrix(p.W * 2.0)  # another W, in place of the first
    p.W = W2
    res = iq.solve_friction(p, tol=TOL)
    assert p.in_contact_units().problem._arrays is not old
    fresh = iq.solve_friction(iq.FrictionContactProblem(W2, p.q, p.mu, contact_dim=2), tol=TOL)
    np.testing.assert_allclose(res.r, fresh.r, rtol=0, atol=1e-12 * np.abs(fresh.r).max())
    assert certify_friction(p, res.r, res.u, tol=TOL).ok
    p.mu = iq.FrictionContactProblem(W2, p.q, 0.1, contact_dim=2).mu  # a new μ object
    res_mu = iq.solve_friction(p, tol=TOL)
    assert np.all(p.in_contact_units().problem._arrays.mu == 0.1)
    assert certify_friction(p, res_mu.r, res_mu.u, tol=TOL).ok
    assert not np.allclose(res_mu.r, res.r)


def test_arrays_kept_for_the_same_W_answer_a_q_rewritten_in_place() -> None:
    """In its own units (W's normal diagonal one) the problem is its own posed problem: its
    arrays stay while q is rewritten in place, and the answer is the new q's."""
    p = planar_pile(40, 3)
    s = 1.0 / np.sqrt(np.repeat(p.W.diagonal()[0::2], 2))
    W = sp.lil_matrix(sp.diags(s) @ p.W @ sp.diags(s))
    W.setdiag(np.where(np.arange(W.shape[0]) % 2 == 0, 1.0, W.diagonal()))  # exactly one
    unit = iq.FrictionContactProblem(sp.csr_matrix(W), s * p.q, p.mu, contact_dim=2)
    assert unit.in_contact_units().problem is unit
    iq.solve_friction(unit, tol=TOL)
    kept = unit._arrays
    unit.q[:] = -np.abs(unit.q) * 0.5 + 0.01 * np.arange(unit.q.size)  # in place
    res = iq.solve_friction(unit, tol=TOL)
    assert unit._arrays is kept
    fresh = iq.FrictionContactProblem(unit.W.copy(), unit.q.copy(), unit.mu, contact_dim=2)
    expected = iq.solve_friction(fresh, tol=TOL)
    np.testing.assert_allclose(res.r, expected.r, rtol=0, atol=1e-12 * np.abs(expected.r).max())
    assert certify_friction(fresh, res.r, tol=TOL).ok
    # another W of the same units (off-diagonal halved), then another μ: rebuilt, and the
    # answers are those of fresh problems of the same data
    W2 = sp.csr_matrix(0.5 * unit.W + 0.5 * sp.diags(unit.W.diagonal()))
    for change in ("W", "mu"):
        if change == "W":
            unit.W = W2
        else:
            unit.mu = iq.FrictionContactProblem(W2, unit.q, 0.2, contact_dim=2).mu
        res = iq.solve_friction(unit, tol=TOL)
        assert unit.in_contact_units().problem is unit and unit._arrays is not kept
        kept = unit._arrays
        fresh = iq.FrictionContactProblem(W2, unit.q.copy(), unit.mu, contact_dim=2)
        expected = iq.solve_friction(fresh, tol=TOL)
        np.testing.assert_allclose(res.r, expected.r, rtol=0,
                                   atol=1e-12 * np.abs(expected.r).max())
        assert certify_friction(fresh, res.r, tol=TOL).ok


def test_arrays_of_a_program_without_attributes_live_for_one_solve() -> None:
    """A program that takes no attributes (a named tuple, as a repair's sub-problem) still
    gets its arrays, not kept."""
    from impactqp.qp.friction.repair import SubProblem
    p = planar_pile(10, 4)
    sub = SubProblem(sp.csr_matrix(p.W), p.q, np.asarray(p.mu), 2, 10)
    data = FrictionData(sub)
    assert data.contacts.diagonal.shape == (10, 2, 2)
    assert FrictionData(sub).arrays is not data.arrays


def test_relaxation_factor_is_youngs_formula_capped() -> None:
    assert relaxation(0.64, 1.9) == pytest.approx(2.0 / 1.6)
    assert relaxation(0.0, 1.9) == pytest.approx(1.0)
    assert relaxation(0.99, 1.5) == 1.5


@pytest.mark.parametrize("seed", range(4))
def test_relaxed_sweeps_end_on_a_certified_answer_and_the_plain_sweeps_one(seed: int) -> None:
    p = planar_pile(80, 10 + seed, mu=0.3 + 0.2 * seed)
    data = FrictionData(p)
    rows, steps = data.contacts, data.steps
    answers = []
    for relax in (1.0, RELAX_PLANAR):
        r = np.zeros(data.n)
        done, err = nsgs_contacts(rows, steps, data.q, data.mu, 2, r, 1e-12, 20000, 3, relax)
        assert err <= 1e-12 and done < 20000
        np.testing.assert_array_equal(project_cones(r, data.mu, 2), r)  # in the cones
        assert certify_friction(p, r, tol=1e-10).ok
        answers.append(r)
    np.testing.assert_allclose(answers[1], answers[0], rtol=0,
                               atol=1e-8 * np.abs(answers[0]).max())


@pytest.mark.parametrize("d", [2, 3])
def test_a_relaxed_contact_is_the_projection_of_the_relaxed_point(d: int) -> None:
    """relax_contact against the cone's definition (project_onto_cone) at random old and
    new reactions, each of the projection's three cases met."""
    rng = np.random.default_rng(d)
    cases = set()
    for _ in range(300):
        mu, omega = rng.uniform(0.1, 1.0), rng.uniform(1.0, 1.9)
        old, new = rng.normal(size=d), rng.normal(size=d)
        r = np.concatenate([rng.normal(size=d), new, rng.normal(size=d)])
        before = r.copy()
        relax_contact(r, d, d, mu, omega, old[0], old[1], old[2] if d == 3 else 0.0)
        x = (1.0 - omega) * old + omega * new
        expected = project_onto_cone(x, mu)
        np.testing.assert_allclose(r[d:2 * d], expected, rtol=1e-13, atol=1e-15)
        np.testing.assert_array_equal(np.delete(r, range(d, 2 * d)),
                                      np.delete(before, range(d, 2 * d)))
        t = np.linalg.norm(x[1:])
        cases.add("inside" if t <= mu * x[0] else "polar" if mu * t <= -x[0] else "edge")
    assert cases == {"inside", "polar", "edge"}


@pytest.mark.parametrize("name", ["FC2D-00071", "FC2D-00237", "FC2D-00727"])
def test_relaxed_sweeps_take_no_more_than_plain_ones(name: str) -> None:
    """Where over-relaxing does not pay (FC2D-00237: at a factor 1.5 the sweeps cycle at
    ‖F‖/‖q‖ ≈ 2e-3), the sweeps go back to plain ones: never more sweeps than plain."""
    data = FrictionData(load(name).problem.in_contact_units().problem)
    counts = []
    for relax in (1.0, RELAX_PLANAR):
        r = np.zeros(data.n)
        done, err = nsgs_contacts(data.contacts, data.steps, data.q, data.mu, 2, r,
                                  0.5 * TOL, 5000, 3, relax)
        assert err <= 0.5 * TOL
        counts.append(done)
    assert counts[1] <= counts[0]


def test_relaxation_cuts_the_sweeps_of_the_granular_flow() -> None:
    """Granular2D-667 (‖q‖ = 4e-18): the plain sweeps take 40 to 5e-9, the relaxed ones
    fewer (26 measured), and both answers are certified."""
    case = load("Granular2D-667")
    data = FrictionData(case.problem.in_contact_units().problem)
    counts = []
    for relax in (1.0, RELAX_PLANAR):
        r = np.zeros(data.n)
        done, err = nsgs_contacts(data.contacts, data.steps, data.q, data.mu, 2, r, 0.5 * TOL,
                                  200, 3, relax)
        assert err <= 0.5 * TOL
        counts.append(done)
    assert counts[1] <= 0.75 * counts[0]
    r, sweeps, left, err = nsgs_route(data, np.zeros(data.n), TOL, 100)
    assert left == 0.0 and err <= 0.5 * TOL and sweeps == counts[1]
    res = iq.solve_friction(case.problem, tol=TOL)
    assert res.backend == "nsgs-short" and res.iterations == counts[1]
    assert certify_friction(case.problem, res.r, res.u, tol=TOL).ok


def test_slow_windows() -> None:
    """Newton's probe asks once, after its first k steps; its stall after every step from
    the k-th, over the last k."""
    errors = [1.0, 0.9, 0.85, 0.1, 0.09, 0.085]
    assert not _slow(errors[:2], (2, 1.25), only_first=True)  # one step: not asked yet
    assert _slow(errors[:3], (2, 1.25), only_first=True)  # 1 → 0.85 in two steps
    assert not _slow(errors[:4], (2, 1.25), only_first=True)  # asked only after step 2
    assert not _slow(errors[:4], (2, 1.25), only_first=False)  # 0.9 → 0.1
    assert _slow(errors, (2, 1.25), only_first=False)  # 0.1 → 0.085
    assert not _slow(errors, (3, 1.25), only_first=False)  # 0.85 → 0.085
    assert not _slow(errors, None, only_first=False)


@pytest.fixture(scope="module")
def capsules_404() -> FrictionData:
    return FrictionData(load("Capsules-404").problem.in_contact_units().problem)


def test_newton_ends_where_it_stalls_near_the_answer(capsules_404: FrictionData) -> None:
    """Capsules-404: Newton from r = 0 sits at ‖F‖/‖q‖ ≈ 3e-6 from its 10th step on; with the
    stall it ends there, well before its 50 steps, at the error it would have crawled from."""
    data = capsules_404
    r, steps, ok = newton(data, np.zeros(data.n), TOL, stall=NEWTON_STALL)
    assert not ok and NEWTON_STALL[0] <= steps < 25
    assert data.error(r) <= STALL_NEAR
    r_full, steps_full, _ = newton(data, np.zeros(data.n), TOL, max_steps=steps + 5)
    assert steps_full == steps + 5
    assert data.error(r_full) > 0.5 * data.error(r)  # five more steps gain less than 2×


def test_newton_goes_on_where_it_converges_or_is_far() -> None:
    """Capsules: Newton certifies in 21 steps, with or without the stall; far from the
    answer (spheres-in-a-box, ‖F‖/‖q‖ > 1e-4 throughout) it takes its 50 steps."""
    data = FrictionData(load("Capsules").problem.in_contact_units().problem)
    r, steps, ok = newton(data, np.zeros(data.n), TOL, stall=NEWTON_STALL)
    assert ok and steps == 21
    assert certify_friction(data.program, r, tol=TOL).ok
    far = FrictionData(load("spheres-in-a-box").problem.in_contact_units().problem)
    r, steps, ok = newton(far, np.zeros(far.n), TOL, stall=NEWTON_STALL)
    assert not ok and steps == NEWTON_STEPS and far.error(r) > STALL_NEAR


def test_socp_route_starts_from_zero_near_but_not_at_the_answer(
        capsules_404: FrictionData, monkeypatch: pytest.MonkeyPatch) -> None:
    """The SOCP route's start: r = 0 from a start between SOCP_WARM·tol and STALL_NEAR, the
    start itself within SOCP_WARM·tol or beyond STALL_NEAR."""
    data = capsules_404
    starts = []

    def spy(data_, r0, tol):
        starts.append(r0.copy())
        return r0, 0, False

    monkeypatch.setattr(friction_methods, "socp_route", spy)
    r_near, _, _ = newton(data, np.zeros(data.n), TOL, stall=NEWTON_STALL)  # ~3e-6
    r_far = np.zeros(data.n)
    r_far[0::3] = 1.0  # far from the answer
    assert data.error(r_far) > STALL_NEAR
    for start, expect_zero in ((r_near, True), (r_far, False), (None, True)):
        friction_methods.socp(data, start, TOL)
        if expect_zero:
            assert not starts[-1].any()
        else:
            np.testing.assert_array_equal(starts[-1], start)
    r_close = newton(data, np.zeros(data.n), 0.5 * SOCP_WARM * TOL, max_steps=60)[0]
    if data.error(r_close) <= SOCP_WARM * TOL:
        friction_methods.socp(data, r_close, TOL)
        np.testing.assert_array_equal(starts[-1], r_close)


def test_capsules_404_takes_the_socp_route_after_a_short_newton() -> None:
    case = load("Capsules-404")
    res = iq.solve_friction(case.problem, tol=TOL)
    assert res.backend == "clarabel"
    assert certify_friction(case.problem, res.r, res.u, tol=TOL).ok
    newton_attempt = [a for a in res.attempts if a.startswith("newton (")]
    steps = int(newton_attempt[0].split(" after ")[1].split(" iterations")[0])
    assert steps < 25
    nsgs_attempt = [a for a in res.attempts if a.startswith("nsgs-short (")]
    assert int(nsgs_attempt[0].split(" after ")[1].split(" iterations")[0]) <= 100 + QUICK_PROBE
