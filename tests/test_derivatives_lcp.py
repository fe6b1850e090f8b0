"""The LCP derivative core (docs/theory.md §18–§19) against central finite differences of an
LCP solved by enumerating its active sets, on stable active sets and on both sides of kinks."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from impactqp.derivatives.lcp import (
    ActiveSet,
    classify,
    directional,
    limiting_active_sets,
    tangent,
)
from impactqp.errors import InputError, ShapeError


def enumerate_lcp(G: np.ndarray, q: np.ndarray) -> np.ndarray:
    """λ of 0 ≤ λ ⟂ Gλ + q ≥ 0 by trying every active set (G positive definite: unique)."""
    m = q.size
    for size in range(m + 1):
        for A in itertools.combinations(range(m), size):
            lam = np.zeros(m)
            A = list(A)
            if A:
                lam[A] = np.linalg.solve(G[np.ix_(A, A)], -q[A])
            w = G @ lam + q
            if lam.min() >= -1e-12 and w.min() >= -1e-12:
                return lam
    raise AssertionError("no solution found")


def problem(m: int, seed: int, degenerate: tuple[int, ...] = ()):
    """G positive definite and q whose solution has the given contacts degenerate."""
    rng = np.random.default_rng(seed)
    B = rng.normal(size=(m, m))
    G = B @ B.T + 0.5 * np.eye(m)
    active = rng.random(m) < 0.5
    lam = np.where(active, rng.uniform(0.5, 2.0, m), 0.0)
    w = np.where(active, 0.0, rng.uniform(0.5, 2.0, m))
    lam[list(degenerate)] = 0.0
    w[list(degenerate)] = 0.0
    return G, w - G @ lam, lam, w


def test_classify_sorts_contacts_and_measures_the_margin() -> None:
    a = classify([2.0, 0.0, 0.0, 1e-13], [0.0, 3.0, 1e-14, 0.0], tol=1e-10)
    assert a.active.tolist() == [True, False, False, False]
    assert a.degenerate.tolist() == [False, False, True, True]
    assert a.inactive.tolist() == [False, True, False, False]
    assert a.margin == 2.0
    assert classify([], [], 1e-9).margin == np.inf
    with pytest.raises(ShapeError):
        classify([1.0], [1.0, 2.0], 1e-9)


@pytest.mark.parametrize("seed", range(8))
def test_tangent_matches_central_differences_on_a_stable_set(seed: int) -> None:
    m = 6
    G, q, lam, w = problem(m, seed)
    aset = classify(lam, w, 1e-9)
    assert not aset.degenerate.any() and aset.margin >= 0.5
    rng = np.random.default_rng(100 + seed)
    dq = rng.normal(size=m)
    S = rng.normal(size=(m, m))
    dG = S + S.T
    h = 1e-6
    fd = (enumerate_lcp(G + h * dG, q + h * dq) - enumerate_lcp(G - h * dG, q - h * dq)) / (2 * h)
    got = tangent(G, lam, aset, dG=dG, dq=dq)
    assert np.allclose(got, fd, rtol=1e-6, atol=1e-7)
    assert np.allclose(directional(G, lam, aset, dG=dG, dq=dq), got, atol=1e-14)
    # k directions at once are the columns one at a time
    Q = rng.normal(size=(m, 3))
    cols = tangent(G, lam, aset, dq=Q)
    assert cols.shape == (m, 3)
    assert np.allclose(cols[:, 1], tangent(G, lam, aset, dq=Q[:, 1]), atol=1e-14)


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("degenerate", [(0,), (1, 3)])
def test_directional_matches_both_sides_of_a_kink(seed: int, degenerate) -> None:
    m = 5
    G, q, lam, w = problem(m, seed, degenerate)
    aset = classify(lam, w, 1e-9)
    assert aset.degenerate[list(degenerate)].all()
    rng = np.random.default_rng(200 + seed)
    dq = rng.normal(size=m)
    h = 1e-7
    # λ is piecewise affine in q: one-sided differences are exact up to round-off
    plus = (enumerate_lcp(G, q + h * dq) - lam) / h
    minus = (enumerate_lcp(G, q - h * dq) - lam) / h
    assert np.allclose(directional(G, lam, aset, dq=dq), plus, atol=1e-6)
    assert np.allclose(directional(G, lam, aset, dq=-dq), minus, atol=1e-6)
    # the one-sided derivative along ±dq is one of the limiting tangents, linear in each
    tangents = [tangent(G, lam, ActiveSet(mask, np.zeros(m, bool), 0.0), dq=dq)
                for mask in limiting_active_sets(aset, cap=64)]
    assert any(np.allclose(t, plus, atol=1e-6) for t in tangents)
    assert any(np.allclose(-t, minus, atol=1e-6) for t in tangents)


def test_directional_with_dG_at_a_kink() -> None:
    G, q, lam, w = problem(4, 3, (2,))
    aset = classify(lam, w, 1e-9)
    rng = np.random.default_rng(7)
    S = rng.normal(size=(4, 4))
    dG, dq = S + S.T, rng.normal(size=4)
    h = 1e-6
    one_sided = (enumerate_lcp(G + h * dG, q + h * dq) - lam) / h
    assert np.allclose(directional(G, lam, aset, dG=dG, dq=dq), one_sided, atol=1e-4)


def test_large_degenerate_set_goes_to_the_lcp_solver() -> None:
    m = 13
    G, q, lam, w = problem(m, 11, tuple(range(12)))
    aset = classify(lam, w, 1e-9)
    assert aset.degenerate.sum() >= 12
    dq = np.random.default_rng(3).normal(size=m)
    plus = (enumerate_lcp(G, q + 1e-7 * dq) - lam) / 1e-7
    assert np.allclose(directional(G, lam, aset, dq=dq), plus, atol=1e-5)


def test_singular_G_gives_the_minimum_norm_tangent() -> None:
    # two identical contacts: G_AA singular, the impulse split is not unique
    G = np.array([[1.0, 1.0], [1.0, 1.0]])
    lam = np.array([0.5, 0.5])
    aset = classify(lam, G @ lam + np.array([-1.0, -1.0]), 1e-9)
    d = tangent(G, lam, aset, dq=np.array([-1.0, -1.0]))
    assert np.allclose(d, [0.5, 0.5])  # the minimum-norm split of a total change of 1


def test_limiting_active_sets_enumerate_and_cap() -> None:
    aset = ActiveSet(np.array([True, False, False, False]),
                     np.array([False, True, False, True]), 1.0)
    sets = limiting_active_sets(aset, cap=10)
    assert len(sets) == 4 and sets[0].tolist() == [True, False, False, False]
    assert sets[-1].tolist() == [True, True, False, True]
    assert len({tuple(s) for s in sets}) == 4
    assert len(limiting_active_sets(aset, cap=2)) == 2
    with pytest.raises(InputError):
        limiting_active_sets(aset, cap=0)


def test_bad_shapes_are_named() -> None:
    G, _, lam, w = problem(3, 0)
    aset = classify(lam, w, 1e-9)
    with pytest.raises(ShapeError, match="dq"):
        tangent(G, lam, aset, dq=np.ones(4))
    with pytest.raises(ShapeError, match="dG"):
        tangent(G, lam, aset, dG=np.ones((2, 2)))
    with pytest.raises(ShapeError, match="G must"):
        tangent(np.ones((2, 2)), lam, aset)
