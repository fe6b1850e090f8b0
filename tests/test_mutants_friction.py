"""The friction kernels' sums and NSGS's local solve (docs/theory.md §15) against references
written here in numpy from the theory's formulas, written to kill the mutants
benchmarks/mutation.py makes of impactqp/kernels/friction.py.

The projection on K_μ is the tests' own, from its closed form (tests/cone_reference.py,
docs/theory.md §15): x itself when ‖x_T‖ ≤ μx_n, 0 when μ‖x_T‖ ≤ −x_n, else
a·(1, μx_T/‖x_T‖) with a = (x_n + μ‖x_T‖)/(1 + μ²).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from cone_reference import project_onto_cone

from impactqp.kernels.friction import certificate_sums, nsgs


def _reference_sums(r, u, mu, d):
    f2 = comp = pen = cone = 0.0
    for c, m in enumerate(mu):
        rc, uc = r[c * d:(c + 1) * d], u[c * d:(c + 1) * d]
        tilde = uc.copy()
        tilde[0] += m * float(np.linalg.norm(uc[1:]))  # ũ = u + μ‖u_T‖e_n
        F = rc - project_onto_cone(rc - tilde, m)
        f2 += float(F @ F)
        comp += abs(float(rc @ tilde))
        pen += max(-uc[0], 0.0) ** 2
        cone += float(np.sum((rc - project_onto_cone(rc, m)) ** 2))
    return f2, comp, pen, cone


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("seed", range(3))
def test_certificate_sums_are_the_definitions(d, seed):
    rng = np.random.default_rng(seed)
    m = 6
    mu = rng.uniform(0.1, 1.2, m)
    r = rng.normal(size=m * d)
    u = rng.normal(size=m * d)
    u[0], u[d] = -0.7, 0.4  # one contact penetrating, one separating, at least
    got = certificate_sums(r, u, mu, d)
    np.testing.assert_allclose(got, _reference_sums(r, u, mu, d), rtol=1e-12, atol=1e-15)


def test_the_penetration_sum_counts_only_approaching_contacts():
    mu = np.array([0.5, 0.5, 0.5])
    r = np.zeros(9)
    u = np.array([-2.0, 0.0, 0.0, 3.0, 0.0, 0.0, -0.5, 0.0, 0.0])
    _, _, pen, _ = certificate_sums(r, u, mu, 3)
    assert pen == pytest.approx(2.0 ** 2 + 0.5 ** 2)


@pytest.mark.parametrize("mu", [2.0, 1.5])
def test_one_sweep_solves_a_single_contact(mu):
    """With one contact the local problem is the whole problem: one sweep, with local steps
    enough, stops only once a step moves r by less than 10⁻⁶‖r‖, close to the solution.

    W = I, q = (−1, 2, 2): sliding, u_n = 0 gives r_n = 1 and r_T = −μr_n q_T/‖q_T‖ when
    ‖q_T‖ = 2√2 > μ r_n (u_T = (‖q_T‖ − μ)q_T/‖q_T‖ ≠ 0)."""
    W = np.eye(3)
    q = np.array([-1.0, 2.0, 2.0])
    r = np.zeros(3)
    sweeps, err = nsgs(W, q, np.array([mu]), 3, r, 0.0, 1, 5000)
    expected = np.array([1.0, -mu / math.sqrt(2.0), -mu / math.sqrt(2.0)])
    assert sweeps == 1
    assert np.linalg.norm(r - expected) <= 1e-4 * np.linalg.norm(expected)
    assert err <= 1e-4
