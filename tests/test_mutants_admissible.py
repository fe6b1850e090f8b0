"""The admissible set S (impactqp/model/admissible.py) against references written here from
its definition (docs/theory.md §2), written to kill the mutants benchmarks/mutation.py makes
of it: each residual of a membership recomputed with scipy's NNLS and numpy, the verdict at
its tolerance, the scale rules, and Moreau's split z ⊥ z⊥."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.optimize

import impactqp as iq


def _dense(A) -> np.ndarray:
    return A.toarray() if hasattr(A, "toarray") else np.asarray(A, dtype=float)


def reference_residuals(p, u: np.ndarray) -> tuple[float, float, float]:
    """(kinetic, kinematic, energetic) of u by their definitions: min over Λ ≥ 0 of
    ‖u − u⁻ − M⁻¹WΛ‖_M / V by scipy's NNLS, max(−γᵢ/(sᵢV))₊, (‖u‖²/V² − 1)₊."""
    M, W, um = _dense(p.M), _dense(p.W), np.asarray(p.u_minus, dtype=float)
    L = np.linalg.cholesky(M)
    V = np.sqrt(um @ M @ um)
    B = np.linalg.solve(L, W)  # ‖M⁻¹WΛ − du‖_M = ‖BΛ − Lᵀdu‖
    _, res = scipy.optimize.nnls(B, L.T @ (u - um))
    s = np.sqrt(np.sum(B * B, axis=0))
    kinematic = max(0.0, float(np.max(-(W.T @ u) / (s * V))))
    energetic = max(0.0, float(u @ M @ u) / V**2 - 1.0)
    return res / V, kinematic, energetic


def _points(p, rng, k):
    MinvW = np.linalg.solve(_dense(p.M), _dense(p.W))
    pts = []
    for _ in range(k):
        lam = rng.random(p.n_contacts) * rng.choice([0.3, 1.0, 3.0])
        pts.append(p.u_minus + MinvW @ lam)
        pts.append(p.u_minus + MinvW @ (lam - 0.5))
        pts.append(rng.standard_normal(p.n_dof))
    return pts


@pytest.mark.parametrize("seed", range(4))
def test_membership_residuals_are_their_definitions(seed: int) -> None:
    rng = np.random.default_rng(seed)
    p = iq.random_impact(5, 3 + seed % 2, seed=seed, redundant=seed % 2)
    S = p.admissible_set()
    for u in _points(p, rng, 4):
        got = S.contains(u)
        ref = reference_residuals(p, u)
        np.testing.assert_allclose([got.kinetic, got.kinematic, got.energetic], ref,
                                   rtol=1e-7, atol=1e-12)
        assert bool(got) == (max(ref) <= 1e-9 or max(ref) < 1e-11)
        # the impulses explain u − u⁻ as well as the best Λ ≥ 0 does
        assert np.all(got.impulses >= 0.0)
        d = u - p.u_minus - np.linalg.solve(_dense(p.M), _dense(p.W) @ got.impulses)
        assert p.norm(d) / p.norm(p.u_minus) == pytest.approx(got.kinetic, rel=1e-6, abs=1e-12)


def test_membership_verdict_at_its_tolerance() -> None:
    p = iq.newtons_cradle()
    S = p.admissible_set()
    # one point breaking each condition by a margin well above rounding
    for u in ([1.0 + 1e-4, -1e-4, 0.0], [0.5, -0.1, 0.6], [0.0, 0.0, 1.0 + 1e-5]):
        worst = max(reference_residuals(p, np.array(u)))
        assert worst > 1e-7
        got = S.contains(u, tol=worst * (1 + 1e-9))
        assert got.member
        assert not S.contains(u, tol=worst * (1 - 1e-6)).member
        assert got.tol == worst * (1 + 1e-9)


@pytest.mark.parametrize("scale", [1e-200, 1e-5, 1e180])
def test_membership_does_not_depend_on_the_units(scale: float) -> None:
    rng = np.random.default_rng(3)
    p = iq.random_impact(5, 3, seed=3)
    q = p.with_u_minus(p.u_minus * scale)
    for u in _points(p, rng, 3):
        a, b = p.admissible_set().contains(u), q.admissible_set().contains(u * scale)
        assert bool(a) == bool(b)
        np.testing.assert_allclose([b.kinetic, b.kinematic, b.energetic],
                                   [a.kinetic, a.kinematic, a.energetic], rtol=1e-7, atol=1e-12)
        if scale < 1e100:
            np.testing.assert_allclose(b.impulses, a.impulses * scale, rtol=1e-6,
                                       atol=1e-12 * scale)


