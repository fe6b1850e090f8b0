"""The projected Gauss–Seidel's closed forms and the ``"kernel"`` method's choice between its
sweeps and Newton (impactqp/kernels/friction_blocks.py, friction_newton.py; docs/theory.md
§15): each closed form against numpy (eigenvalues, a natural map written here), the sweeps
kept on a problem where their rate is fast, Newton on one where it is slow, both answers
certified and checked by that natural map."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import impactqp as iq
from impactqp.kernels.friction_blocks import (
    exact_contact,
    local_steps,
    nonzero_rows,
    sticking,
)
from impactqp.kernels.friction_newton import (
    scales,
    solve_small,
    sweep_budget,
    sweeps_first,
)


def natural_map(W: np.ndarray, q: np.ndarray, mu: np.ndarray, d: int,
                r: np.ndarray) -> np.ndarray:
    """F = r − P_K(r − ũ), ũ = u + μ‖u_T‖e_n, u = W r + q, written with numpy alone."""
    u = W @ r + q
    F = np.empty_like(r)
    for c, m in enumerate(mu):
        k = slice(c * d, c * d + d)
        ut = u[k].copy()
        ut[0] += m * np.linalg.norm(u[k][1:])
        x = r[k] - ut
        xn, t = x[0], np.linalg.norm(x[1:])
        if t <= m * xn:  # inside the cone
            p = x
        elif m * t <= -xn:  # inside its polar
            p = np.zeros(d)
        else:  # onto the rim: the nearest point of the ray (1, μ x_T/t)
            ray = np.concatenate([[1.0], m * x[1:] / t])
            p = max(x @ ray, 0.0) / (ray @ ray) * ray
        F[k] = r[k] - p
    return F


def abh(W, q, mu, d, r) -> float:
    return float(np.linalg.norm(natural_map(W, q, mu, d, r)) / np.linalg.norm(q))


@pytest.mark.parametrize("d", [2, 3])
def test_local_steps_are_those_of_the_eigenvalues(d: int) -> None:
    rng = np.random.default_rng(d)
    A = rng.standard_normal((300, d, d))
    blocks = A @ A.transpose(0, 2, 1) + 0.3 * rng.standard_normal((300, d, d))  # skew parts
    blocks[:20] = np.diag(rng.uniform(0.1, 5.0, d))  # diagonal ones (the closed form's branch)
    sym = 0.5 * (blocks + blocks.transpose(0, 2, 1))
    lam = np.linalg.eigvalsh(sym)
    total = lam[:, 0] + lam[:, -1]
    expected = np.where(total > 0, 2.0 / np.where(total > 0, total, 1.0), 1.0)
    np.testing.assert_allclose(local_steps(blocks), expected, rtol=1e-10)
    blocks[0, 0, 0] = np.nan
    assert local_steps(blocks)[0] == 1.0


@pytest.mark.parametrize("d", [2, 3])
def test_a_contact_solved_in_closed_form_solves_its_local_problem(d: int) -> None:
    rng = np.random.default_rng(10 + d)
    solved = {"apart": 0, "stick": 0, "other": 0}
    for _ in range(400):
        A = rng.standard_normal((d, d))
        Wc = A @ A.T + 0.2 * np.eye(d) + 0.1 * rng.standard_normal((d, d))
        b = rng.standard_normal(d) * rng.choice([0.1, 1.0, 10.0])
        mu = rng.choice([0.0, 0.2, 0.9, 2.0])
        out = np.full(d, 7.0)
        if not exact_contact(Wc, b, mu, d, out):
            assert np.all(out == 7.0)
            # left over: a sliding 3-D contact, or a planar one with no solution (u_n falls
            # as r_n grows along a rim of the cone: W_nn ± μW_nt ≤ 0)
            assert d == 3 or min(Wc[0, 0] - mu * Wc[0, 1], Wc[0, 0] + mu * Wc[0, 1]) <= 0
            continue
        assert abh(Wc, b, np.array([mu]), d, out) <= 1e-12
        kind = "apart" if b[0] >= 0 else ("stick" if sticking(Wc, b, mu, d, np.empty(d))
                                          else "other")
        solved[kind] += 1
    assert min(solved.values()) > 0 if d == 2 else solved["apart"] * solved["stick"] > 0


def test_nonzero_rows_are_scipys() -> None:
    W = np.zeros((6, 6))
    W[0, 0], W[2, 5], W[5, 1], W[3, 3] = 1.0, -2.0, np.nan, 4.0
    indptr, indices, data = nonzero_rows(W)
    ref = sp.csr_matrix(np.nan_to_num(W, nan=9.0))
    np.testing.assert_array_equal(indptr, ref.indptr)
    np.testing.assert_array_equal(indices, ref.indices)
    assert np.isnan(data[3]) and np.array_equal(data[:3], ref.data[:3])  # NaN kept


def planar_chain(m: int) -> iq.FrictionContactProblem:
    """A row of m planar contacts, each pressed and pushed sideways, weakly coupled to its
    neighbours: NSGS with exact planar local solves is fast on it."""
    rng = np.random.default_rng(3)
    d, n = 2, 2 * m
    W = np.zeros((n, n))
    for c in range(m):
        W[2 * c:2 * c + 2, 2 * c:2 * c + 2] = [[2.0, 0.3], [0.3, 1.5]]
        if c + 1 < m:
            W[2 * c, 2 * c + 2] = W[2 * c + 2, 2 * c] = 0.2
    q = np.column_stack([-rng.uniform(0.5, 2.0, m), rng.uniform(-3.0, 3.0, m)]).ravel()
    return iq.FrictionContactProblem(W, q, 0.5, contact_dim=d)


def stiff_contacts(m: int) -> iq.FrictionContactProblem:
    """m 3-D contacts sliding, each W_cc with a condition number of 10⁴, weakly coupled: the
    projected fixed point contracts by ~1 − 2·10⁻⁴ a step, so the sweeps' rate is slow."""
    n = 3 * m
    W = 0.01 * np.ones((n, n))
    for c in range(m):
        W[3 * c:3 * c + 3, 3 * c:3 * c + 3] = [[1.0, 5e-3, 0.0], [5e-3, 1e-4, 0.0],
                                               [0.0, 0.0, 1.0]]
    q = np.tile([-1.0, 2.0, -0.5], m)
    return iq.FrictionContactProblem(W, q, 0.3)


