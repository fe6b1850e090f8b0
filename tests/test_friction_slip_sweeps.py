"""The small route's sweeps solve each sliding 3-D contact by its slip angle (docs/theory.md
§15): the slip function by its five coefficients against its definition, and sweeps whose
local problems are exact against contacts solved one by one and the general route."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse

import impactqp as iq
from impactqp.kernels.friction_blocks import diagonal_blocks, local_steps, sticking
from impactqp.kernels.friction_slip import _slip_at, _slip_terms, sliding_3d, sliding_from
from impactqp.kernels.friction_sweep import nsgs_blocks
from impactqp.laws import friction_small
from impactqp.laws.friction_small import SmallFrictionResult
from impactqp.model.friction import certify_friction
from impactqp.qp.friction import methods

TOL = 1e-8


def slip_by_definition(Wc: np.ndarray, base: np.ndarray, mu: float, theta: float) -> float:
    """G(θ) = e × (a·u_t) as docs/theory.md §15 defines it, in numpy: r = (1, −μe) per unit
    r_n, a = (W_cc r)_n, a·u_t = a·b_t − b_n (W_cc r)_t."""
    e = np.array([math.cos(theta), math.sin(theta)])
    r = np.array([1.0, -mu * e[0], -mu * e[1]])
    wr = Wc @ r
    au = wr[0] * base[1:] - base[0] * wr[1:]
    return float(e[0] * au[1] - e[1] * au[0])


def sliding_contact(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, float]:
    """A random contact block (symmetric positive definite) and b with b_n < 0."""
    A = rng.standard_normal((3, 3))
    Wc = A @ A.T + 0.1 * np.eye(3)
    base = rng.standard_normal(3)
    base[0] = -abs(base[0])
    return Wc, base, float(rng.uniform(0.05, 1.5))


def slides(rng: np.random.Generator, r: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """A drawn contact that neither separates nor sticks (redrawn while it sticks), its
    sliding answer by sliding_3d in ``r``."""
    Wc, base, mu = sliding_contact(rng)
    while sticking(Wc, base, mu, 3, r):
        Wc, base, mu = sliding_contact(rng)
    assert sliding_3d(Wc, base, mu, r)
    return Wc, base, mu


@pytest.mark.parametrize("seed", range(10))
def test_the_slip_coefficients_give_the_slip_function_and_its_derivative(seed: int) -> None:
    """G and G′ from the five coefficients equal G by its definition, and its central
    difference, at random angles."""
    Wc, base, mu = sliding_contact(np.random.default_rng(seed))
    g, _ = _slip_terms(Wc, base, mu)
    scale = np.abs(Wc).max() * np.abs(base).max() * (1.0 + mu)
    for theta in np.random.default_rng(100 + seed).uniform(0.0, 2.0 * math.pi, 8):
        value, slope = _slip_at(g, math.cos(theta), math.sin(theta))
        assert value == pytest.approx(slip_by_definition(Wc, base, mu, theta),
                                      abs=1e-13 * scale)
        h = 1e-6
        central = (slip_by_definition(Wc, base, mu, theta + h)
                   - slip_by_definition(Wc, base, mu, theta - h)) / (2 * h)
        assert slope == pytest.approx(central, abs=1e-7 * scale)


@pytest.mark.parametrize("seed", range(10))
def test_the_slip_root_is_a_root_of_the_definition(seed: int) -> None:
    """A contact that neither separates nor sticks slides (W_cc definite: its local problem
    has one solution): sliding_3d answers, the angle of its r_t is a root of G by its
    definition, to round-off, with u_n = 0 and u_t along the slip (u_t · r_t < 0)."""
    r = np.empty(3)
    Wc, base, mu = slides(np.random.default_rng(seed), r)
    theta = math.atan2(-r[2], -r[1])
    scale = np.abs(Wc).max() * np.abs(base).max() * (1.0 + mu)
    assert abs(slip_by_definition(Wc, base, mu, theta)) <= 1e-13 * scale
    u = Wc @ r + base
    assert abs(u[0]) <= 1e-12 * np.abs(base).max()
    assert u[1] * r[1] + u[2] * r[2] < 0.0


@pytest.mark.parametrize("seed", range(10))
def test_newton_from_the_last_slip_angle_finds_the_same_answer(seed: int) -> None:
    """sliding_from, started from an angle near the slip (as a sweep's last r_t is) or from
    any angle, answers the contact's one sliding solution (W_cc definite) or nothing: never
    another r."""
    rng = np.random.default_rng(seed)
    exact = np.empty(3)
    Wc, base, mu = slides(rng, exact)
    near = np.empty(3)
    turn = rng.uniform(-0.05, 0.05)
    t1 = exact[1] * math.cos(turn) - exact[2] * math.sin(turn)
    t2 = exact[1] * math.sin(turn) + exact[2] * math.cos(turn)
    assert sliding_from(Wc, base, mu, t1, t2, near)
    np.testing.assert_allclose(near, exact, rtol=1e-12, atol=1e-14 * np.abs(exact).max())
    for angle in np.linspace(0.0, 2.0 * math.pi, 9)[:-1]:
        far = np.full(3, np.nan)
        if sliding_from(Wc, base, mu, math.cos(angle), math.sin(angle), far):
            np.testing.assert_allclose(far, exact, rtol=1e-10,
                                       atol=1e-12 * np.abs(exact).max())
        else:
            assert np.isnan(far).all()  # untouched
    assert not sliding_from(Wc, base, mu, 0.0, 0.0, near)  # no last angle


def decoupled_problem(m: int, seed: int) -> iq.FrictionContactProblem:
    """m 3-D contacts, W block-diagonal (no contact moves another), each block's b driving
    it to slide: a tangential push well beyond μ times the normal one."""
    rng = np.random.default_rng(seed)
    blocks, q = [], []
    for _ in range(m):
        A = rng.standard_normal((3, 3))
        blocks.append(A @ A.T + 0.5 * np.eye(3))
        angle = rng.uniform(0.0, 2.0 * math.pi)
        q.append([-1.0, 3.0 * math.cos(angle), 3.0 * math.sin(angle)])
    return iq.FrictionContactProblem(scipy.linalg.block_diag(*blocks),
                                     np.concatenate(q), 0.3, contact_dim=3)


@pytest.mark.parametrize("seed", range(4))
def test_decoupled_sliding_contacts_end_in_one_sweep(seed: int) -> None:
    """With W block-diagonal each contact's local problem is the problem: exact local
    solves end it in one sweep, to round-off, and each contact's answer is that of the
    contact posed alone and solved by Newton's method (another route, another algorithm)."""
    problem = decoupled_problem(4, seed)
    fast = iq.solve_friction(problem, tol=TOL)
    assert type(fast) is SmallFrictionResult and fast.iterations == 1
    assert fast.error <= 1e-14
    assert certify_friction(problem, fast.r, fast.u, tol=1e-13).ok
    sliding = 0
    for c in range(4):
        k = slice(3 * c, 3 * c + 3)
        alone = iq.FrictionContactProblem(problem.W[k, k], problem.q[k], 0.3, contact_dim=3)
        other = iq.solve_friction(alone, tol=1e-12, backend="newton")
        np.testing.assert_allclose(fast.r[k], other.r, rtol=1e-9, atol=1e-12)
        sliding += np.hypot(fast.r[k][1], fast.r[k][2]) >= 0.3 * fast.r[k][0] * (1 - 1e-12)
    assert sliding >= 1  # the draws do slide: the slip angle was exercised


@pytest.mark.parametrize("seed", range(6))
def test_coupled_sliding_contacts_agree_with_the_general_route(seed: int) -> None:
    """Weakly coupled sliding contacts: the small route's answer (exact sweeps) is certified
    again independently and gives the velocity of the general route (the few-contact call
    switched off)."""
    problem = decoupled_problem(3, seed)
    coupled = problem.W + 0.05 * np.ones_like(problem.W)  # symmetric, still definite
    problem = iq.FrictionContactProblem(coupled, problem.q, 0.3, contact_dim=3)
    fast = iq.solve_friction(problem, tol=TOL)
    assert type(fast) is SmallFrictionResult
    assert certify_friction(problem, fast.r, fast.u, tol=TOL).ok
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(methods, "SMALL_CONTACTS", 0)
        patch.setattr(friction_small, "SWEPT_CONTACTS", 0)
        # a new problem object: the first one keeps the pack of its solve (friction_small)
        general = iq.solve_friction(
            iq.FrictionContactProblem(coupled, problem.q, 0.3, contact_dim=3), tol=TOL)
    assert general.backend != "kernel" and general.certificate.ok
    np.testing.assert_allclose(fast.u, general.u, atol=1e-5 * np.linalg.norm(problem.q))


@pytest.mark.parametrize("seed", range(3))
def test_the_sweeps_after_the_first_solve_sliding_contacts_by_their_slip_angle(
        seed: int) -> None:
    """The sweeps that go on after the first one (nsgs_blocks, which solve_packed's
    sweeps_on runs) solve each sliding contact exactly too: on a block-diagonal W one of them
    from r = 0 ends the problem to round-off, where local fixed-point steps would not."""
    problem = decoupled_problem(3, seed)
    W = scipy.sparse.csr_matrix(problem.W)
    rows = (W.indptr, W.indices, W.data)
    Wcc = diagonal_blocks(W.indptr, W.indices, W.data, 3, 3)
    r = np.zeros(9)
    mu = np.full(3, 0.3)
    done, err = nsgs_blocks(rows, (Wcc, local_steps(Wcc)), problem.q, mu, 3, r, 1e-30, 1, 3)
    assert done == 1 and err <= 1e-14
    assert certify_friction(problem, r, problem.W @ r + problem.q, tol=1e-13).ok
