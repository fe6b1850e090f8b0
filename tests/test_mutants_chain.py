"""The chain's impulses by compensated running sums (docs/theory.md §5, "Impulses by anchored
prefix sums"): a few ulps whatever a block's length, against exact rational sums written
here, to kill the mutants benchmarks/mutation.py makes of impactqp/kernels/chain.py.

The velocities come in pairs (a, −a − δ) with a ≈ 10⁸ and δ ≈ 1: the running sums pass
through 10⁸ and come back to O(1), so an uncompensated sum keeps about 10⁻⁸ of error there,
while the compensated one keeps a few ulps of the impulses themselves.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from impactqp.kernels.chain import project

EPS = np.finfo(float).eps


def _pairs(rng: np.random.Generator, pairs: int):
    a = rng.uniform(1e8, 2e8, pairs)
    delta = rng.uniform(0.5, 1.5, pairs)
    u = np.empty(2 * pairs)
    u[0::2], u[1::2] = a, -a - delta
    m = np.repeat(rng.uniform(0.5, 2.0, pairs), 2)  # one mass per pair: Σ m(a − a − δ) < 0
    return m, u


def _project(m, u, left, right):
    n = u.size
    z, L = np.empty(n), np.empty(n + 1)
    project(m, u, left, right, z, L, np.empty(n + 1, dtype=np.int64), np.empty(n))
    return z, L


def _assert_close(L, exact):
    """Each impulse within a few ulps of the largest exact one near it (the anchor's)."""
    scale = max(abs(float(x)) for x in exact)
    for j, (got, want) in enumerate(zip(L, exact)):
        assert abs(Fraction(float(got)) - want) <= 8 * EPS * scale, j


@pytest.mark.parametrize("seed", range(2))
def test_impulses_between_two_walls_are_exact_to_a_few_ulps(seed):
    """z = 0 and the least impulses L_j = max_i E_i − E_j, E_j = Σ_{i<j} m_i(z_i − u_i)."""
    m, u = _pairs(np.random.default_rng(seed), 1000)
    z, L = _project(m, u, True, True)
    np.testing.assert_array_equal(z, 0.0)
    terms = [Fraction(float(x)) for x in m * (z - u)]  # the rounded terms the kernel sums
    E = [Fraction(0)]
    for t in terms:
        E.append(E[-1] + t)
    top = max(E)
    _assert_close(L, [top - e for e in E])


@pytest.mark.parametrize("seed", range(2))
def test_impulses_hanging_from_a_left_wall_are_exact_to_a_few_ulps(seed):
    """Every suffix of m·u sums to less than 0, so the whole chain is clipped at the left wall:
    z = 0, no impulse at the open right end, L_j = Σ_{i≥j} m_i(z_i − u_i)."""
    m, u = _pairs(np.random.default_rng(10 + seed), 1000)
    z, L = _project(m, u, True, False)
    np.testing.assert_array_equal(z, 0.0)
    terms = [Fraction(float(x)) for x in m * (z - u)]
    exact = [Fraction(0)]
    for t in reversed(terms):
        exact.append(exact[-1] + t)
    _assert_close(L, exact[::-1])
