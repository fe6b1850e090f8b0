"""Long chains at the floor: no matrix on the isotonic path, the O(N) chain certificate equal to
the general one (docs/theory.md §5, §8), and the single-chain prefix sums against the batch
path."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.laws.certificate import certify
from impactqp.model.chain_structure import ChainStructure, chain_directions
from impactqp.model.programs import velocity_program
from impactqp.model.residuals import law_residuals
from impactqp.model.structure import ChainInfo
from impactqp.qp.isotonic import chain_moreau, chain_moreau_batch

WALLS = [(False, False), (True, False), (False, True), (True, True)]
FORMED = ("M", "W", "delassus", "Minv_W", "contact_rows", "_chol", "scaled_W", "kernel_pack",
          "delassus_lu", "_formed")


def random_chain(rng: np.random.Generator, n: int, walls, scale: float) -> iq.ImpactProblem:
    masses = 10.0 ** rng.uniform(-3, 3, n)
    return iq.chain(masses, rng.standard_normal(n) * scale, left_wall=walls[0],
                    right_wall=walls[1])


def dense_twin(p: iq.ImpactProblem) -> iq.ImpactProblem:
    """The chain's impact as a general dense problem (its residuals take the dense pass)."""
    return iq.ImpactProblem(np.diag(p.chain.masses), np.asarray(p.W.todense())
                            if hasattr(p.W, "todense") else p.W, p.u_minus)


def close(a: dict, b: dict) -> None:
    """Same keys, same values up to rounding (far below the default tolerance 1e-9)."""
    assert a.keys() == b.keys()
    for k in a:
        want = float(np.ravel(b[k])[0])
        assert abs(a[k] - want) <= 1e-9 * abs(want) + 1e-12, (k, a[k], want)


@pytest.mark.parametrize("n", [10**5])
@pytest.mark.parametrize("walls", [(False, False), (True, False)])
def test_cold_chain_solve_forms_no_matrix(n, walls):
    u = np.zeros(n)
    u[0] = 1.0
    p = iq.chain(np.ones(n), u, left_wall=walls[0], right_wall=walls[1])
    r = iq.moreau(p, 0.5)
    assert r.backend == "isotonic" and r.certificate.ok
    assert not set(FORMED) & set(vars(p.structure))
    # the matrices are still there for whoever asks
    assert p.M.shape == (n, n) and p.W.shape == (n, p.n_contacts)
    assert (p.W != chain_directions(n, left_wall=walls[0], right_wall=walls[1],
                                    sparse=True)).nnz == 0


@pytest.mark.timeout(120)
def test_a_failing_chain_certificate_fails_fast(monkeypatch):
    # a defect in the O(N) chain pass (simulated: its momentum off by one) makes the exact
    # isotonic answer fail its certificate; on 10⁵ balls the solve stops at once with a
    # CertificateError naming the fast path, instead of minutes in general solvers
    import impactqp.model.residuals as residuals
    from impactqp.laws import small
    true_pass = residuals.chain_residuals

    def broken(*args):
        true_pass(*args)
        args[-1][0] += 1.0

    monkeypatch.setattr(residuals, "chain_residuals", broken)
    # the general path's fail-fast: the chain's compiled call (tested in test_small_path) is
    # set aside
    monkeypatch.setattr(small, "on_chain", lambda *args: False)
    n = 10**5
    u = np.zeros(n)
    u[0] = 1.0
    p = iq.chain(np.ones(n), u)
    with pytest.raises(iq.CertificateError, match="isotonic answer on 100000 unknowns") as err:
        iq.moreau(p, 0.5)
    assert "momentum" in str(err.value)


