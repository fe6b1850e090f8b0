"""The chain certificate of many rows side by side (impactqp/kernels/chain_batch.py) against the
single pass over one chain (docs/theory.md §5, §8), planted bugs it must catch, and the
projection's pooling and anchored impulses (impactqp/kernels/chain.py) against scipy's
isotonic regression and exact rational sums."""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np
import pytest
from scipy.optimize import isotonic_regression

import impactqp as iq
from impactqp.kernels.chain import project
from impactqp.kernels.chain_batch import BLOCK, chain_residual_columns, chain_residual_rows
from impactqp.kernels.residuals import chain_residuals
from impactqp.laws import chain_rows
from impactqp.qp.isotonic import chain_moreau_batch

SHAPES = [(n, left, right) for n, left, right in itertools.product(range(1, 8), (False, True),
                                                                    (False, True))
          if n - 1 + left + right > 0]


def _rows(rng, k, n, m):
    """Random rows with every kind the certificate meets: ordinary, far outside the unit
    range (rescaled), at rest, NaN and infinite answers."""
    Um, Up, Lam = rng.standard_normal((k, n)), rng.standard_normal((k, n)), rng.random((k, m))
    Um[3] *= 1e70
    Um[4] *= 1e-70
    Um[5] = 0.0
    Up[6, -1] = np.nan
    Lam[7, 0] = np.inf
    return Um, Up, Lam


@pytest.mark.parametrize(("n", "left", "right"), SHAPES)
def test_rows_side_by_side_equal_the_single_pass_bit_for_bit(n, left, right):
    rng = np.random.default_rng(n + 10 * left + 20 * right)
    m = n - 1 + left + right
    k = 2 * BLOCK + 37  # three blocks, the last one short
    masses = 10.0 ** rng.uniform(-2, 2, n)
    scale = rng.uniform(0.5, 2.0, m)
    Um, Up, Lam = _rows(rng, k, n, m)
    for E, eps, moreau in ((0.3, 0.3, True), (0.0, 0.0, True), (0.7, 0.0, False)):
        got = chain_residual_rows(Um, Up, Lam, masses, 1.0 / masses, scale, left, right, E,
                                  eps, moreau)
        row = np.empty(6)
        for r in range(k):
            chain_residuals(Um[r], Up[r], Lam[r], masses, 1.0 / masses, scale, left, right, E,
                            eps, moreau, row)
            np.testing.assert_array_equal(got[r], row)
        assert not (got[6] <= 1.0).all() and not (got[7] <= 1.0).all()  # NaN, inf fail


def test_columns_written_into_a_view_of_the_batch():
    rng = np.random.default_rng(1)
    masses, scale = np.ones(3), np.ones(2)
    Um, Up, Lam = _rows(rng, 300, 3, 2)
    out = np.full((6, 900), -1.0)
    chain_residual_columns(Um, Up, Lam, masses, masses, scale, False, False, 0.5, 0.5, True,
                           out[:, 300:600])
    np.testing.assert_array_equal(out[:, :300], -1.0)
    np.testing.assert_array_equal(out[:, 600:], -1.0)
    np.testing.assert_array_equal(out[:, 300:600].T, chain_residual_rows(
        Um, Up, Lam, masses, masses, scale, False, False, 0.5, 0.5, True))


@pytest.mark.parametrize(("left", "right"), [(False, False), (True, False), (False, True)])
def test_rows_side_by_side_catch_planted_bugs(left, right):
    """Exact answers pass; each planted defect fails on its own row and no other."""
    rng = np.random.default_rng(5)
    n, k, eps = 4, 600, 0.5
    masses = rng.uniform(0.5, 2.0, n)
    U = rng.standard_normal((k, n))
    sol = chain_moreau_batch(masses, U, eps, left_wall=left, right_wall=right)
    p = iq.chain(masses, U[0], left_wall=left, right_wall=right)
    scale = p.structure.contact_scale

    def failing(Up, Lam):
        res = chain_residual_rows(U, Up, Lam, masses, 1.0 / masses, scale, left, right, eps,
                                  eps, True)
        return set(np.flatnonzero(~(res <= 1e-9).all(axis=1)))

    assert failing(sol.u_plus, sol.impulses) == set()
    V = np.sqrt((masses * U * U).sum(axis=1))
    busy = np.flatnonzero((np.abs(sol.impulses) > 1e-3).any(axis=1))  # rows the law changes
    assert busy.size > 100
    a, b, c, d, e = busy[[0, 10, 20, 30, 40]]
    Up, Lam = sol.u_plus.copy(), sol.impulses.copy()
    Up[a, 2] += 1e-7 * V[a]  # a velocity off
    Lam[b, 0] += 1e-7 * V[b]  # an impulse off
    Lam[c] *= (1.0 - eps) / (1.0 + eps)  # a solve that scales by 1 − ε instead of 1 + ε
    Up[d] = (Up[d] + eps * U[d]) / (1.0 + eps)  # a solve that forgets the restitution
    Lam[e] = -Lam[e]  # impulses of the wrong sign
    assert failing(Up, Lam) == {a, b, c, d, e}


