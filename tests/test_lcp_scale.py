"""solve_lcp at every scale floats can hold: the same answer in any units, and a named error
(never NaN or a zero that is no solution) when the solution itself is not representable."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq

SCALES = [1e-300, 1e-200, 1e-155, 1e-50, 1.0, 1e50, 1e155, 1e200, 1e300, 1e306]
"""Scales of q (and G) whose products with order-one entries stay normal floats (subnormal
numbers carry fewer digits: the input itself would change)."""


def _random_lcp(seed: int, k: int = 5) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((k, k + 2))
    return A @ A.T, rng.standard_normal(k)


@pytest.mark.parametrize("seed", range(4))
def test_solutions_scale_with_q_and_g(seed):
    G, q = _random_lcp(seed)
    ref = iq.solve_lcp(G, q)
    assert np.any(ref.z > 0)
    for sq in SCALES:
        for sg in (1e-300, 1e-100, 1.0, 1e100, 1e300):
            z_scale = sq / sg
            if not 1e-300 < z_scale < 1e300:
                continue
            r = iq.solve_lcp(G * sg, q * sq)
            assert np.isfinite(r.z).all() and r.ok
            np.testing.assert_allclose(r.z / z_scale, ref.z, rtol=1e-9, atol=1e-12)
            assert r.error <= 1e-12


@pytest.mark.parametrize("sq, sg", [(1e-300, 1e100), (1e300, 1e-100), (1e-100, 1e300),
                                    (1e308 / 3, 1e-300)])
def test_an_unrepresentable_solution_is_a_named_error(sq, sg):
    G, q = _random_lcp(0)
    with pytest.raises(iq.OutOfRangeError, match="floats cannot represent"):
        iq.solve_lcp(G * sg, q * sq)
    assert issubclass(iq.OutOfRangeError, iq.InputError)


def test_tiny_and_huge_q_are_not_mistaken_for_zero_or_overflow():
    G = np.array([[2.0, -1.0], [-1.0, 2.0]])
    for s in (1e-320, 1e-250, 1e155, 1e300):
        r = iq.solve_lcp(G, np.array([-1.0, 0.5]) * s)
        np.testing.assert_allclose(r.z, [0.5 * s, 0.0], rtol=1e-12)
        assert r.error == 0.0 or r.error < 1e-12
