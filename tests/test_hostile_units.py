"""Problems stated in units far from order one, as a user would: the answer transforms as
physics says, or the problem is refused by name (OutOfRangeError) where floats cannot pose
its Delassus matrix G = WᵀM⁻¹W — never a solver library's own exception or a wrong claim."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import impactqp as iq
from impactqp.laws.certificate import certify

W = np.array([[-1.0, 0.0], [1.0, -1.0], [0.0, 1.0]])
U = np.array([1.0, 0.0, -0.5])
COEFFICIENT = {"moreau": 0.5, "newton": np.array([1.0, 0.5]),
               "fremond": np.array([[0.5, 0.1], [0.0, 0.3]])}
EPS = {"moreau": 0.5}
LAWS = [iq.Moreau(0.5), iq.Newton([1.0, 0.5]), iq.Fremond([[0.5, 0.1], [0.0, 0.3]])]


@pytest.mark.parametrize("law", LAWS, ids=lambda law: law.name)
def test_units_of_mass_velocity_and_direction_transform_the_answer(law):
    """M × a, u⁻ × b, W × c: u⁺ × b and Λ × ab/c, and the same verdicts (checked both ways:
    the scaled problem's answer against the scaled answer, and back)."""
    M = np.array([[2.0, 0.3, 0.0], [0.3, 1.0, 0.1], [0.0, 0.1, 1.5]])
    ref = iq.solve(iq.ImpactProblem(M, W, U), law)
    for a, b, c in [(1e6, 1e4, 1e-3), (1e-6, 1e-4, 1e3), (1e9, 1e-4, 1.0)]:
        r = iq.solve(iq.ImpactProblem(M * a, W * c, U * b), law)
        np.testing.assert_allclose(r.u_plus / b, ref.u_plus, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(r.impulses * c / (a * b), ref.impulses, rtol=1e-9,
                                   atol=1e-12)
        assert r.certificate.ok and ref.certificate.ok
        assert bool(r.admissible) == bool(ref.admissible)
        # the other way: the reference answer, scaled, passes the scaled problem's
        # certificate, and the scaled answer, scaled back, passes the reference's
        scaled = iq.ImpactProblem(M * a, W * c, U * b)
        assert certify(scaled, ref.u_plus * b, ref.impulses * a * b / c, COEFFICIENT[law.name],
                       eps=EPS.get(law.name)).ok
        assert certify(iq.ImpactProblem(M, W, U), r.u_plus / b, r.impulses * c / (a * b),
                       COEFFICIENT[law.name], eps=EPS.get(law.name)).ok


@pytest.mark.parametrize("M, Wx", [
    (np.eye(3) * 1e-320, W),          # subnormal masses: M⁻¹ = 1e320 is beyond the floats
    (np.eye(3) * 1e-300, W * 1e5),    # G = 1e310
    (np.eye(3) * 1e300, W * 1e-10),   # G = 1e-320, a subnormal: Λ = 1e310
], ids=["subnormal-M", "G-overflows", "G-underflows"])
@pytest.mark.parametrize("law", LAWS[:2], ids=lambda law: law.name)
def test_a_delassus_matrix_beyond_the_floats_is_named(M, Wx, law):
    with pytest.raises(iq.OutOfRangeError, match="Delassus"):
        iq.solve(iq.ImpactProblem(M, Wx, U), law)
    with pytest.raises(iq.OutOfRangeError, match="Delassus"):
        iq.ImpactProblem(sp.csc_matrix(M), sp.csc_matrix(Wx), U)


def test_a_sparse_non_diagonal_subnormal_mass_is_named():
    M = sp.csc_matrix(np.array([[2.0, 0.5, 0.0], [0.5, 1.0, 0.0], [0.0, 0.0, 1.0]]) * 1e-320)
    with pytest.raises(iq.OutOfRangeError, match="Delassus"):
        iq.solve(iq.ImpactProblem(M, sp.csc_matrix(W), U), iq.Moreau(0.5))


@pytest.mark.parametrize("masses", [[1e-320] * 3, [1.0, 1e-320, 1.0], [1e308] * 3])
def test_chains_with_masses_beyond_the_floats_are_named(masses):
    with pytest.raises(iq.OutOfRangeError, match="Delassus"):
        iq.chain(masses, [1.0, 0.0, 0.0])
    iq.chain([1e308], [1.0])  # one ball and no wall: no contact, nothing to refuse


def test_extreme_but_representable_units_still_solve():
    for M, Wx in [(np.eye(3) * 1e-300, W), (np.eye(3) * 1e300, W), (np.eye(3), W * 1e150)]:
        r = iq.solve(iq.ImpactProblem(M, Wx, U), iq.Moreau(0.5))
        np.testing.assert_allclose(r.u_plus, [-0.25, 0.25, 0.5], rtol=1e-12)
        assert r.certificate.ok
