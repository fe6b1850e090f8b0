"""The admissible set S: exact membership vs the SOCP, projection, support, cvxpy form."""

import cvxpy as cp
import numpy as np
import pytest

import impactqp as iq


def sample_points(p, rng, k):
    """Points of u⁻ + N (some in S, some beyond the energy sphere) and arbitrary points."""
    pts = []
    Minv_W = np.linalg.solve(p.M, p.W)
    for _ in range(k):
        lam = rng.random(p.n_contacts) * rng.choice([0.3, 1.0, 3.0])
        pts.append(p.u_minus + Minv_W @ lam)
        pts.append(p.u_minus + rng.standard_normal(p.n_dof))
    return pts


@pytest.mark.parametrize("seed", range(6))
def test_exact_and_optimizer_membership_agree(seed):
    rng = np.random.default_rng(seed)
    p = iq.random_impact(5, 3 + seed % 3, seed=seed, redundant=seed % 2)
    S = p.admissible_set()
    agree = members = 0
    for u in sample_points(p, rng, 12):
        exact = S.contains(u)
        opt = S.contains(u, method="optimizer")
        # the distance to S decides the optimizer's verdict; skip nothing, but points within
        # the optimizer's tolerance of the boundary must agree with the exact residuals
        margin = max(exact.kinetic, exact.kinematic, exact.energetic)
        if margin > 1e-4 or margin == 0 or bool(exact):
            assert bool(exact) == bool(opt), (u, exact, opt)
        agree += bool(exact) == bool(opt)
        members += bool(exact)
    assert agree >= 20
    # the Moreau points are in S for consistent pre-impact velocities, both ways
    for eps in (0.0, 0.5, 1.0):
        u = iq.moreau(p, eps).u_plus
        assert S.contains(u)
        assert S.contains(u, method="optimizer")


def test_projection_is_nearest_and_in_S():
    p = iq.newtons_cradle()
    S = p.admissible_set()
    rng = np.random.default_rng(0)
    for _ in range(5):
        x = rng.standard_normal(3) * 2
        y = S.project(x)
        assert S.contains(y, tol=1e-7)
        # no sampled point of S is closer
        d = p.norm(x - y)
        for lam in rng.random((50, 2)) * 2:
            u = p.u_minus + np.linalg.solve(p.M, p.W @ lam)
            if S.contains(u):
                assert p.norm(x - u) >= d - 1e-7
    # a point of S projects onto itself; z is the projection of the origin
    np.testing.assert_allclose(S.project([0, 0, 1.0]), [0, 0, 1.0], atol=1e-6)
    # interior-point positions are accurate to about the square root of the gap tolerance
    np.testing.assert_allclose(S.project([0.0, 0.0, 0.0]), [1 / 3] * 3, atol=1e-6)


def test_support_of_the_cradle():
    p = iq.newtons_cradle()
    S = p.admissible_set()
    value, u = S.support([0.0, 0.0, 1.0])  # fastest possible last ball: the observed cradle
    assert value == pytest.approx(1.0, abs=1e-8)
    np.testing.assert_allclose(u, [0, 0, 1.0], atol=1e-4)
    value, u = S.support([-1.0, 0.0, 0.0])  # strongest bounce of ball 1: Moreau ε = 1
    assert value == pytest.approx(1 / 3, abs=1e-8)


def test_cvxpy_constraints_give_the_same_projection():
    p = iq.random_impact(4, 3, seed=3)
    S = p.admissible_set()
    x = np.array([1.0, -2.0, 0.5, 0.3])
    u = cp.Variable(4)
    L = np.linalg.cholesky(p.M)
    prob = cp.Problem(cp.Minimize(cp.norm(L.T @ (u - x))), S.constraints(u))
    prob.solve(solver="CLARABEL")
    y = S.project(x)
    # distances agree to the solvers' accuracy; positions to about its square root
    assert prob.value == pytest.approx(p.norm(x - y), rel=1e-7)
    np.testing.assert_allclose(u.value, y, atol=1e-4)


def test_membership_reports_each_condition():
    p = iq.newtons_cradle()
    S = p.admissible_set()
    m = S.contains([0.0, 1.0, 0.0])  # ball 2 passes through ball 3: penetration
    assert not m and "kinematic" in m.failed()
    m = S.contains([-1.0, 1.0, 1.0])  # more energy than before
    assert not m and "energetic" in m.failed()
    m = S.contains([1.1, -0.1, 0.0])  # would need a pulling (negative) impulse
    assert not m and "kinetic" in m.failed()
    m = S.contains([0.0, 0.0, 0.5])  # momentum is not conserved
    assert not m and "kinetic" in m.failed()
