"""Fast paths (isotonic chains, the active-set kernel) and the batch API against the references."""

import numpy as np
import pytest

import impactqp as iq


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("n,m,red", [(4, 3, 0), (6, 6, 2), (5, 8, 4), (10, 10, 0)])
def test_kernel_matches_enumeration_and_nnls(seed, n, m, red):
    p = iq.random_impact(n, m, seed=seed, redundant=red, consistent=seed % 2 == 0)
    for eps in (0.0, 0.6, 1.0):
        k = iq.moreau(p, eps, backend="kernel")
        assert k.backend == "kernel" and k.certificate.ok
        for ref in (iq.moreau(p, eps, backend="nnls"), iq.moreau(p, eps, backend="exact",
                                                                   form="velocity")):
            assert p.norm(k.u_plus - ref.u_plus) <= 1e-9 * p.velocity_scale


@pytest.mark.parametrize("walls", [(False, False), (True, False), (False, True), (True, True)])
def test_isotonic_matches_qp_on_chains(walls):
    rng = np.random.default_rng(7)
    for _ in range(5):
        masses = rng.uniform(0.1, 10.0, 7)
        p = iq.chain(masses, rng.standard_normal(7), left_wall=walls[0], right_wall=walls[1])
        for eps in (0.0, 0.5, 1.0):
            a = iq.moreau(p, eps, backend="isotonic")
            b = iq.moreau(p, eps, backend="exact", form="velocity")
            assert a.backend == "isotonic"
            assert p.norm(a.u_plus - b.u_plus) <= 1e-10 * p.velocity_scale
            np.testing.assert_allclose(p.W @ a.impulses, p.W @ b.impulses, atol=1e-9)


def test_auto_picks_fast_paths():
    assert iq.moreau(iq.newtons_cradle(), 1.0).backend == "isotonic"  # the chain's call
    assert iq.moreau(iq.newtons_cradle(), 1.0, form="impulse").backend == "kernel"
    assert iq.moreau(iq.newtons_cradle(20), 1.0).backend == "isotonic"
    assert iq.moreau(iq.random_impact(5, 4, seed=0), 1.0).backend == "kernel"
    assert iq.newton(iq.newtons_cradle(), [1.0, 0.5]).backend == "kernel"
    assert iq.moreau(iq.random_impact(30, 20, seed=0), 1.0).backend == "kernel"
    assert iq.moreau(iq.random_impact(30, 20, seed=0), 1.0, backend="nnls").backend == "nnls"


def test_named_fast_path_that_does_not_apply():
    with pytest.raises(iq.BackendUnsuitableError, match="chains"):
        iq.moreau(iq.random_impact(4, 3, seed=0), 0.5, backend="isotonic")
    with pytest.raises(iq.BackendUnsuitableError, match="dense"):
        iq.moreau(iq.chain(np.ones(600), np.r_[1.0, np.zeros(599)], sparse=True), 0.5,
                  backend="kernel")


def test_long_chain_is_exact():
    n = 100_000
    p = iq.newtons_cradle(n_balls=n)
    r = iq.moreau(p, 0.0)
    assert r.backend == "isotonic" and r.certificate.ok
    np.testing.assert_allclose(r.u_plus, 1.0 / n, rtol=1e-12)


@pytest.mark.parametrize("make", [lambda: iq.newtons_cradle(5),
                                  lambda: iq.random_impact(6, 4, seed=3, redundant=1),
                                  lambda: iq.random_impact(30, 20, seed=3)])
def test_batch_equals_loop(make):
    p = make()
    U = np.random.default_rng(1).standard_normal((40, p.n_dof))
    b = iq.moreau_batch(p, U, 0.7)
    assert b.ok.all() and b.u_plus.shape == U.shape
    for i in range(0, 40, 7):
        r = iq.moreau(p.with_u_minus(U[i]), 0.7)
        assert p.norm(b.u_plus[i] - r.u_plus) <= 1e-9 * max(p.norm(U[i]), 1e-300)


def test_batch_rejects_bad_rows():
    p = iq.newtons_cradle()
    with pytest.raises(iq.errors.ShapeError, match="U_minus"):
        iq.moreau_batch(p, np.zeros((4, 2)))
    with pytest.raises(iq.errors.NonFiniteError, match="U_minus"):
        iq.moreau_batch(p, np.full((2, 3), np.nan))
    with pytest.raises(iq.errors.RestitutionError):
        iq.moreau_batch(p, np.zeros((2, 3)), eps=2.0)


def test_sector_law_batch_matches_single_calls():
    p = iq.newtons_cradle(5)
    U = np.random.default_rng(4).standard_normal((50, 5))
    b = iq.sector_law_batch(p, U)
    assert b.ok.all()
    for i in range(0, 50, 9):
        r = iq.sector_law(p.with_u_minus(U[i]))
        np.testing.assert_array_equal(b.u_plus[i], r.u_plus)
        np.testing.assert_allclose(b.impulses[i], r.impulses, atol=1e-14)
    with pytest.raises(iq.errors.SectorLawError):
        iq.sector_law_batch(iq.chain([1.0, 2.0, 1.0], [1.0, 0, 0]), U[:, :3])