def test_a_batch_with_a_mutated_solve_is_never_returned_uncertified(monkeypatch):
    """A defect in the column solve (its impulses scaled by 1 − ε for 1 + ε) is caught by the
    rows' certificate: those rows are solved again one by one, and the batch returned is
    the exact one."""
    rng = np.random.default_rng(2)
    p, U, eps = iq.newtons_cradle(3), rng.standard_normal((3000, 3)), 0.5
    good = iq.moreau_batch(p, U, eps)
    assert good.resolved == 0 and good.ok.all()
    solve = chain_rows.ChainRows.solve

    def mutated(self, U, Up, Lam):
        solve(self, U, Up, Lam)
        Lam *= (1.0 - eps) / (1.0 + eps)

    monkeypatch.setattr(chain_rows.ChainRows, "solve", mutated)
    bad = iq.moreau_batch(p, U, eps)
    active = (np.abs(good.impulses) > 1e-12).any(axis=1)
    assert bad.resolved == int(active.sum()) > 1000
    assert bad.ok.all()
    np.testing.assert_allclose(bad.u_plus, good.u_plus, rtol=0, atol=1e-12)
    np.testing.assert_allclose(bad.impulses, good.impulses, rtol=0, atol=1e-12)


def _pooled(rng, n, kind):
    if kind == "singletons":  # nothing pools: every ball its own block
        return np.sort(rng.standard_normal(n))
    if kind == "pairs":  # blocks of one and two balls in turn
        u = np.arange(n, dtype=float)
        u[1::3] += 1.5
        return u
    if kind == "one block":  # the cradle: one block growing ball by ball
        return np.r_[1.0, np.zeros(n - 1)]
    if kind == "ties":
        return np.round(rng.standard_normal(n))
    return rng.standard_normal(n)


@pytest.mark.parametrize("kind", ["singletons", "pairs", "one block", "ties", "random"])
@pytest.mark.parametrize("n", [1, 2, 7, 400])
def test_projection_against_scipy_and_exact_sums(kind, n):
    """z is scipy's weighted isotonic regression; L_{j+1} = Σ_{i ≤ j} mᵢ(u⁻ᵢ − zᵢ) summed
    exactly in rationals from scipy's z (a free chain: L₀ = 0)."""
    rng = np.random.default_rng(n)
    u = _pooled(rng, n, kind)
    for masses in (np.ones(n), rng.uniform(0.25, 4.0, n)):
        z, L = np.empty(n), np.empty(n + 1)
        project(masses, u, False, False, z, L, np.empty(n + 1, dtype=np.int64), np.empty(n))
        ref = isotonic_regression(u, weights=masses).x
        np.testing.assert_allclose(z, ref, rtol=1e-13, atol=1e-13)
        exact, total = [Fraction(0)], Fraction(0)
        for j in range(n):
            total += Fraction(float(masses[j])) * (Fraction(float(u[j])) - Fraction(float(ref[j])))
            exact.append(total)
        size = 1.0 + float(np.abs(masses * u).sum())
        assert max(abs(float(a - Fraction(float(b)))) for a, b in zip(exact, L)) < 1e-12 * size
        assert L[0] == 0.0 and L[n] == 0.0


@pytest.mark.parametrize(("left", "right"), [(True, False), (False, True), (True, True)])
@pytest.mark.parametrize("kind", ["singletons", "pairs", "ties", "random"])
def test_projection_with_walls_is_scipys_clipped(left, right, kind):
    rng = np.random.default_rng(11)
    n = 50
    u = _pooled(rng, n, kind) - 0.4 * n * (kind == "pairs")
    masses = rng.uniform(0.25, 4.0, n)
    z = np.empty(n)
    project(masses, u, left, right, z, np.empty(n + 1), np.empty(n + 1, dtype=np.int64),
            np.empty(n))
    ref = isotonic_regression(u, weights=masses).x
    ref = np.zeros(n) if left and right else np.maximum(ref, 0) if left else np.minimum(ref, 0)
    np.testing.assert_allclose(z, ref, rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("walls", [(False, False), (True, False), (False, True), (True, True)])
@pytest.mark.parametrize("n", [2, 3, 5])
def test_block_solve_equals_the_compiled_projection(walls, n):
    """The batch's block solve (min–max formula, anchored sums, rows side by side) against
    the one-impact compiled projection (pooling adjacent violators, compensated sums) on
    rows with ties, a block and a half long: the two algorithms agree to round-off."""
    rng = np.random.default_rng(n)
    masses = rng.uniform(0.5, 2.0, n)
    p = iq.chain(masses, np.ones(n), left_wall=walls[0], right_wall=walls[1])
    U = rng.standard_normal((BLOCK + BLOCK // 2, n))
    U[::3, 0] = U[::3, -1]
    U[::5] = np.round(U[::5])
    for eps in (0.0, 0.4):
        Up, Lam = np.empty_like(U), np.empty((len(U), p.n_contacts))
        chain_rows.ChainRows(p.structure, eps).solve(U, Up, Lam)
        lo = 0 if walls[0] else 1
        for r in range(len(U)):
            z, L = np.empty(n), np.empty(n + 1)
            project(masses, U[r], *walls, z, L, np.empty(n + 1, dtype=np.int64), np.empty(n))
            np.testing.assert_allclose(Up[r], (1 + eps) * z - eps * U[r], rtol=0, atol=1e-14)
            np.testing.assert_allclose(Lam[r], (1 + eps) * L[lo:lo + p.n_contacts], rtol=0,
                                       atol=1e-13)
