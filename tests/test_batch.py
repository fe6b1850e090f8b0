"""Batches of impacts (laws.batch): rows equal single solves, every row certified, results
independent of the chunking and of the threads."""

import numpy as np
import pytest
from scipy.optimize import isotonic_regression

import impactqp as iq
import impactqp.laws.batch as batch
from impactqp.laws.chain_rows import MAX_BALLS, ChainRows

WALLS = [(False, False), (True, False), (False, True), (True, True)]


def rows_with_ties(rng, k, n):
    """Random rows, some with equal entries (ties in the regression) and some exact zeros."""
    U = rng.standard_normal((k, n))
    U[::5] = np.round(U[::5])
    U[1::9, : n // 2] = 0.0
    return U


CHAINS = [(n, walls) for n in (1, 2, 3, 5, MAX_BALLS) for walls in WALLS
          if n > 1 or any(walls)]  # a free single ball has no contact


@pytest.mark.parametrize("n, walls", CHAINS)
def test_chain_rows_equal_single_solves(n, walls):
    rng = np.random.default_rng(10 * n + sum(walls))
    masses = rng.uniform(0.1, 10.0, n)
    p = iq.chain(masses, np.ones(n), left_wall=walls[0], right_wall=walls[1])
    U = rows_with_ties(rng, 60, n)
    for eps in (0.0, 0.4, 1.0):
        b = iq.moreau_batch(p, U, eps)
        assert b.backend == "isotonic" and b.resolved == 0 and b.ok.all()
        for i, u in enumerate(U):
            r = iq.moreau(p.with_u_minus(u), eps)
            scale = max(p.norm(u), 1e-300)
            assert p.norm(b.u_plus[i] - r.u_plus) <= 1e-12 * scale
            if walls != (True, True):  # else Λ is one point of a half-line (docs/theory.md §5)
                np.testing.assert_allclose(b.impulses[i], r.impulses, atol=1e-12 * scale * 10)


@pytest.mark.parametrize("walls", WALLS)
def test_chain_residuals_are_the_laws_own(walls):
    """The column formulas give the residuals of Moreau.residuals, also for rows whose scale
    needs the general routine (zero, tiny, huge)."""
    rng = np.random.default_rng(3)
    p = iq.chain([1.0, 3.0, 0.5, 2.0], np.ones(4), left_wall=walls[0], right_wall=walls[1])
    U = rows_with_ties(rng, 50, 4)
    U[7], U[8], U[9] = 0.0, 1e-200 * U[10], 1e200 * U[11]
    for eps in (0.0, 0.7):
        b = iq.moreau_batch(p, U, eps)
        assert b.ok.all() and b.resolved == 0
        ref = iq.Moreau(eps).residuals(p.structure, U, b.u_plus, b.impulses)
        assert list(b.residuals) == list(ref)
        for key, value in ref.items():
            np.testing.assert_allclose(b.residuals[key], value, rtol=1e-12, atol=1e-15)
        assert b.u_plus[7].tolist() == [0.0] * 4


@pytest.mark.parametrize("n", [2, 3, 4, 6])
def test_min_max_projection_equals_pava(n):
    rng = np.random.default_rng(n)
    masses = rng.uniform(0.5, 2.0, n)
    p = iq.chain(masses, np.ones(n))
    U = rows_with_ties(rng, 200, n)
    z, lam = np.empty_like(U), np.empty((len(U), p.n_contacts))
    ChainRows(p.structure, 0.0).solve(U, z, lam)
    ref = [isotonic_regression(u, weights=masses).x for u in U]  # scipy's PAVA, independent
    np.testing.assert_allclose(z, ref, rtol=0, atol=1e-14)
    assert np.all(np.diff(z, axis=1) >= 0)


@pytest.mark.parametrize("make,law", [
    (lambda: iq.newtons_cradle(3), iq.Moreau(0.5)),
    (lambda: iq.chain([1.0, 2.0, 1.0], np.ones(3), left_wall=True), iq.Moreau(0.0)),
    (lambda: iq.newtons_cradle(12), iq.Moreau(0.3)),  # compiled projection by rows
    (lambda: iq.random_impact(5, 4, seed=2), iq.Moreau(0.5)),  # active-set search
    (lambda: iq.newtons_cradle(4), iq.SectorLaw()),  # closed form
])
def test_independent_of_chunks_and_threads(monkeypatch, make, law):
    p = make()
    U = np.random.default_rng(5).standard_normal((300, p.n_dof))
    ref = iq.solve_batch(p, law, U)
    for rows in (30, 64, 1 << 20):
        monkeypatch.setattr(batch, "CHUNK_ROWS", rows)
        for n_jobs in (1, 2, 3):
            b = iq.solve_batch(p, law, U, n_jobs=n_jobs)
            np.testing.assert_array_equal(b.u_plus, ref.u_plus)
            np.testing.assert_array_equal(b.impulses, ref.impulses)
            for key, value in ref.residuals.items():
                np.testing.assert_array_equal(b.residuals[key], value)


def test_corrupted_chain_row_is_resolved(monkeypatch):
    solve = ChainRows.solve

    def corrupt(self, U, Up, Lam):
        solve(self, U, Up, Lam)
        Up[3, 1] += 1e-3  # row 3 of the chunk breaks the impact equation

    monkeypatch.setattr(ChainRows, "solve", corrupt)
    monkeypatch.setattr(batch, "CHUNK_ROWS", 16)
    p = iq.newtons_cradle(3)
    U = np.random.default_rng(2).standard_normal((40, 3))
    b = iq.moreau_batch(p, U, 0.2)
    assert b.resolved == 3 and b.ok.all()  # rows 3, 19, 35
    for i in (3, 19, 35):
        r = iq.moreau(p.with_u_minus(U[i]), 0.2)
        assert p.norm(b.u_plus[i] - r.u_plus) <= 1e-12 * p.norm(U[i])


def test_corrupted_kernel_row_is_resolved(monkeypatch):
    """The kernel backend's rows (a chain longer than the compiled path takes, Newton's law)
    are checked by the law's certificate: a wrong impulse claimed solved is solved again."""
    from impactqp.qp.backends import kernel
    solve_many = kernel.solve_many

    def corrupt(qp, C, **kw):
        X, Y, done = solve_many(qp, C, **kw)
        X[0] += 0.5  # a wrong impulse, claimed solved
        return X, Y, done

    monkeypatch.setattr(kernel, "solve_many", corrupt)
    p = iq.newtons_cradle(12)
    U = np.random.default_rng(1).standard_normal((10, 12))
    b = iq.solve_batch(p, iq.Newton(0.5), U, backend="kernel")
    assert b.backend == "kernel" and b.resolved == 1 and b.ok.all()
    r = iq.newton(p.with_u_minus(U[0]), 0.5)
    assert p.norm(b.u_plus[0] - r.u_plus) <= 1e-12 * p.norm(U[0])


def test_corrupted_compiled_rows_are_resolved():
    """Dense batches run the compiled impact row by row; with its operators corrupted (M⁻¹W
    halved) every row misses its own certificate and is solved again on the general path."""
    p = iq.random_impact(5, 3, seed=4)
    st = p.structure
    U = np.random.default_rng(2).standard_normal((12, 5))
    clean = iq.moreau_batch(p, U, 0.3)
    assert clean.backend == "kernel" and clean.resolved == 0 and clean.ok.all()
    packed = st.kernel_pack.copy()
    start = st.n * st.n + st.m * st.n
    packed[start:start + st.n * st.m] *= 0.5
    st.__dict__["kernel_pack"] = packed
    try:
        b = iq.moreau_batch(p, U, 0.3)
    finally:
        del st.__dict__["kernel_pack"]
    assert b.resolved == 12 and b.ok.all()
    np.testing.assert_allclose(b.u_plus, clean.u_plus, rtol=1e-9, atol=1e-12)


def test_failing_closed_form_row_is_rejected(monkeypatch):
    rows = iq.SectorLaw.closed_form_rows

    def corrupt(self, problem, U):
        Up, Lam = rows(self, problem, U)
        Up[-1, 0] += 1.0
        return Up, Lam

    monkeypatch.setattr(iq.SectorLaw, "closed_form_rows", corrupt)
    U = np.random.default_rng(0).standard_normal((5, 3))
    with pytest.raises(iq.CertificateError, match="row 4"):
        iq.sector_law_batch(iq.newtons_cradle(3), U)


def test_paths_agree_and_empty_batches():
    p = iq.newtons_cradle(3)
    U = np.random.default_rng(8).standard_normal((100, 3))
    a, b = iq.moreau_batch(p, U, 0.5), iq.moreau_batch(p, U, 0.5, backend="kernel")
    assert (a.backend, b.backend) == ("isotonic", "kernel")
    np.testing.assert_allclose(a.u_plus, b.u_plus, atol=1e-14)
    np.testing.assert_allclose(a.impulses, b.impulses, atol=1e-14)
    empty = iq.moreau_batch(p, np.zeros((0, 3)))
    assert empty.u_plus.shape == (0, 3) and empty.impulses.shape == (0, 2)
    assert set(empty.residuals) == set(a.residuals)
