"""Tests for impactqp.qp.isotonic: exact Moreau impacts on 1-D chains (docs/theory.md §3, §5)."""
from __future__ import annotations

import clarabel
import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.optimize import isotonic_regression

from impactqp.qp.isotonic import ChainSolution, chain_moreau, chain_moreau_batch

WALLS = [(False, False), (True, False), (False, True), (True, True)]


def chain_W(n: int, left: bool, right: bool) -> np.ndarray:
    """Dense W with columns [left wall e_1, e_{i+1} - e_i, right wall -e_N]."""
    cols = [np.eye(n)[:, 0]] if left else []
    cols += [np.eye(n)[:, i + 1] - np.eye(n)[:, i] for i in range(n - 1)]
    cols += [-np.eye(n)[:, -1]] if right else []
    return np.array(cols).T.reshape(n, len(cols))


def qp_reference(m, u, left, right):
    """Independent z and Λ_z: Clarabel on min ½(v-u)ᵀM(v-u) s.t. Wᵀv >= 0, tight tolerances."""
    W = chain_W(len(m), left, right)
    st_ = clarabel.DefaultSettings()
    st_.verbose = False
    st_.tol_gap_abs = st_.tol_gap_rel = st_.tol_feas = 1e-10
    s = clarabel.DefaultSolver(sp.csc_matrix(np.diag(m)), -m * u, sp.csc_matrix(-W.T),
                               np.zeros(W.shape[1]), [clarabel.NonnegativeConeT(W.shape[1])], st_)
    sol = s.solve()
    assert str(sol.status) in ("Solved", "AlmostSolved")
    return np.array(sol.x), np.array(sol.z)  # dual z: M(v - u) = W y


def check_kkt(m, u, eps, left, right, s: ChainSolution, tol=1e-10):
    """docs/theory.md §1/docs/theory.md §3 conditions: impact equation, Λ >= 0, γ⁺+εγ⁻ >= 0,
    complementarity, energy."""
    W = chain_W(len(m), left, right)
    scale = 1.0 + np.max(np.abs(m * u))
    lam, w = s.impulses, W.T @ s.u_plus + eps * (W.T @ u)
    np.testing.assert_allclose(m * (s.u_plus - u), W @ lam, atol=tol * scale)
    assert np.all(lam >= -tol * scale)
    assert np.all(w >= -tol * (1 + np.abs(u).max()))
    assert np.all(np.abs(lam * w) <= tol * scale * (1 + np.abs(u).max()))
    assert m @ s.u_plus**2 <= m @ u**2 * (1 + 1e-12) + 1e-14
    # momentum: only the walls can change the total momentum
    ext = (lam[0] if left else 0.0) - (lam[-1] if right else 0.0)
    assert abs(m @ (s.u_plus - u) - ext) <= tol * scale * len(m)


@pytest.mark.parametrize("v", [1.0, -2.5, 3.0])
def test_cradle_reference_numbers(v):
    # docs/theory.md §5, equal masses m = 2 scale Λ by m
    s0 = chain_moreau([2.0, 2.0, 2.0], [v, 0.0, 0.0], 0.0)
    s1 = chain_moreau([2.0, 2.0, 2.0], [v, 0.0, 0.0], 1.0)
    if v > 0:
        np.testing.assert_allclose(s0.u_plus, [v / 3] * 3, rtol=1e-15)
        np.testing.assert_allclose(s0.impulses, [2 * 2 * v / 3, 2 * v / 3], rtol=1e-15)
        np.testing.assert_allclose(s1.u_plus, [-v / 3, 2 * v / 3, 2 * v / 3], rtol=1e-15)
        np.testing.assert_allclose(s1.impulses, [2 * 4 * v / 3, 2 * 2 * v / 3], rtol=1e-15)
    else:  # balls separating: no impact at all
        np.testing.assert_array_equal(s0.u_plus, [v, 0, 0])
        np.testing.assert_array_equal(s1.impulses, [0, 0])


@pytest.mark.parametrize("n", [2, 10, 1000, 100_000])
def test_long_cradle_exact(n):
    u = np.zeros(n)
    u[0] = 1.0
    s = chain_moreau(np.ones(n), u)
    assert np.abs(s.z * n - 1.0).max() < 1e-12
    lam_exact = 1.0 - np.arange(1, n) / n  # Λ_i = 1 - i/N
    assert np.abs(s.impulses - lam_exact).max() < 1e-12


@pytest.mark.parametrize("left,right", WALLS)
@pytest.mark.parametrize("seed", range(6))
def test_walls_vs_qp(left, right, seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 30))
    m = rng.uniform(0.1, 10.0, n)
    u = rng.normal(size=n) * rng.uniform(0.1, 5)
    s = chain_moreau(m, u, 0.0, left_wall=left, right_wall=right)
    zq, yq = qp_reference(m, u, left, right)
    np.testing.assert_allclose(s.z, zq, atol=1e-7)
    check_kkt(m, u, 0.0, left, right, s)
    if not (left and right):  # Λ unique
        np.testing.assert_allclose(s.impulses, yq, atol=1e-6 * (1 + np.abs(m * u).sum()))


