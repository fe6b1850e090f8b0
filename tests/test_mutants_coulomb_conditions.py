"""The friction certificate's own inequalities (docs/theory.md §15, the table of figures)
against a reference written here in numpy, contact by contact, written to kill the mutants
benchmarks/mutation.py makes of impactqp/kernels/coulomb_conditions.py.

Inputs are arbitrary pairs (r, u), not solutions, so that every term of every condition is
of order one and a changed sign, index or factor shows.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from impactqp.kernels.coulomb_conditions import coulomb_violation_sums


def _reference(r: np.ndarray, u: np.ndarray, mu: np.ndarray, d: int):
    """(cone², dual², complementarity²) summed over the contacts, from the definitions of
    docs/theory.md §15."""
    cone = dual = comp = 0.0
    for c, m in enumerate(mu):
        rc, uc = r[c * d:(c + 1) * d], u[c * d:(c + 1) * d]
        omega = math.sqrt(1.0 + m * m)
        ut = float(np.linalg.norm(uc[1:]))
        tilde = uc.copy()
        tilde[0] = uc[0] + m * ut  # De Saxcé: ũ = u + μ‖u_T‖e_n
        a = max((float(np.linalg.norm(rc[1:])) - m * rc[0]) / omega, -rc[0], 0.0)
        b = max((m * float(np.linalg.norm(tilde[1:])) - tilde[0]) / omega, -tilde[0], 0.0)
        size = float(np.linalg.norm(rc) + np.linalg.norm(tilde))
        dot = abs(float(rc @ tilde))
        e = dot / size if size > 0.0 else 0.0
        cone, dual, comp = cone + a * a, dual + b * b, comp + e * e
    return cone, dual, comp


@pytest.mark.parametrize("d", [1, 2, 3])
@pytest.mark.parametrize("seed", range(3))
def test_the_sums_are_the_definitions(d, seed):
    rng = np.random.default_rng(seed)
    m = 5
    mu = rng.uniform(0.0, 1.5, m)
    mu[0] = 0.0  # the normal half-line
    r = rng.normal(size=m * d)
    u = rng.normal(size=m * d)
    got = coulomb_violation_sums(r, u, mu, d)
    np.testing.assert_allclose(got, _reference(r, u, mu, d), rtol=1e-12, atol=1e-15)


def test_each_condition_alone():
    """One contact, μ = 1/2, ω = √5/2: a point of each cone's complement, the other figures
    zero, by hand."""
    mu = np.array([0.5])
    omega = math.sqrt(1.25)
    # r outside K_μ (‖r_T‖ = 1 > μ r_n = 1/2), u = 0: cone only
    cone, dual, comp = coulomb_violation_sums(np.array([1.0, 1.0, 0.0]), np.zeros(3), mu, 3)
    assert cone == pytest.approx(((1.0 - 0.5) / omega) ** 2) and dual == 0.0 and comp == 0.0
    # r = 0, u = (−2, 0, 0): ũ_n = −2 is not in K*_μ: dual only, the larger term −ũ_n
    cone, dual, comp = coulomb_violation_sums(np.zeros(3), np.array([-2.0, 0.0, 0.0]), mu, 3)
    assert cone == 0.0 and dual == pytest.approx(4.0) and comp == 0.0
    # u = (−1, 0, 2): ũ = (0, 0, 2), μ‖ũ_T‖ − ũ_n = 1 > 0: dual (1/ω)², De Saxcé's term decides
    cone, dual, comp = coulomb_violation_sums(np.zeros(3), np.array([-1.0, 0.0, 2.0]), mu, 3)
    assert cone == 0.0 and dual == pytest.approx(1.0 / omega ** 2) and comp == 0.0
    # r = (1, 0, 0) ∈ K_μ, u = (1, 0, 0) ∈ K*_μ, r·ũ = 1: complementarity only, (1/2)²
    cone, dual, comp = coulomb_violation_sums(np.array([1.0, 0.0, 0.0]),
                                              np.array([1.0, 0.0, 0.0]), mu, 3)
    assert cone == 0.0 and dual == 0.0 and comp == pytest.approx(0.25)


def test_a_sliding_solution_satisfies_every_condition():
    """Sliding at μ = 0.3 against the slip: r = (1, −0.3, 0), u = (0, 2, 0) gives
    ũ = (0.6, 2, 0): r ∈ ∂K_μ, ũ ∈ ∂K*_μ (μ‖ũ_T‖ = 0.6 = ũ_n), r·ũ = 0.6 − 0.6 = 0."""
    mu = np.array([0.3, 0.3])
    r = np.array([1.0, -0.3, 0.0, 0.0, 0.0, 0.0])
    u = np.array([0.0, 2.0, 0.0, 0.0, 0.0, 0.0])  # the second contact: all zero
    assert coulomb_violation_sums(r, u, mu, 3) == pytest.approx((0.0, 0.0, 0.0), abs=1e-28)


@pytest.mark.parametrize("where", range(6))
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_non_finite_entry_never_passes(where, bad):
    """A NaN anywhere gives NaN sums; an infinite one never gives sums a verdict accepts."""
    mu = np.array([0.4, 0.7])
    r = np.array([1.0, 0.1, 0.0, 0.5, 0.0, 0.2])
    u = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    (r if where % 2 == 0 else u)[where] = bad
    sums = coulomb_violation_sums(r, u, mu, 3)
    if np.isnan(bad):
        assert all(np.isnan(s) for s in sums)
    else:
        assert not all(s <= 1e-6 for s in sums)
