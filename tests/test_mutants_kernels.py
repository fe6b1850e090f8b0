"""The compiled impact kernels against references written here in numpy from their formulas
(docs/theory.md §1, §8, §9), written to kill the mutants benchmarks/mutation.py makes of
impactqp/kernels/impact.py, active_set.py and residuals.py.

Inputs are arbitrary (not solutions) where a formula is checked, so that every term of every
residual is of order one and a changed sign or index shows.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from impactqp.kernels.active_set import (
    ITERATION_LIMIT,
    NO_SOLUTION,
    SOLVED,
    lcp_psd,
    lcp_psd_rows,
    solve_lcp_psd,
)
from impactqp.kernels.chain_batch import chain_residual_rows
from impactqp.kernels.impact import _unpack, pack, solve_impact, solve_impact_rows
from impactqp.kernels.residuals import (
    SCALE_RANGE,
    chain_residuals,
    chain_step_residuals,
    dense_residual_rows,
    dense_residuals,
    dense_step_residuals,
    finish_rows,
    fold_contacts,
    unit_of,
)


def _spd(rng: np.random.Generator, n: int) -> np.ndarray:
    A = rng.normal(size=(n, n))
    return A @ A.T + n * np.eye(n)


def _problem(seed: int, n: int = 4, m: int = 3):
    rng = np.random.default_rng(seed)
    return rng, _spd(rng, n), rng.normal(size=(n, m))


# ------------------------------------------------------------------ numpy references
def residuals_reference(M, W, um, up, lam, E, eps, moreau, ur=None):
    """The six residuals of docs/theory.md §8 written directly from their definitions."""
    ur = um if ur is None else ur
    G = W.T @ np.linalg.solve(M, W)
    s = np.sqrt(np.diag(G))
    V = np.sqrt(um @ M @ um)
    if V == 0.0:
        V = max(np.sqrt(up @ M @ up), 1.0)
    d = up - um - np.linalg.solve(M, W @ lam)
    momentum = np.sqrt(d @ M @ d) / V
    Emat = eps * np.eye(W.shape[1]) if moreau else E
    w = W.T @ up + Emat @ (W.T @ ur)
    out = [momentum, max(0.0, np.max(-lam * s)) / V, max(0.0, np.max(-w / s)) / V,
           np.max(np.abs(lam * w)) / V**2, np.nan, np.nan]
    if moreau:
        z = (up + eps * um) / (1.0 + eps)
        out[4] = 2.0 * eps * abs(z @ M @ (um - z)) / V**2
        out[5] = np.sum(np.abs(lam * w)) / V**2 + momentum**2
    return np.array(out)


def lcp_brute_force(G, q):
    """w = Gx + q of a solution of 0 ≤ x ⟂ Gx + q ≥ 0 (unique for PSD G), by trying every
    support; None when no support gives a solution."""
    m = q.size
    for size in range(m + 1):
        for P in itertools.combinations(range(m), size):
            x = np.zeros(m)
            if P:
                idx = list(P)
                x[idx] = np.linalg.lstsq(G[np.ix_(idx, idx)], -q[idx], rcond=None)[0]
            w = G @ x + q
            if np.all(x >= -1e-12) and np.all(w >= -1e-10) and abs(x @ w) < 1e-10:
                return w
    return None


def chain_matrices(masses, left_wall, right_wall):
    """M and W of a 1-D chain: a wall contact γ = u₁ first, the gaps uⱼ − uⱼ₋₁, a wall
    contact γ = −u_N last."""
    n = masses.size
    cols = []
    if left_wall:
        cols.append(np.eye(n)[0])
    for j in range(1, n):
        c = np.zeros(n)
        c[j], c[j - 1] = 1.0, -1.0
        cols.append(c)
    if right_wall:
        cols.append(-np.eye(n)[n - 1])
    return np.diag(masses), np.array(cols).T


# ------------------------------------------------------------------ pack
@pytest.mark.parametrize("n, m", [(1, 1), (3, 2), (4, 3), (5, 5)])
def test_pack_holds_the_operators_numpy_computes(n: int, m: int) -> None:
    _, M, W = _problem(n * 10 + m, n, m)
    Mv, Wt, MinvW, G, s, check = _unpack(pack(M, W), n, m)
    MinvW_ref = np.linalg.solve(M, W)
    G_ref = W.T @ MinvW_ref
    np.testing.assert_allclose(Mv, M, rtol=0, atol=0)
    np.testing.assert_allclose(Wt, W.T, rtol=0, atol=0)
    np.testing.assert_allclose(MinvW, MinvW_ref, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(G, G_ref, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(s, np.sqrt(np.diag(G_ref)), rtol=1e-12)
    np.testing.assert_allclose(check, MinvW_ref, rtol=1e-12, atol=1e-14)
    assert pack(M, W).size == n * n + 3 * m * n + m * m + m


# ------------------------------------------------------------------ residuals
@pytest.mark.parametrize("moreau", [True, False])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_dense_residuals_are_the_formulas(moreau: bool, seed: int) -> None:
    rng, M, W = _problem(seed)
    n, m = W.shape
    um, up, ur = rng.normal(size=n), rng.normal(size=n), rng.normal(size=n)
    lam = rng.normal(size=m)
    E = rng.normal(size=(m, m))
    eps = 0.3 + 0.1 * seed
    Mv, Wt, MinvW, G, s, check = _unpack(pack(M, W), n, m)
    out = np.empty(6)
    work = np.empty(2 * n + 2 * m)
    dense_residuals(Mv, Wt, MinvW, s, um, up, lam, E, eps, moreau, out, work)
    np.testing.assert_allclose(out, residuals_reference(M, W, um, up, lam, E, eps, moreau),
                               rtol=1e-10, equal_nan=True)
    dense_step_residuals(Mv, Wt, MinvW, s, um, up, lam, ur, E, eps, moreau, out, work)
    np.testing.assert_allclose(out, residuals_reference(M, W, um, up, lam, E, eps, moreau, ur),
                               rtol=1e-10, equal_nan=True)
    rows = dense_residual_rows(Mv, Wt, MinvW, s, np.array([um, 2 * um]), np.array([up, up]),
                               np.array([lam, lam]), E, eps, moreau)
    np.testing.assert_allclose(rows[1], residuals_reference(M, W, 2 * um, up, lam, E, eps,
                                                            moreau), rtol=1e-10, equal_nan=True)


@pytest.mark.parametrize("scale", [1e-80, 1e75, 1e200])
def test_dense_residuals_do_not_depend_on_the_units(scale: float) -> None:
    rng, M, W = _problem(7)
    n, m = W.shape
    um, up, lam = rng.normal(size=n), rng.normal(size=n), rng.normal(size=m)
    Mv, Wt, MinvW, G, s, check = _unpack(pack(M, W), n, m)
    base, out = np.empty(6), np.empty(6)
    work = np.empty(2 * n + 2 * m)
    dense_residuals(Mv, Wt, MinvW, s, um, up, lam, np.empty((0, 0)), 0.5, True, base, work)
    dense_residuals(Mv, Wt, MinvW, s, scale * um, scale * up, scale * lam, np.empty((0, 0)),
                    0.5, True, out, work)
    np.testing.assert_allclose(out, base, rtol=1e-10)


def test_the_velocity_unit_of_a_body_at_rest() -> None:
    # u⁻ = 0: the inputs are divided by the largest entry c of u⁺ and Λ, and V is the
    # answer's own size in those units, at least 1
    rng, M, W = _problem(3)
    n, m = W.shape
    Mv, Wt, MinvW, G, s, check = _unpack(pack(M, W), n, m)
    out = np.empty(6)
    work = np.empty(2 * n + 2 * m)
    for size in (1e-3, 10.0, 1e70):
        up = size * rng.normal(size=n)
        lam = size * rng.normal(size=m)
        dense_residuals(Mv, Wt, MinvW, s, np.zeros(n), up, lam, np.eye(m), 0.0, False, out,
                        work)
        c = max(np.max(np.abs(up)), np.max(np.abs(lam)))
        ref = residuals_reference(M, W, np.zeros(n), up / c, lam / c, np.eye(m), 0.0, False)
        np.testing.assert_allclose(out[:4], ref[:4], rtol=1e-10)
        V = max(np.sqrt((up / c) @ M @ (up / c)), 1.0)
        d = up / c - np.linalg.solve(M, W @ (lam / c))
        np.testing.assert_allclose(out[0], np.sqrt(d @ M @ d) / V, rtol=1e-10)


def test_unit_of() -> None:
    lo, hi = SCALE_RANGE
    assert unit_of(np.array([0.5, -2.0]), np.zeros(2), np.zeros(1)) == 1.0
    assert unit_of(np.array([3 * hi, -5 * hi]), np.zeros(2), np.zeros(1)) == 5 * hi
    assert unit_of(np.array([lo / 4, -lo / 2]), np.zeros(2), np.zeros(1)) == lo / 2
    assert unit_of(np.array([lo, 0.0]), np.zeros(2), np.zeros(1)) == lo
    assert unit_of(np.array([hi, 0.0]), np.zeros(2), np.zeros(1)) == hi
    assert unit_of(np.zeros(2), np.array([1.0, -7.0]), np.array([3.0])) == 7.0
    assert unit_of(np.zeros(2), np.array([1.0, -2.0]), np.array([-9.0])) == 9.0
    assert unit_of(np.zeros(2), np.zeros(2), np.zeros(1)) == 1.0


def test_fold_contacts_and_finish_rows() -> None:
    lam = np.array([2.0, -1.0, 0.5])
    w = np.array([-3.0, 4.0, 1.0])
    s = np.array([1.0, 2.0, 4.0])
    fold = fold_contacts(lam, w, s)
    assert fold == (-2.0, -3.0, 6.0, 6.0 + 4.0 + 0.5)
    V = np.array([2.0])
    out = finish_rows(V, np.array([0.5]), lam[None], w[None], s, 0.25, True, np.array([-0.8]))
    np.testing.assert_allclose(out[0], [0.25, 1.0, 1.5, 1.5, 2 * 0.25 * 0.8 / 4,
                                        10.5 / 4 + 0.0625])
    out = finish_rows(V, np.array([0.5]), lam[None], w[None], s, 0.25, False, np.array([1.0]))
    assert np.isnan(out[0, 4:]).all()
    # no contacts: nothing violated, nothing to complement
    out = finish_rows(V, np.array([0.5]), np.zeros((1, 0)), np.zeros((1, 0)), np.zeros(0), 0.25,
                      True, np.array([0.0]))
    np.testing.assert_array_equal(out[0], [0.25, 0.0, 0.0, 0.0, 0.0, 0.0625])
    nan = fold_contacts(np.array([1.0, np.nan]), np.array([1.0, 1.0]), np.ones(2))
    assert np.isnan([nan[0], nan[2], nan[3]]).all() and nan[1] == 1.0


@pytest.mark.parametrize("walls", [(False, False), (True, False), (False, True), (True, True)])
@pytest.mark.parametrize("moreau", [True, False])
def test_chain_residuals_are_the_formulas(walls: tuple[bool, bool], moreau: bool) -> None:
    rng = np.random.default_rng(11)
    n = 5
    masses = rng.uniform(0.5, 3.0, size=n)
    M, W = chain_matrices(masses, *walls)
    m = W.shape[1]
    um, up, ur, lam = (rng.normal(size=n), rng.normal(size=n), rng.normal(size=n),
                       rng.normal(size=m))
    e = 0.4
    s = np.sqrt(np.diag(W.T @ np.linalg.solve(M, W)))
    out = np.empty(6)
    chain_residuals(um, up, lam, masses, 1.0 / masses, s, walls[0], walls[1], e, e, moreau,
                    out)
    ref = residuals_reference(M, W, um, up, lam, e * np.eye(m), e, moreau)
    np.testing.assert_allclose(out, ref, rtol=1e-10, equal_nan=True)
    chain_step_residuals(um, up, lam, ur, masses, 1.0 / masses, s, walls[0], walls[1], e, e,
                         moreau, out)
    ref = residuals_reference(M, W, um, up, lam, e * np.eye(m), e, moreau, ur)
    np.testing.assert_allclose(out, ref, rtol=1e-10, equal_nan=True)
    for scale in (1e-90, 1e90):
        rows = chain_residual_rows(scale * um[None], scale * up[None], scale * lam[None],
                                   masses, 1.0 / masses, s, walls[0], walls[1], e, e, moreau)
        ref = residuals_reference(M, W, um, up, lam, e * np.eye(m), e, moreau)
        np.testing.assert_allclose(rows[0], ref, rtol=1e-10, equal_nan=True)


# ------------------------------------------------------------------ active set
def _check_lcp(G, q, x, w, status):
    assert status == SOLVED
    np.testing.assert_allclose(w, G @ x + q, atol=1e-10)
    assert np.all(x >= 0.0)
    assert np.all(w >= -1e-10)
    assert abs(x @ w) <= 1e-10
    np.testing.assert_allclose(w, lcp_brute_force(G, q), atol=1e-8)


@pytest.mark.parametrize("seed", range(8))
def test_active_set_solves_what_brute_force_solves(seed: int) -> None:
    rng = np.random.default_rng(seed)
    m = 2 + seed % 4
    A = rng.normal(size=(m + 1, m))
    G = A.T @ A
    q = rng.normal(size=m) * 3.0
    x, w, status = solve_lcp_psd(G, q)
    _check_lcp(G, q, x, w, status)
    passive = x > 0.0
    warm = passive.copy()
    x2, w2, status2 = solve_lcp_psd(G, q, warm)
    _check_lcp(G, q, x2, w2, status2)
    np.testing.assert_array_equal(warm, x2 > 0.0)
    # a wrong warm start (the complement) still ends at the solution
    wrong = ~passive
    x3, w3, status3 = solve_lcp_psd(G, q, wrong)
    _check_lcp(G, q, x3, w3, status3)
    np.testing.assert_array_equal(wrong, x3 > 0.0)


@pytest.mark.parametrize("seed", range(6))
def test_active_set_with_redundant_contacts(seed: int) -> None:
    # dependent columns (duplicated and combined contacts): G is singular, w still unique
    rng = np.random.default_rng(100 + seed)
    base = rng.normal(size=(3, 3))
    A = np.column_stack([base, base[:, 0], base[:, 1] + base[:, 2], 2 * base[:, 2]])
    G = A.T @ A
    q = rng.normal(size=6) * 2.0
    x, w, status = solve_lcp_psd(G, q)
    _check_lcp(G, q, x, w, status)
    x, w, status = solve_lcp_psd(G, q, np.ones(6, dtype=bool))
    _check_lcp(G, q, x, w, status)
    for scale in (1e-8, 1e8):  # dependence is judged relative to G's scale
        xs, ws, status = solve_lcp_psd(scale * G, scale * q)
        assert status == SOLVED
        _assert_kkt(scale * G, scale * q, xs, ws)
        np.testing.assert_allclose(ws, scale * w, rtol=1e-6, atol=1e-9 * scale)


def _assert_kkt(G, q, x, w) -> None:
    """0 ≤ x ⟂ w = Gx + q ≥ 0, to rounding relative to the sizes involved."""
    size = 1.0 + np.abs(q).max() + np.abs(G).max() * np.abs(x).max()
    np.testing.assert_allclose(w, G @ x + q, atol=1e-9 * size)
    assert np.all(x >= 0.0) and np.all(w >= -1e-9 * size)
    assert abs(x @ w) <= 1e-9 * size * (1.0 + np.abs(x).max())


def test_active_set_on_many_small_lcps() -> None:
    # a sweep over sizes, ranks and warm starts: every answer satisfies the LCP's conditions,
    # and an LCP is declared without solution only when no support gives one
    rng = np.random.default_rng(2024)
    for _ in range(150):
        m = int(rng.integers(2, 8))
        A = rng.normal(size=(int(rng.integers(1, m + 2)), m))
        G = A.T @ A
        q = rng.normal(size=m) * rng.choice([0.1, 1.0, 10.0])
        regular = bool(np.all(np.linalg.eigvalsh(G) > 1e-9))  # then solvable for every q
        for passive in (None, rng.random(m) < 0.5):
            x, w, status = solve_lcp_psd(G, q, passive)
            if status == SOLVED:
                _assert_kkt(G, q, x, w)
            else:
                assert not regular and status == NO_SOLUTION
                assert lcp_brute_force(G, q) is None


def test_active_set_reports_an_infeasible_lcp_and_the_step_limit() -> None:
    G = np.array([[1.0, -1.0], [-1.0, 1.0]])
    q = np.array([-1.0, -1.0])  # x₁ − x₂ ≥ 1 and x₂ − x₁ ≥ 1 cannot both hold
    assert solve_lcp_psd(G, q)[2] == NO_SOLUTION
    rng = np.random.default_rng(5)
    A = rng.normal(size=(6, 6))
    G = A.T @ A
    q = -np.abs(rng.normal(size=6)) - 1.0
    x, w = np.zeros(6), np.zeros(6)
    assert lcp_psd(G, q, np.zeros(6, dtype=bool), x, w, 1) == ITERATION_LIMIT
    assert lcp_psd(G, q, np.zeros(6, dtype=bool), x, w, 200) == SOLVED
    _check_lcp(G, q, x, w, SOLVED)


def test_every_step_changes_the_passive_set() -> None:
    # max_iter bounds the steps that change the passive set: a one-variable LCP whose
    # variable is positive takes two (it joins; nothing more joins), cold or warm
    for passive in (False, True):
        x, w = np.zeros(1), np.zeros(1)
        status = lcp_psd(np.array([[2.0]]), np.array([-1.0]), np.array([passive]), x, w, 2)
        assert status == SOLVED
        assert x[0] == 0.5 and w[0] == 0.0


def test_active_set_rows_warm_start_each_other() -> None:
    rng = np.random.default_rng(9)
    A = rng.normal(size=(5, 4))
    G = A.T @ A
    Q = rng.normal(size=(6, 4))
    X, Wv, status = lcp_psd_rows(G, Q, np.zeros(4, dtype=bool), 200)
    for r in range(6):
        _check_lcp(G, Q[r], X[r], Wv[r], status[r])


def test_a_solution_at_zero_needs_no_step() -> None:
    G = np.eye(3)
    q = np.array([1.0, 0.0, 2.0])
    x, w, status = solve_lcp_psd(G, q)
    assert status == SOLVED
    np.testing.assert_array_equal(x, 0.0)
    np.testing.assert_array_equal(w, q)


# ------------------------------------------------------------------ solve_impact
def _impact_reference(M, W, um, Eq):
    """u⁺ and Λ of 0 ≤ Λ ⟂ GΛ + (I + E)Wᵀu⁻ ≥ 0 by brute force."""
    G = W.T @ np.linalg.solve(M, W)
    q = (np.eye(W.shape[1]) + Eq) @ (W.T @ um)
    w = lcp_brute_force(G, q)
    lam = np.linalg.lstsq(G, w - q, rcond=None)[0]
    return um + np.linalg.solve(M, W @ lam), w


@pytest.mark.parametrize("law", ["moreau", "newton", "fremond"])
@pytest.mark.parametrize("seed", range(4))
def test_solve_impact_against_brute_force(law: str, seed: int) -> None:
    rng, M, W = _problem(20 + seed)
    n, m = W.shape
    um = rng.normal(size=n) * 2.0
    eps = 0.5
    E = {"moreau": eps * np.eye(m), "newton": np.diag(rng.uniform(0, 1, m)),
         "fremond": rng.uniform(0, 0.4, (m, m))}[law]
    moreau = law == "moreau"
    packed = pack(M, W)
    out = np.empty(n + m + 6)
    passive = np.zeros(m, dtype=bool)
    ok = solve_impact(packed, um, E, eps, moreau, 1e-9, passive, out)
    up, lam, res = out[:n], out[n:n + m], out[n + m:]
    ref_up, ref_w = _impact_reference(M, W, um, E)
    assert ok
    np.testing.assert_allclose(up, ref_up, atol=1e-9)
    np.testing.assert_allclose(res, residuals_reference(M, W, um, up, lam, E, eps, moreau),
                               atol=1e-14, rtol=1e-8, equal_nan=True)
    np.testing.assert_array_equal(passive, lam > 0.0)
    # the verdict at its edge: tol = the largest judged residual passes, just below fails
    count = 6 if moreau else 4
    worst = np.max(res[:count])
    assert solve_impact(packed, um, E, eps, moreau, worst, passive, out)
    if worst > 0.0:
        assert not solve_impact(packed, um, E, eps, moreau, np.nextafter(worst, 0), passive,
                                out)
    Up, Lam, Res, certified = solve_impact_rows(packed, np.array([um, -um, 3 * um]), E, eps,
                                                moreau, 1e-9, np.zeros(m, dtype=bool))
    assert certified.all()
    np.testing.assert_allclose(Up[0], ref_up, atol=1e-9)
    np.testing.assert_allclose(Up[1], _impact_reference(M, W, -um, E)[0], atol=1e-9)
    np.testing.assert_allclose(Up[2], 3 * ref_up, atol=1e-8)


def test_solve_impact_refuses_what_it_cannot_certify() -> None:
    rng, M, W = _problem(40)
    n, m = W.shape
    um = rng.normal(size=n)
    out = np.empty(n + m + 6)
    E = np.full((m, m), np.nan)  # a law that cannot be evaluated
    assert not solve_impact(pack(M, W), um, E, 0.0, False, 1e-9, np.zeros(m, dtype=bool), out)
    # Moreau's energy residuals are judged: a negative tolerance fails even a zero residual
    assert not solve_impact(pack(M, W), um, E, 0.5, True, -1.0, np.zeros(m, dtype=bool), out)
