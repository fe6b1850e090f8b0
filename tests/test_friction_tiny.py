"""A small dense frictional problem is posed, solved and certified in one compiled call
(impactqp/kernels/friction_tiny.py, docs/theory.md §15): the same answer and the same
certificate as the general route, the scale-first rule left to that route."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.kernels.friction_tiny import (
    CERTIFIED,
    NEEDS_SCALING,
    NOT_CERTIFIED,
    TinyLimits,
    solve_tiny,
)
from impactqp.model.friction import certify_friction


def problem(m: int, seed: int, *, unit: float = 1.0, d: int = 3,
            q_scale: float = 1.0) -> iq.FrictionContactProblem:
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((d * m, d * m))
    q = rng.standard_normal(d * m)
    q[::d] = -np.abs(q[::d])
    W = (A.T @ A / (d * m) + 1e-2 * np.eye(d * m)) * unit
    return iq.FrictionContactProblem(W, q * q_scale, rng.uniform(0.1, 1.0, m), contact_dim=d)


@pytest.mark.parametrize("m, d", [(1, 3), (3, 3), (9, 3), (4, 2), (20, 3)])
@pytest.mark.parametrize("seed", [0, 1])
def test_the_tiny_route_is_the_general_one(m: int, d: int, seed: int) -> None:
    p = problem(m, seed, d=d)
    tiny = iq.solve_friction(p, tol=1e-10)
    general = iq.solve_friction(p, backend="newton", tol=1e-10)
    assert tiny.backend == "kernel" and tiny.attempts[-1] == "kernel (friction): certified"
    assert tiny.certificate.ok and tiny.status == "solved"
    # the certificate it carries is the one certify_friction recomputes from r and u
    again = certify_friction(p, tiny.r, tiny.u, tol=1e-10)
    assert again.ok
    for name, value in again.values.items():
        assert tiny.certificate.values[name] == pytest.approx(value, rel=1e-6, abs=1e-15)
    for name, value in again.reported.items():
        assert tiny.certificate.reported[name] == pytest.approx(value, rel=1e-6, abs=1e-15)
    np.testing.assert_allclose(tiny.u, p.W @ tiny.r + p.q, atol=1e-12 * np.abs(p.q).max())
    scale = np.abs(general.r).max()
    np.testing.assert_allclose(tiny.r, general.r, atol=1e-6 * scale)


@pytest.mark.parametrize("unit", [1e-8, 1e9])
def test_contact_units_are_applied_and_said(unit: float) -> None:
    p = problem(3, 4, unit=unit)
    r = iq.solve_friction(p, tol=1e-10)
    assert r.backend == "kernel" and r.attempts[0].startswith("solved in its contacts' units")
    assert certify_friction(p, r.r, r.u, tol=1e-10).ok
    same = iq.solve_friction(problem(3, 4), tol=1e-10)
    np.testing.assert_allclose(r.r * unit, same.r, rtol=1e-6, atol=1e-9 * np.abs(same.r).max())


def test_the_kernel_outcomes() -> None:
    p = problem(2, 7)
    n = p.q.size
    r, u, fig = np.empty(n), np.empty(n), np.empty(7)
    limits = TinyLimits(1e-10, 50, 100, 3)
    its, outcome, _ = solve_tiny(p.W, p.q, p.mu, 3, limits, r, u, fig)
    assert outcome == CERTIFIED and its >= 1 and np.all(fig[:5] <= 1e-10)
    # q beyond the range posed as it is: the general route's scale-first rule takes over
    big = problem(2, 7, q_scale=1e150)
    _, outcome, _ = solve_tiny(big.W, big.q, big.mu, 3, limits, r, u, fig)
    assert outcome == NEEDS_SCALING
    answer = iq.solve_friction(big, tol=1e-10)
    assert answer.certificate.ok and "(2^0)" not in answer.attempts[0]
    # a tolerance no answer meets: judged, not certified
    _, outcome, _ = solve_tiny(p.W, p.q, p.mu, 3, limits._replace(tol=1e-300), r, u, fig)
    assert outcome == NOT_CERTIFIED and fig[0] > 1e-300
    # a NaN in q fails every figure instead of passing
    bad_q = p.q.copy()
    bad_q[1] = np.nan
    _, outcome, _ = solve_tiny(p.W, bad_q, p.mu, 3, limits, r, u, fig)
    assert outcome == NOT_CERTIFIED


def test_a_sparse_w_of_a_few_contacts_takes_the_same_call() -> None:
    import scipy.sparse as sp

    dense = problem(9, 5)
    sparse = iq.FrictionContactProblem(sp.csc_matrix(dense.W), dense.q, dense.mu)
    a, b = iq.solve_friction(dense, tol=1e-10), iq.solve_friction(sparse, tol=1e-10)
    assert b.backend == "kernel" and b.attempts == a.attempts
    np.testing.assert_array_equal(a.r, b.r)
    assert certify_friction(sparse, b.r, b.u, tol=1e-10).ok
