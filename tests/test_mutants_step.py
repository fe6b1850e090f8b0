"""The pieces of the one Moreau–Jean step (docs/theory.md §14, §16, §17) against references
written here in numpy from the theory's formulas, written to kill the mutants
benchmarks/mutation.py makes of impactqp/kernels/step.py.

Inputs are arbitrary (random, of order one; an asymmetric Frémond matrix; contacts taken out
of order), so that a changed sign, index, factor or transposition shows.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from impactqp.kernels.step import (
    activation,
    end_step,
    free_velocity,
    gather_local,
    linear_gaps,
    rows_times,
    step_q,
)


def _rows(rng: np.random.Generator, m: int, d: int, n: int):
    """Hᵀ (d·m × n, sparse, random) and its compressed rows."""
    Ht = rng.normal(size=(m * d, n)) * (rng.random((m * d, n)) < 0.6)
    csr = sp.csr_matrix(Ht)
    return Ht, csr.indptr.astype(np.int64), csr.indices.astype(np.int64), csr.data.copy()


@pytest.mark.parametrize("d", [1, 2, 3])
def test_linear_gaps_are_the_normal_rows(d):
    rng = np.random.default_rng(d)
    m, n = 4, 5
    Ht, ptr, idx, val = _rows(rng, m, d, n)
    q, v, b = rng.normal(size=n), rng.normal(size=n), rng.normal(size=m)
    g, gamma = linear_gaps(ptr, idx, val, b, d, q, v, np.empty(m), np.empty(m))
    Hn = Ht[::d]
    np.testing.assert_allclose(g, Hn @ q + b, rtol=1e-13, atol=1e-14)
    np.testing.assert_allclose(gamma, Hn @ v, rtol=1e-13, atol=1e-14)


def test_activation_closes_the_gaps_predicted_shut_half_a_step_ahead():
    h = 0.1
    g = np.array([0.01, 0.01, 0.0, -0.01, 0.02, 0.005])
    gamma = np.array([-0.3, -0.1, 0.0, 1.0, -0.4, -0.1])
    # g + h/2·γ: −0.005, 0.005, 0 (closed at the edge), 0.04, 0 (closed), 0 (closed)
    closed = np.zeros(g.size, dtype=np.bool_)
    count = activation(g, gamma, h, closed)
    expected = g + 0.5 * h * gamma <= 0.0
    np.testing.assert_array_equal(closed, expected)
    np.testing.assert_array_equal(closed, [True, False, True, False, True, True])
    assert count == 4


@pytest.mark.parametrize("theta", [0.5, 1.0])
def test_free_velocity_of_a_linear_force(theta):
    rng = np.random.default_rng(7)
    n, h = 4, 0.05
    A = rng.normal(size=(n, n))
    M = A @ A.T + n * np.eye(n)
    B = rng.normal(size=(n, n))
    K = B @ B.T
    Wh = M + h * h * theta * theta * K
    chol = np.linalg.cholesky(Wh)
    c, q, v = rng.normal(size=n), rng.normal(size=n), rng.normal(size=n)
    out = free_velocity(chol, K, c, np.zeros(n), True, h, theta, q, v, np.empty(n),
                        np.empty(n))
    # M(v_free − v) = h(c − Kq) − h²θK v ... with Ŵ: v_free = v − Ŵ⁻¹(hKq + h²θKv − hc)
    expected = v - np.linalg.solve(Wh, h * K @ q + h * h * theta * K @ v - h * c)
    np.testing.assert_allclose(out, expected, rtol=1e-12, atol=1e-14)


def test_free_velocity_of_a_constant_force():
    rng = np.random.default_rng(8)
    n = 3
    v, shift = rng.normal(size=n), rng.normal(size=n)
    empty = np.zeros((n, n))
    out = free_velocity(empty, empty, np.zeros(n), shift, False, 0.1, 0.5, np.zeros(n), v,
                        np.empty(n), np.empty(n))
    np.testing.assert_allclose(out, v - shift, rtol=1e-15)


@pytest.mark.parametrize("d", [1, 3])
def test_rows_times_takes_the_contacts_in_the_order_given(d):
    rng = np.random.default_rng(d + 10)
    m, n = 5, 6
    Ht, ptr, idx, val = _rows(rng, m, d, n)
    x = rng.normal(size=n)
    C = np.array([3, 0, 4], dtype=np.int64)
    out = rows_times(ptr, idx, val, d, C, x, np.empty(C.size * d))
    rows = np.concatenate([np.arange(c * d, (c + 1) * d) for c in C])
    np.testing.assert_allclose(out, Ht[rows] @ x, rtol=1e-13, atol=1e-14)


@pytest.mark.parametrize("d", [1, 2, 3])
def test_step_q_with_one_coefficient_per_contact(d):
    rng = np.random.default_rng(20 + d)
    m = 5
    C = np.array([4, 1, 2], dtype=np.int64)
    e = rng.uniform(0.0, 1.0, m)
    gamma_k = rng.normal(size=m)
    gamma_free = rng.normal(size=C.size * d)
    out = np.empty(C.size * d)
    approaching = step_q(gamma_free, gamma_k, e, np.zeros((0, 0)), C, d, out)
    expected = gamma_free.copy()
    expected[::d] += e[C] * gamma_k[C]
    np.testing.assert_allclose(out, expected, rtol=1e-14, atol=1e-15)
    assert approaching == bool((expected[::d] < 0.0).any())


@pytest.mark.parametrize("d", [1, 3])
def test_step_q_with_an_asymmetric_fremond_matrix(d):
    """q_c = γ_free,c + Σ_{c' ∈ C} E[c, c'] γ_k[c'] over the closed contacts only: row c of
    E, not column c (E is not symmetric), and contacts outside C do not enter."""
    rng = np.random.default_rng(30 + d)
    m = 5
    E = rng.uniform(0.0, 0.6, (m, m))
    E[1, 3], E[3, 1] = 0.9, 0.0
    C = np.array([3, 1, 0], dtype=np.int64)
    gamma_k = rng.normal(size=m)
    gamma_free = rng.normal(size=C.size * d)
    out = np.empty(C.size * d)
    approaching = step_q(gamma_free, gamma_k, np.zeros(m), E, C, d, out)
    expected = gamma_free.copy()
    expected[::d] += E[np.ix_(C, C)] @ gamma_k[C]
    np.testing.assert_allclose(out, expected, rtol=1e-14, atol=1e-15)
    assert approaching == bool((expected[::d] < 0.0).any())


def test_step_q_says_whether_a_contact_approaches():
    C = np.array([0, 1], dtype=np.int64)
    e = np.array([0.5, 0.5])
    gamma_k = np.array([-2.0, 1.0])
    # normal rows 1 − 1 = 0 and 0 + 0.5: nothing approaches (0 is not approaching)
    out = np.empty(4)
    assert not step_q(np.array([1.0, -5.0, 0.0, -5.0]), gamma_k, e, np.zeros((0, 0)), C, 2,
                      out)
    np.testing.assert_array_equal(out, [0.0, -5.0, 0.5, -5.0])
    # the second normal row −1 + 0.5 < 0: approaching, whatever the tangent rows
    assert step_q(np.array([1.0, 3.0, -1.0, 3.0]), gamma_k, e, np.zeros((0, 0)), C, 2, out)


def test_gather_local_poses_the_problem_in_contact_units():
    rng = np.random.default_rng(40)
    k = 6
    A = rng.normal(size=(k, k))
    G = A @ A.T + np.eye(k)
    units = rng.uniform(0.5, 3.0, k)
    cols = np.array([4, 1, 5], dtype=np.int64)
    q = rng.normal(size=cols.size)
    W, qt = gather_local(G, units, cols, q, np.empty((3, 3)), np.empty(3))
    D = np.diag(1.0 / units[cols])
    np.testing.assert_allclose(W, D @ G[np.ix_(cols, cols)] @ D, rtol=1e-14)
    np.testing.assert_allclose(qt, D @ q, rtol=1e-14)


@pytest.mark.parametrize("theta", [0.5, 1.0])
def test_end_step_is_the_theta_method_and_keeps_the_asked_rows(theta):
    rng = np.random.default_rng(50)
    n, h = 3, 0.2
    q0, v0, vn = rng.normal(size=n), rng.normal(size=n), rng.normal(size=n)
    lam = rng.normal(size=2)
    kept = np.array([2, 5], dtype=np.int64)
    Q, V, L = np.full((2, n), np.nan), np.full((2, n), np.nan), np.full((2, 2), np.nan)
    q, v = q0.copy(), v0.copy()
    row = end_step(q, v, vn, lam, h, theta, 1, 0, kept, Q, V, L)  # step 1 → row of step 2
    expected_q = q0 + h * ((1.0 - theta) * v0 + theta * vn)
    np.testing.assert_allclose(q, expected_q, rtol=1e-15)
    np.testing.assert_array_equal(v, vn)
    assert row == 1
    np.testing.assert_array_equal(Q[0], q)
    np.testing.assert_array_equal(V[0], vn)
    np.testing.assert_array_equal(L[0], lam)
    assert np.isnan(Q[1]).all()
    # step 2 → step 3 is not kept: nothing recorded, the row stays
    assert end_step(q, v, vn, lam, h, theta, 2, row, kept, Q, V, L) == 1
    assert np.isnan(Q[1]).all() and np.isnan(L[1]).all()
    # past the last kept row nothing is read or written
    assert end_step(q, v, vn, lam, h, theta, 4, 2, kept, Q, V, L) == 2