def test_clip_claim_is_the_bounded_regression():
    """The clip of the unbounded isotonic regression equals the QP with a wall (docs/theory.md
    §3)."""
    rng = np.random.default_rng(42)
    for _ in range(40):
        n = int(rng.integers(2, 12))
        m, u = rng.uniform(0.1, 5, n), rng.normal(size=n) + rng.normal()
        for left, right in WALLS[1:]:
            zq, _ = qp_reference(m, u, left, right)
            s = chain_moreau(m, u, left_wall=left, right_wall=right)
            np.testing.assert_allclose(s.z, zq, atol=1e-6)
            W = chain_W(n, left, right)
            assert np.all(W.T @ s.z >= 0.0)  # feasible, and no worse than the QP optimum
            f, fq = m @ (s.z - u) ** 2, m @ (zq - u) ** 2
            assert f <= fq + 1e-9 * (1.0 + fq)


def test_both_walls_minimal_impulse():
    m, u = np.array([1.0, 2.0, 3.0]), np.array([1.0, -2.0, 0.5])
    s = chain_moreau(m, u, 0.5, left_wall=True, right_wall=True)
    np.testing.assert_allclose(s.u_plus, -0.5 * u)
    np.testing.assert_allclose(s.impulses, [4.5, 6.0, 0.0, 2.25])
    assert s.impulses.min() == 0.0  # lowering all by t > 0 would break Λ >= 0


finite = st.floats(-1e3, 1e3, allow_nan=False)


@settings(max_examples=150, deadline=None)
@given(
    data=st.integers(1, 25).flatmap(
        lambda n: st.tuples(arrays(float, n, elements=st.floats(1e-3, 1e3)),
                            arrays(float, n, elements=finite))),
    eps=st.floats(0.0, 1.0),
    walls=st.sampled_from(WALLS),
)
def test_kkt_property(data, eps, walls):
    m, u = data
    s = chain_moreau(m, u, eps, left_wall=walls[0], right_wall=walls[1])
    check_kkt(m, u, eps, walls[0], walls[1], s, tol=1e-9)
    np.testing.assert_allclose(s.u_plus, (1 + eps) * s.z - eps * u)


@pytest.mark.parametrize("left,right", WALLS)
@pytest.mark.parametrize("n", [1, 2, 3, 9, 80])
def test_batch_equals_loop(left, right, n):
    rng = np.random.default_rng(n)
    m = rng.uniform(0.2, 5, n)
    U = rng.normal(size=(300, n))
    U[:5] = 0.0  # ties
    U[5:10] = np.sort(U[5:10], axis=1)  # already separating
    b = chain_moreau_batch(m, U, 0.7, left_wall=left, right_wall=right)
    loop = [chain_moreau(m, r, 0.7, left_wall=left, right_wall=right) for r in U]
    for f in ("u_plus", "impulses", "z"):
        np.testing.assert_allclose(getattr(b, f), [getattr(s, f) for s in loop],
                                   rtol=1e-12, atol=1e-12)
    assert b.impulses.shape == (300, n - 1 + left + right)


def test_batch_empty_and_equal_to_scipys_regression():
    m = np.array([1.0, 2.0, 1.0, 0.5, 3.0])
    assert chain_moreau_batch(m, np.zeros((0, 5))).u_plus.shape == (0, 5)
    U = np.random.default_rng(1).normal(size=(50, 5))
    U[:10] = np.round(U[:10])  # ties
    b = chain_moreau_batch(m, U, 0.2)
    ref = [isotonic_regression(u, weights=m).x for u in U]  # scipy's PAVA, independent
    np.testing.assert_allclose(b.z, ref, atol=1e-15)


@pytest.mark.parametrize("args,word", [
    (([1.0, -1.0], [0.0, 0.0]), "masses"),
    (([1.0, np.inf], [0.0, 0.0]), "masses"),
    (([], []), "masses"),
    (([[1.0, 1.0]], [0.0, 0.0]), "masses"),
    (([1.0, 1.0], [0.0, 0.0, 0.0]), "u_minus"),
    (([1.0, 1.0], [0.0, np.nan]), "u_minus"),
    (([1.0, 1.0], [0.0, 0.0], 1.5), "eps"),
    (([1.0, 1.0], [0.0, 0.0], -0.1), "eps"),
    (([1.0, 1.0], [0.0, 0.0], float("nan")), "eps"),
    (([1.0, 1.0], [0.0, 0.0], "x"), "eps"),
])
def test_bad_inputs(args, word):
    with pytest.raises(ValueError, match=word):
        chain_moreau(*args)


def test_bad_batch_inputs():
    with pytest.raises(ValueError, match="U_minus"):
        chain_moreau_batch([1.0, 1.0], [0.0, 1.0])
    with pytest.raises(ValueError, match="U_minus"):
        chain_moreau_batch([1.0, 1.0], np.ones((4, 3)))
    with pytest.raises(ValueError, match="eps"):
        chain_moreau_batch([1.0, 1.0], np.ones((4, 2)), 2.0)
