"""The compiled kernels against independent computations: the active-set search against KKT
conditions, an LP feasibility test and scipy's NNLS; the residual kernels against the table
of docs/theory.md §8 evaluated here with numpy; the single-impact kernel row by row.

CI also runs this file with NUMBA_DISABLE_JIT=1, so the kernels' Python text is exercised."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog
from scipy.optimize import nnls as scipy_nnls

import impactqp as iq
from impactqp.kernels.active_set import NO_SOLUTION, SOLVED, lcp_psd_rows, solve_lcp_psd
from impactqp.kernels.impact import solve_impact, solve_impact_rows
from impactqp.kernels.nnls import solve_nnls
from impactqp.kernels.residuals import RESIDUALS, chain_residuals, dense_residuals
from impactqp.model.residuals import restitution_matrix


def random_lcp(rng: np.random.Generator):
    """A PSD G = BᵀB (some columns dependent) and q in or out of the range of G."""
    m, n = int(rng.integers(1, 9)), int(rng.integers(1, 9))
    B = rng.standard_normal((n, m))
    if m > 1 and rng.random() < 0.4:
        B[:, -1] = B[:, 0] * rng.uniform(0.5, 2.0)
    q = B.T @ rng.standard_normal(n) if rng.random() < 0.5 else rng.standard_normal(m)
    return B.T @ B, q


def test_lcp_search_meets_kkt_or_proves_infeasibility():
    rng = np.random.default_rng(0)
    solved = infeasible = 0
    for _ in range(300):
        G, q = random_lcp(rng)
        x, w, status = solve_lcp_psd(G, q)
        scale = np.abs(q).max() + np.abs(G).max() * max(np.abs(x).max(), 1.0)
        if status == NO_SOLUTION:  # then no x ≥ 0 has Gx + q ≥ 0 (an LP says so)
            lp = linprog(np.zeros(q.size), A_ub=-G, b_ub=q, bounds=[(0, None)] * q.size)
            assert lp.status == 2
            infeasible += 1
            continue
        assert status == SOLVED
        np.testing.assert_allclose(w, G @ x + q, atol=1e-12 * scale)
        assert x.min() >= 0 and w.min() >= -1e-10 * scale
        assert np.abs(x * w).max() <= 1e-10 * scale * max(1.0, np.abs(x).max())
        solved += 1
    assert solved > 100 and infeasible > 5  # both outcomes were exercised


def test_warm_rows_equal_cold_solves():
    rng = np.random.default_rng(1)
    G, _ = random_lcp(rng)
    B = np.linalg.cholesky(G + np.eye(G.shape[0]))
    Q = rng.standard_normal((50, G.shape[0])) @ B.T  # q in the range (G + I is definite)
    G = G + np.eye(G.shape[0])
    X, W, status = lcp_psd_rows(G, Q, np.zeros(G.shape[0], dtype=bool), 500)
    assert (status == SOLVED).all()
    for q, x in zip(Q, X):
        np.testing.assert_array_equal(solve_lcp_psd(G, q)[0], x)  # the support fixes x


def test_nnls_is_optimal_and_no_worse_than_scipy():
    rng = np.random.default_rng(2)
    for trial in range(200):
        n, m = int(rng.integers(1, 12)), int(rng.integers(1, 12))
        A, b = rng.standard_normal((n, m)), rng.standard_normal(n)
        if m > 2 and trial % 3 == 0:
            A[:, 1] = A[:, 0] + A[:, 2]  # dependent columns
        x, rnorm = solve_nnls(A, b)
        assert x.min() >= 0 and rnorm == pytest.approx(np.linalg.norm(A @ x - b), abs=1e-12)
        grad = A.T @ (A @ x - b)  # KKT of min ½‖Ax − b‖², x ≥ 0
        scale = np.abs(A).max() * (np.abs(b).max() + 1.0)
        assert grad.min() >= -1e-9 * scale and np.abs(x * grad).max() <= 1e-9 * scale
        assert rnorm <= scipy_nnls(A, b)[1] + 1e-9 * (1.0 + rnorm)


def table_residuals(M, W, um, up, lam, E, eps):
    """docs/theory.md §8's table, term by term (Moreau's two extra rows when eps is given)."""
    V = np.sqrt(um @ M @ um)
    s = np.sqrt(np.diag(W.T @ np.linalg.solve(M, W)))
    d = up - um - np.linalg.solve(M, W @ lam)
    w = W.T @ up + E @ (W.T @ um)
    out = [np.sqrt(d @ M @ d) / V, max(0.0, (-lam * s).max()) / V,
           max(0.0, (-w / s).max()) / V, np.abs(lam * w).max() / V**2]
    if eps is not None:
        z = (up + eps * um) / (1 + eps)
        out += [2 * eps * abs(z @ M @ (um - z)) / V**2, np.abs(lam * w).sum() / V**2 + out[0]**2]
    return out


@pytest.mark.parametrize("moreau", [True, False])
def test_dense_residuals_are_the_table_of_the_theory(moreau):
    rng = np.random.default_rng(3)
    for seed in range(30):
        p = iq.random_impact(int(rng.integers(2, 7)), int(rng.integers(1, 4)), seed=seed,
                             consistent=False)
        st, m = p.structure, p.n_contacts
        up = p.u_minus + 0.1 * rng.standard_normal(p.n_dof)
        lam = rng.standard_normal(m)
        eps = float(rng.random())
        E = eps * np.eye(m) if moreau else rng.random((m, m))
        out = np.empty(6)
        dense_residuals(st.dense_mass, st.dense_Wt, st.dense_Minv_W, st.contact_scale,
                        p.u_minus, up, lam, E, eps, moreau, out, np.empty(2 * p.n_dof + 2 * m))
        want = table_residuals(st.dense_mass, st.dense_Wt.T, p.u_minus, up, lam, E,
                               eps if moreau else None)
        np.testing.assert_allclose(out[:len(want)], want, rtol=1e-9, atol=1e-15)
        assert moreau or np.isnan(out[4:]).all()


@pytest.mark.parametrize("walls", [(False, False), (True, False), (False, True), (True, True)])
def test_chain_loop_equals_the_dense_residuals(walls):
    rng = np.random.default_rng(4)
    for n in (1, 2, 5, 9):
        masses = 10.0 ** rng.uniform(-2, 2, n)
        p = iq.chain(masses, rng.standard_normal(n), left_wall=walls[0], right_wall=walls[1])
        if p.n_contacts == 0:
            continue
        dense = iq.ImpactProblem(np.diag(masses), p.W, p.u_minus).structure
        up = p.u_minus + rng.standard_normal(n)
        lam = rng.standard_normal(p.n_contacts)
        a, b = np.empty(6), np.empty(6)
        chain_residuals(p.u_minus, up, lam, masses, 1.0 / masses, p.structure.contact_scale,
                        walls[0], walls[1], 0.4, 0.4, True, a)
        dense_residuals(dense.dense_mass, dense.dense_Wt, dense.dense_Minv_W,
                        dense.contact_scale, p.u_minus, up, lam, 0.4 * np.eye(p.n_contacts),
                        0.4, True, b, np.empty(2 * n + 2 * p.n_contacts))
        np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-15)


def test_non_finite_input_gives_non_finite_residuals():
    p = iq.newtons_cradle(3)
    st = p.structure
    for bad in (np.nan, np.inf):
        out = np.empty(6)
        up = np.array([0.0, bad, 1.0])
        dense_residuals(st.dense_mass, st.dense_Wt, st.dense_Minv_W, st.contact_scale,
                        p.u_minus, up, np.zeros(2), 0.5 * np.eye(2), 0.5, True, out,
                        np.empty(10))
        assert not (out <= 1e-9).all()


def test_impact_rows_equal_single_impacts():
    rng = np.random.default_rng(5)
    p = iq.random_impact(6, 4, seed=1, redundant=1)
    st = p.structure
    U = rng.standard_normal((30, 6))
    for law in (iq.Moreau(0.5), iq.Newton([0.2, 0.4, 0.6, 0.8])):
        moreau = type(law) is iq.Moreau
        E = restitution_matrix(law.restitution(4), 4)
        eps = law.eps if moreau else 0.0
        Up, Lam, Res, ok = solve_impact_rows(st.kernel_pack, U, E, eps, moreau, 1e-9,
                                             np.zeros(4, dtype=bool))
        for u, up, lam, res, good in zip(U, Up, Lam, Res, ok):
            out = np.empty(6 + 4 + 6)
            assert solve_impact(st.kernel_pack, u, E, eps, moreau, 1e-9,
                                np.zeros(4, dtype=bool), out) == good
            np.testing.assert_array_equal(out[:6], up)
            np.testing.assert_array_equal(out[6:10], lam)
            ref = iq.solve(p.with_u_minus(u), law, backend="exact")
            np.testing.assert_allclose(up, ref.u_plus, rtol=1e-9, atol=1e-12)
            assert good and len(RESIDUALS) == res.size