@pytest.mark.parametrize("sparse", [False, True])
def test_lazy_structure_serves_every_consumer(sparse):
    m, u = np.array([1.0, 2.0, 0.5, 3.0]), np.array([2.0, -1.0, 0.5, -2.0])
    lazy = iq.chain(m, u, left_wall=True, sparse=sparse)
    eager = iq.ImpactProblem(np.diag(m), chain_directions(4, left_wall=True), u)
    assert isinstance(lazy.structure, ChainStructure) and lazy.structure.sparse == sparse
    np.testing.assert_allclose(np.asarray(lazy.delassus.todense() if sparse else lazy.delassus),
                               eager.delassus, rtol=1e-15)
    np.testing.assert_allclose(lazy.structure.solve_mass(u), eager.structure.solve_mass(u))
    for backend in ("exact", "clarabel", "isotonic"):
        a, b = iq.moreau(lazy, 0.3, backend=backend), iq.moreau(eager, 0.3, backend="exact")
        np.testing.assert_allclose(a.u_plus, b.u_plus, atol=1e-8)
    qp = velocity_program(lazy)
    np.testing.assert_array_equal(qp.c, -m * u)
    assert qp.n_vars == 4 and qp.n_constraints == 4 and not qp.nonnegative
    assert qp.sparse == sparse and qp.A.shape == (4, 4)


@pytest.mark.parametrize("masses,error", [
    ([[1.0, 2.0]], iq.errors.ShapeError), ([], iq.errors.ShapeError),
    ([1.0, np.nan], iq.errors.NonFiniteError),
    ([1.0, np.inf], iq.errors.NonFiniteError), ([1.0, 0.0], iq.errors.MassMatrixError),
    ([1.0, -2.0], iq.InputError)])
def test_chain_masses_checked(masses, error):
    with pytest.raises(error, match="masses"):
        iq.chain(masses, np.zeros(np.size(masses)))
    with pytest.raises(error, match="masses"):
        ChainStructure(ChainInfo(np.array(masses, dtype=float)), sparse=False)


@pytest.mark.parametrize("walls", WALLS)
@pytest.mark.parametrize("scale", [1e-200, 1.0, 1e200])
@pytest.mark.parametrize("eps", [0.0, 0.5, 1.0])
def test_chain_certificate_equals_the_general_one(walls, scale, eps):
    rng = np.random.default_rng([int(walls[0]), int(walls[1]), int(eps * 2)])
    for n in (1, 2, 7, 60):
        p = random_chain(rng, n, walls, scale)
        if p.n_contacts == 0:
            continue
        r = iq.moreau(p, eps)
        st, um = p.structure, p.u_minus
        bad_u = r.u_plus + 1e-6 * np.abs(um).max() * rng.standard_normal(n)
        unit = p.velocity_scale / st.contact_scale  # the impulse unit of contact i
        bad_lam = r.impulses + 1e-6 * unit * rng.standard_normal(p.n_contacts)
        dense = dense_twin(p).structure  # the same impact with M and W formed
        for up, lam in ((r.u_plus, r.impulses), (bad_u, r.impulses), (r.u_plus, bad_lam)):
            fast = law_residuals(st, um, up, lam, eps, eps=eps)  # the O(N) chain loop
            close(fast, law_residuals(dense, um, up, lam, eps, eps=eps))
            close(law_residuals(st, um, up, lam, eps),  # without ε's extra residuals
                  law_residuals(dense, um, up, lam, eps))
        assert certify(p, r.u_plus, r.impulses, eps, eps=eps).ok
        assert not certify(p, bad_u, r.impulses, eps, eps=eps).ok
        assert not certify(p, r.u_plus, bad_lam, eps, eps=eps).ok