def test_the_sweeps_answer_where_their_rate_is_fast() -> None:
    p = planar_chain(12)
    W, q, mu = p.W, p.q, p.mu
    r = np.empty_like(q)
    budget = sweep_budget(q.size, mu.size, np.count_nonzero(W), 100, 10)
    done = sweeps_first(nonzero_rows(W), q, mu, 2, r, 1e-8, 100, 10)
    assert done <= budget and abh(W, q, mu, 2, r) <= 0.5e-8  # no Newton needed
    res = iq.solve_friction(p, tol=1e-8)
    assert res.backend == "kernel" and res.certificate.ok
    assert abh(W, q, mu, 2, res.r) <= 1e-8 and res.error <= 1e-8
    np.testing.assert_allclose(res.u, W @ res.r + q, atol=1e-12)
    # the same answer by Newton alone (the general route's method, from r = 0)
    newton = iq.solve_friction(p, backend="newton", tol=1e-10)
    np.testing.assert_allclose(res.r, newton.r, atol=1e-7)


def test_newton_answers_where_the_sweeps_rate_is_slow() -> None:
    for m in (1, 4):
        p = stiff_contacts(m)
        W, q, mu = p.W, p.q, p.mu
        budget = sweep_budget(q.size, m, np.count_nonzero(W), 100, 10)
        assert (budget < 1.0) == (m == 1)  # one 3-D contact: a sweep costs more than Newton
        r = np.empty(3 * m)
        done = sweeps_first(nonzero_rows(W), q, mu, 3, r, 1e-8, 100, 10)
        assert done == (0 if m == 1 else 1) and abh(W, q, mu, 3, r) > 1e-8  # to Newton
        r = np.empty(3 * m)
        its, ok = solve_small(W, q, mu, scales(W.diagonal(), 3), 3, 1e-8, r, 50, 100, 10)
        assert ok and its > done and abh(W, q, mu, 3, r) <= 0.5e-8
        res = iq.solve_friction(p, tol=1e-8)
        assert res.backend == "kernel" and res.certificate.ok
        assert abh(W, q, mu, 3, res.r) <= 1e-8
        ut = res.u[1:3]  # the first contact slides: r on the cone's rim, against u_T
        assert np.linalg.norm(ut) > 1e-3
        np.testing.assert_allclose(res.r[1:3], -mu[0] * res.r[0] * ut / np.linalg.norm(ut),
                                   rtol=1e-6)
