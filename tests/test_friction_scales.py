"""Frictional problems far from order one (docs/theory.md §15): the certificate's sums of
squares underflowed or overflowed at ‖q‖ ≈ 1e∓160, where r = 0 passed at any speed of
penetration; solve_friction works in units of max|qᵢ| there and scales r back."""

import numpy as np
import pytest

import impactqp as iq
from impactqp.model.friction import certify_friction

SCALES = [1e-300, 1e-170, 1e-120, 1.0, 1e120, 1e170, 1e300]


@pytest.mark.parametrize("scale", SCALES)
def test_a_sliding_contact_is_solved_and_judged_alike_at_every_scale(scale):
    # one contact of W = I in the plane, q = (−1, 0.5)·scale: it slides with r = (1, −0.3)
    problem = iq.FrictionContactProblem(np.eye(2), [-scale, 0.5 * scale], 0.3, contact_dim=2)
    assert not certify_friction(problem, np.zeros(2)).ok  # full-speed penetration fails
    assert not certify_friction(problem, np.array([0.9, -0.27]) * scale).ok
    result = iq.solve_friction(problem)
    assert result.certificate.ok
    np.testing.assert_allclose(result.r / scale, [1.0, -0.3], rtol=1e-12)
    np.testing.assert_allclose(result.u / scale, [0.0, 0.2], atol=1e-12)


@pytest.mark.parametrize("backend", ["nsgs", "clarabel", "newton"])
def test_every_method_takes_a_tiny_problem(backend):
    rng = np.random.default_rng(3)
    A = rng.standard_normal((9, 9))
    W = A @ A.T + 0.1 * np.eye(9)
    q = rng.standard_normal(9)
    q[::3] = -np.abs(q[::3])
    unit = iq.solve_friction(iq.FrictionContactProblem(W, q, 0.5), backend=backend)
    tiny = iq.solve_friction(iq.FrictionContactProblem(W, q * 1e-200, 0.5), backend=backend)
    np.testing.assert_allclose(tiny.u * 1e200, unit.u, atol=1e-7 * np.abs(unit.u).max())


def test_coulomb_batches_rows_far_from_order_one():
    problem = iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0])
    law = iq.Coulomb(0.3, 0.5)
    U = np.array([[1.0, -2.0, 0.0], [1e200, -2e200, 0.0], [1e-200, -2e-200, 0.0]])
    batch = iq.solve_batch(problem, law, U)
    single = iq.solve(problem, law).u_plus
    np.testing.assert_allclose(batch.u_plus / np.array([1.0, 1e200, 1e-200])[:, None],
                               np.tile(single, (3, 1)), rtol=1e-12)


@pytest.mark.parametrize("mass", [1e-12, 1e-8, 1.0, 1e8, 1e12])
def test_s_with_friction_does_not_depend_on_the_unit_of_mass(mass):
    # a planar box on two corners (3 dof, 4 columns: Λ not unique, the cone program decides):
    # the distance program is posed in contact units; in raw units its interior-point
    # answer was not certified at M × 1e8 and called a certified answer inadmissible at 1e-12
    a, b = 0.5, 0.25
    M = np.diag([1.0, 1.0, (a * a + b * b) / 3]) * mass
    W = np.column_stack([[0.0, 1.0, -a], [1.0, 0.0, b], [0.0, 1.0, a], [1.0, 0.0, b]])
    problem = iq.ImpactProblem(M, W, [1.0, -1.0, 0.3], contact_dim=2)
    result = iq.solve(problem, iq.Coulomb(0.3, 0.2))
    membership = result.admissible
    assert membership.method == "optimizer" and membership.member
    assert membership.kinetic < 1e-9
    np.testing.assert_allclose(membership.impulses, result.impulses,
                               atol=1e-6 * np.abs(result.impulses).max())
    outside = problem.admissible_set(mu=0.3).contains(result.u_plus + [0.0, 0.0, 1.0])
    assert not outside.member