@pytest.mark.parametrize("walls", WALLS)
def test_chain_certificate_fails_corrupted_long_answers(walls):
    rng = np.random.default_rng(7)
    n = 20_000
    p = random_chain(rng, n, walls, 1.0)
    r = iq.moreau(p, 0.5)
    assert r.certificate.ok
    cases, V, s = [], p.velocity_scale, p.structure.contact_scale
    for k in (0, n // 2, n - 1):  # one velocity off by 1e-7 V in the kinetic norm
        up = r.u_plus.copy()
        up[k] += 1e-7 * V / np.sqrt(p.chain.masses[k])
        cases.append((up, r.impulses))
    for k in (0, p.n_contacts // 2, p.n_contacts - 1):  # one impulse off by 1e-7 of its unit
        lam = r.impulses.copy()
        lam[k] += 1e-7 * V / s[k]
        cases.append((r.u_plus, lam))
    cases.append((r.u_plus, -np.abs(r.impulses)))
    for up, lam in cases:
        fast = certify(p, up, lam, 0.5, eps=0.5)
        assert not fast.ok
        close(fast.residuals, law_residuals(p.structure, p.u_minus[None], up[None], lam[None],
                                            0.5, eps=0.5))  # rows: the numpy products


def test_chain_certificate_non_finite_and_zero_velocity():
    p = iq.chain([1.0, 2.0, 3.0], [1.0, 0.0, -1.0], right_wall=True)
    r = iq.moreau(p, 0.5)
    for bad in (np.nan, np.inf):
        up = r.u_plus.copy()
        up[1] = bad
        assert not certify(p, up, r.impulses, 0.5, eps=0.5).ok
        lam = r.impulses.copy()
        lam[0] = bad
        assert not certify(p, r.u_plus, lam, 0.5, eps=0.5).ok
    rest = p.with_u_minus(np.zeros(3))
    assert certify(rest, np.zeros(3), np.zeros(3), 0.5, eps=0.5).ok
    moving = certify(rest, np.array([0.0, 1e-300, 0.0]), np.zeros(3), 0.5, eps=0.5)
    assert not moving.ok
    close(moving.residuals, law_residuals(dense_twin(rest).structure, rest.u_minus,
                                          np.array([0.0, 1e-300, 0.0]), np.zeros(3), 0.5,
                                          eps=0.5))


@pytest.mark.parametrize("walls", WALLS)
@pytest.mark.parametrize("n", [1, 2, 65, 5000])
def test_single_chain_prefix_sums_match_the_batch_path(walls, n):
    rng = np.random.default_rng(n)
    m = 10.0 ** rng.uniform(-2, 2, n)
    for u in (rng.standard_normal(n), np.sort(rng.standard_normal(n)),
              -np.sort(rng.standard_normal(n)), np.zeros(n)):
        one = chain_moreau(m, u, 0.4, left_wall=walls[0], right_wall=walls[1])
        rows = chain_moreau_batch(m, u[None, :], 0.4, left_wall=walls[0], right_wall=walls[1])
        scale = 1.0 + np.abs(m * u).sum()
        np.testing.assert_allclose(one.z, rows.z[0], rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(one.impulses, rows.impulses[0], atol=1e-12 * scale)


def test_long_chain_with_walls_is_exact():
    n = 200_000
    u = np.zeros(n)
    u[0] = 1.0
    s = chain_moreau(np.ones(n), u, right_wall=True)  # everything stops at the wall
    np.testing.assert_array_equal(s.z, 0.0)
    assert np.abs(s.impulses - 1.0).max() < 1e-12  # the whole momentum reaches the wall
    s = chain_moreau(np.ones(n), -u[::-1], left_wall=True)
    np.testing.assert_array_equal(s.z, 0.0)
    assert np.abs(s.impulses - 1.0).max() < 1e-12


def test_threads_give_the_answers_of_single_solves() -> None:
    """The compiled projection keeps no state between solves: the same chains solved on two
    threads, long and short mixed, give the single solves' answers bit for bit."""
    from concurrent.futures import ThreadPoolExecutor

    from impactqp.qp import isotonic

    rng = np.random.default_rng(3)
    sizes = [5000, 7, 3000, 1, 64, 65, 4097]
    data = [(rng.uniform(0.5, 2.0, n), rng.normal(size=n)) for n in sizes]
    first = [isotonic.chain_projection(m, u, False, n == 1) for (m, u), n in zip(data, sizes)]
    with ThreadPoolExecutor(2) as pool:
        again = list(pool.map(lambda mu: isotonic.chain_projection(*mu, False, mu[0].size == 1),
                              data * 3))
    for (z, lam), (z2, lam2) in zip(first * 3, again):
        np.testing.assert_array_equal(z, z2)
        np.testing.assert_array_equal(lam, lam2)
