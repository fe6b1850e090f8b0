"""Duplicate and parallel contacts are collapsed before solving and their impulses split
back, so the certificate holds on the original problem (impactqp.laws.parallel); checked
against the LCP of the original problem solved as it is."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.laws.parallel import parallel_groups


def _lcp_u_plus(p: iq.ImpactProblem, eps: float) -> np.ndarray:
    """u⁺ of Moreau's law through the impulse LCP of the problem as given (no collapsing)."""
    M, W = np.asarray(p.structure.dense_mass), np.asarray(p.structure.W.toarray()
                                                          if hasattr(p.structure.W, "toarray")
                                                          else p.structure.W)
    MinvW = np.linalg.solve(M, W)
    lam = iq.solve_lcp(W.T @ MinvW, (1 + eps) * (W.T @ p.u_minus)).z
    return p.u_minus + MinvW @ lam


def test_ten_thousand_copies_of_one_contact():
    W = np.tile([[-1.0], [1.0]], (1, 10_000))
    W[:, 5000:] *= 3.0  # parallel, not only equal
    p = iq.ImpactProblem(np.eye(2), W, [1.0, 0.0])
    for law in (iq.Moreau(0.5), iq.Newton(0.5)):
        r = iq.solve(p, law)
        one = iq.solve(iq.ImpactProblem(np.eye(2), W[:, :1], [1.0, 0.0]), law)
        np.testing.assert_allclose(r.u_plus, one.u_plus, rtol=1e-14)
        assert r.certificate.ok and np.all(r.impulses >= 0)
        np.testing.assert_allclose(W @ r.impulses, W[:, :1] @ one.impulses, rtol=1e-12)
        assert "groups of parallel ones" in r.attempts[0]


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("eps", [0.0, 0.6, 1.0])
def test_random_parallel_contacts_agree_with_the_uncollapsed_lcp(seed, eps):
    rng = np.random.default_rng(seed)
    n, base = 3, 3
    A = rng.standard_normal((n, n))
    M = A @ A.T + n * np.eye(n)
    B = rng.standard_normal((n, base))
    picks = rng.integers(0, base, size=5)
    W = np.hstack([B, B[:, picks] * rng.uniform(0.2, 5.0, size=5)])
    W = W[:, rng.permutation(W.shape[1])]
    u = rng.standard_normal(n)
    p = iq.ImpactProblem(M, W, u)
    groups = parallel_groups(p.structure)
    assert groups is not None and groups.representative.size == base
    r = iq.moreau(p, eps)
    assert r.certificate.ok and np.all(r.impulses >= 0)
    np.testing.assert_allclose(r.u_plus, _lcp_u_plus(p, eps), rtol=1e-9, atol=1e-12)


def test_newton_with_different_coefficients_in_a_group_is_solved_as_given():
    W = np.array([[-1.0, -2.0, 0.0], [1.0, 2.0, -1.0]])
    p = iq.ImpactProblem(np.eye(2), W, [1.0, 0.0])
    r = iq.newton(p, [0.5, 0.9, 0.5])
    assert r.certificate.ok and not any("parallel" in a for a in r.attempts)
    same = iq.newton(p, [0.5, 0.5, 0.5])
    assert same.certificate.ok


def test_no_parallel_columns_no_groups():
    p = iq.random_impact(3, 5, seed=1)
    assert parallel_groups(p.structure) is None
    assert parallel_groups(iq.newtons_cradle(4).structure) is None
