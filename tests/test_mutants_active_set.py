"""What the active-set search returns when it stops early (docs/theory.md §9, "The compiled
active-set search"), written to kill the mutants benchmarks/mutation.py makes of
impactqp/kernels/active_set.py that change what a stopped search hands back.

A search stopped by its step budget returns the point it has reached: a feasible iterate
(finite, x ≥ 0, w = Gx + q, the passive set where x > 0), which callers may use as a warm
start; a budget of no steps leaves the start x = 0 untouched. The problems are small integer
LCPs with redundant columns (G singular), which make the search follow rays.
"""

from __future__ import annotations

import numpy as np
import pytest

from impactqp.kernels.active_set import ITERATION_LIMIT, NO_SOLUTION, SOLVED, lcp_psd


def _search(G: np.ndarray, q: np.ndarray, warm: np.ndarray, budget: int):
    passive = warm.copy()
    x = np.full(q.size, np.nan)
    w = np.full(q.size, np.nan)
    status = lcp_psd(G, q, passive, x, w, budget)
    return status, x, w, passive


def _assert_feasible_iterate(G, q, x, w, passive):
    assert np.all(np.isfinite(x)) and np.all(np.isfinite(w))
    assert x.min() >= 0.0
    scale = np.abs(q).max() + np.abs(G).max() * x.max() + 1.0
    np.testing.assert_allclose(w, G @ x + q, rtol=0, atol=1e-9 * scale)
    np.testing.assert_array_equal(passive, x > 0.0)


def _redundant(rng: np.random.Generator):
    """G = AᵀA with a repeated column (a redundant contact), integer data."""
    m = int(rng.integers(3, 6))
    A = rng.integers(-1, 2, size=(m, m)).astype(float)
    A[:, -1] = A[:, 0]
    b = rng.integers(-2, 3, size=m).astype(float)
    return A.T @ A, -(A.T @ b)


# two equal columns 0 and 2: warm-started on {0, 1}, the search joins 2 along a ray
RAY = (np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 1.0]]),
       np.array([-2.0, -1.0, -3.0]), np.array([True, True, False]))


@pytest.mark.parametrize("budget", range(1, 8))
def test_a_search_stopped_on_a_ray_returns_a_feasible_iterate(budget):
    G, q, warm = RAY
    status, x, w, passive = _search(G, q, warm, budget)
    _assert_feasible_iterate(G, q, x, w, passive)
    if status == SOLVED:  # the solution: x₁ = 1 and x₀ + x₂ = 3 (both columns are one)
        assert x[1] == pytest.approx(1.0) and x[0] + x[2] == pytest.approx(3.0)
        assert w.min() >= -1e-12 and abs(x @ w) <= 1e-12
    else:
        assert status == ITERATION_LIMIT


@pytest.mark.parametrize("seed", range(4))
def test_every_stopped_search_returns_a_feasible_iterate(seed):
    rng = np.random.default_rng(seed)
    for _ in range(60):
        G, q = _redundant(rng)
        for warm in (np.zeros(q.size, dtype=bool), rng.random(q.size) < 0.5):
            for budget in (1, 2, 3, 5):
                status, x, w, passive = _search(G, q, warm, budget)
                if status != NO_SOLUTION:
                    _assert_feasible_iterate(G, q, x, w, passive)


@pytest.mark.parametrize("warm", [(True, True, False, False, False),
                                  (False, False, True, False, True),
                                  (True, False, True, True, True)])
def test_a_budget_of_no_steps_leaves_the_start(warm):
    """The budget counts every step, the warm start's first move to the minimizer on its
    passive set included: with none, nothing moves and the search says it ran out."""
    G = np.array([[3.0, -3.0, 3.0, 0.0, 3.0], [-3.0, 4.0, -4.0, 1.0, -3.0],
                  [3.0, -4.0, 5.0, -1.0, 3.0], [0.0, 1.0, -1.0, 3.0, 0.0],
                  [3.0, -3.0, 3.0, 0.0, 3.0]])
    q = np.array([-1.0, 1.0, -1.0, 2.0, -1.0])
    status, x, w, passive = _search(G, q, np.array(warm), 0)
    assert status == ITERATION_LIMIT
    np.testing.assert_array_equal(x, 0.0)
    np.testing.assert_array_equal(w, q)
    assert not passive.any()
    status, x, w, passive = _search(G, q, np.array(warm), 100)  # and with steps it solves
    assert status == SOLVED
    assert x.min() >= 0.0 and w.min() >= -1e-12 and abs(x @ w) <= 1e-12