def test_a_sparse_chain_decides_like_the_dense_one() -> None:
    masses, um = [1.0, 2.0, 3.0, 4.0], [1.0, 0.0, -1.0, 0.0]
    dense, sparse = iq.chain(masses, um), iq.chain(masses, um, sparse=True)
    rng = np.random.default_rng(8)
    for u in _points(dense, rng, 4):
        a, b = dense.admissible_set().contains(u), sparse.admissible_set().contains(u)
        ref = reference_residuals(dense, u)
        np.testing.assert_allclose([b.kinetic, b.kinematic, b.energetic], ref, rtol=1e-7,
                                   atol=1e-11)
        assert bool(a) == bool(b)


def test_a_body_at_rest_admits_only_rest() -> None:
    p = iq.newtons_cradle()
    q = p.with_u_minus(np.zeros(3))
    S = q.admissible_set()
    rest = S.contains(np.zeros(3))
    assert rest and (rest.kinetic, rest.kinematic, rest.energetic) == (0.0, 0.0, 0.0)
    np.testing.assert_array_equal(rest.impulses, 0.0)
    assert S.contains(np.zeros(3), method="optimizer").distance == 0.0
    m = S.contains([0.0, 1e-300, 0.0])
    assert not m and m.kinetic == np.inf
    assert S.contains([1.0, 0.0, 0.0], method="optimizer").distance == np.inf
    np.testing.assert_array_equal(S.project([1.0, 2.0, 3.0]), 0.0)
    assert S.support([1.0, 0.0, 0.0])[0] == 0.0
    z, zp = S.moreau_split()
    np.testing.assert_array_equal(z, 0.0)
    np.testing.assert_array_equal(zp, 0.0)


def test_separating_bodies_admit_only_their_velocity() -> None:
    # no contact approaches: S = {u⁻}
    p = iq.newtons_cradle().with_u_minus(np.array([-1.0, 0.0, 1.0]))
    S = p.admissible_set()
    assert S.contains([-1.0, 0.0, 1.0])
    value, u = S.support([0.0, 0.0, 1.0])
    np.testing.assert_allclose(u, [-1.0, 0.0, 1.0], atol=1e-12)
    assert value == pytest.approx(1.0)
    value, u = S.support([0.0, 0.0, 0.0])
    assert value == 0.0
    np.testing.assert_array_equal(u, p.u_minus)


@pytest.mark.parametrize("scale", [1.0, 1e-150, 1e150])
def test_moreau_split_is_the_kinetic_projection(scale: float) -> None:
    p = iq.random_impact(6, 4, seed=6)
    p = p.with_u_minus(p.u_minus * scale)
    z, zp = p.admissible_set().moreau_split()
    M, W = _dense(p.M), _dense(p.W)
    np.testing.assert_allclose(z + zp, p.u_minus, rtol=1e-12, atol=0)
    np.testing.assert_allclose(z, iq.moreau(p, 0.0).u_plus, rtol=1e-8, atol=1e-9 * scale)
    # z ∈ T_C, z⊥ = −M⁻¹WΛ with Λ ≥ 0, z ⊥ z⊥ in the kinetic metric
    assert np.all(W.T @ z >= -1e-9 * scale)
    lam = np.linalg.lstsq(W, -(M @ zp), rcond=None)[0]
    assert np.all(lam >= -1e-9 * scale)
    assert abs(z @ M @ zp) <= 1e-9 * scale**2 * max(p.norm(p.u_minus / scale) ** 2, 1.0)


def test_moreau_split_of_one_contact() -> None:
    # two equal balls, one contact: z is the common velocity, z⊥ the rest
    p = iq.newtons_cradle(2)
    z, zp = p.admissible_set().moreau_split()
    np.testing.assert_allclose(z, [0.5, 0.5], atol=1e-12)
    np.testing.assert_allclose(zp, [0.5, -0.5], atol=1e-12)


def test_support_and_projection_against_sampled_points() -> None:
    p = iq.newtons_cradle(4)
    S = p.admissible_set()
    rng = np.random.default_rng(2)
    c = np.array([1.0, -0.5, 0.2, 2.0])
    value, u = S.support(c)
    assert S.contains(u, tol=1e-6)
    assert value == pytest.approx(c @ u)
    MinvW = np.linalg.solve(p.M, p.W)
    for lam in rng.random((200, p.n_contacts)) * 2:
        v = p.u_minus + MinvW @ lam
        if S.contains(v):
            assert c @ v <= value + 1e-7
    scaled, u2 = S.support(10.0 * c)
    assert scaled == pytest.approx(10.0 * value, rel=1e-6)
    x = np.array([0.3, -1.0, 2.0, 0.1])
    y = S.project(x)
    assert S.contains(y, tol=1e-6)
    for scale in (1e3, 1e-3):  # S and the projection scale with u⁻
        far = p.with_u_minus(p.u_minus * scale).admissible_set().project(x * scale)
        np.testing.assert_allclose(far, y * scale, rtol=1e-5, atol=1e-6 * scale)
