"""Reference numbers of the 3-ball cradle (docs/theory.md §5) on every backend and form."""

import numpy as np
import pytest

import impactqp as iq

BACKENDS = ["auto", "exact", "nnls", "clarabel", "osqp", "cvxpy", "cvxpy:CLARABEL",
            "qpsolvers:daqp", "qpsolvers:piqp"]


def expected(eps, v=1.0, m=1.0):
    """u⁺ and Λ of Moreau's law on the 3-ball cradle, by linear interpolation along the
    half-line u⁺ = (1+ε)z − εu⁻ between the ε = 0 and ε = 1 reference points of docs/theory.md
    §5."""
    u0, l0 = np.array([v / 3, v / 3, v / 3]), np.array([2 * m * v / 3, m * v / 3])
    u1, l1 = np.array([-v / 3, 2 * v / 3, 2 * v / 3]), np.array([4 * m * v / 3, 2 * m * v / 3])
    return u0 + eps * (u1 - u0), l0 + eps * (l1 - l0)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("eps", [0.0, 0.5, 1.0])
@pytest.mark.parametrize("form", ["impulse", "velocity"])
def test_cradle_reference(backend, eps, form):
    if backend == "nnls" and form == "velocity":
        with pytest.raises(iq.BackendUnsuitableError):
            iq.moreau(iq.newtons_cradle(v=2.0, mass=3.0), eps, backend=backend, form=form)
        return
    p = iq.newtons_cradle(v=2.0, mass=3.0)
    r = iq.moreau(p, eps=eps, backend=backend, form=form)
    u, lam = expected(eps, v=2.0, m=3.0)
    np.testing.assert_allclose(r.u_plus, u, rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(r.impulses, lam, rtol=1e-7, atol=1e-9)
    assert r.certificate.ok
    np.testing.assert_allclose(r.z, [2 / 3] * 3, atol=1e-9)
    np.testing.assert_allclose(r.z + r.z_perp, p.u_minus, atol=1e-12)
    assert r.energy_before == pytest.approx(0.5 * 3.0 * 4.0)
    # ε = 1 conserves energy, ε < 1 loses some
    if eps == 1.0:
        assert r.energy_after == pytest.approx(r.energy_before, rel=1e-9)
    else:
        assert r.energy_after < r.energy_before


def test_classification_of_section5():
    p = iq.newtons_cradle(v=1.0)
    observed = iq.classify(p, [0.0, 0.0, 1.0])
    assert observed.alpha_deg == pytest.approx(30.0, abs=1e-9)
    assert observed.dissipation == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(observed.impulses, [1.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(observed.topology, [2**-0.5, 2**-0.5], atol=1e-12)
    for eps in (0.0, 0.5, 1.0):
        c = iq.moreau(p, eps).classification
        assert c.alpha_deg == pytest.approx(0.0, abs=1e-6)
        # the dissipation is a square root (of an energy ratio): a rounding of 1e-16 in the
        # energies of an exact u⁺ shows as 1e-8 in it
        assert c.dissipation == pytest.approx(eps, abs=1e-7)
    # both ε = 1 points lie on the same energy sphere
    assert iq.moreau(p, 1.0).classification.dissipation == pytest.approx(observed.dissipation)


def test_no_contact_means_no_jump():
    p = iq.ImpactProblem(np.eye(2), np.zeros((2, 0)), [1.0, -2.0])
    r = iq.moreau(p, 0.5)
    np.testing.assert_array_equal(r.u_plus, p.u_minus)
    assert r.impulses.shape == (0,)
    assert p.admissible_set().contains(p.u_minus)


def test_problem_exposes_delassus_and_energy():
    p = iq.newtons_cradle(mass=2.0, v=3.0)
    np.testing.assert_allclose(p.delassus, 0.5 * np.array([[2, -1], [-1, 2]]))
    np.testing.assert_allclose(p.gamma_minus, [-3.0, 0.0])
    assert p.kinetic_energy() == pytest.approx(9.0)


def test_chain_with_walls_directions():
    p = iq.chain([1.0, 2.0], [1.0, -1.0], left_wall=True, right_wall=True)
    np.testing.assert_array_equal(p.W, [[1, -1, 0], [0, 1, -1]])
    r = iq.moreau(p, 0.0)
    np.testing.assert_allclose(r.u_plus, [0.0, 0.0], atol=1e-12)
    assert r.admissible
