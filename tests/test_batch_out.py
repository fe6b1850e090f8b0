"""Batches written into an earlier result's arrays (``out=``, laws.batch_out): the same
numbers as fresh arrays on every route, every entry rewritten and every row certified, and
each unusable buffer refused with an error that names it."""

import dataclasses

import numpy as np
import pytest

import impactqp as iq
import impactqp.laws.batch as batch
from impactqp.errors import InputError, ShapeError
from impactqp.laws.chain_rows import ChainRows

ROUTES = [
    (lambda: iq.newtons_cradle(3), iq.Moreau(0.5), "auto"),  # compiled chain pass
    (lambda: iq.chain([1.0, 2.0, 1.0], np.ones(3), left_wall=True), iq.Moreau(0.0), "auto"),
    (lambda: iq.newtons_cradle(12), iq.Moreau(0.3), "auto"),  # projection by rows
    (lambda: iq.random_impact(5, 4, seed=2), iq.Moreau(0.5), "auto"),  # compiled rows
    (lambda: iq.random_impact(5, 4, seed=2), iq.Newton(0.5), "auto"),  # active-set search
    (lambda: iq.newtons_cradle(4), iq.SectorLaw(), "auto"),  # closed form
    (lambda: iq.newtons_cradle(3), iq.Moreau(0.2), "clarabel"),  # rows one by one
]


def spoiled(result):
    """``result`` with every entry of its arrays overwritten by NaN (a stale buffer)."""
    for array in (result.u_plus, result.impulses, *result.residuals.values()):
        array[...] = np.nan
    return result


@pytest.mark.parametrize("make, law, backend", ROUTES)
def test_out_gives_the_fresh_numbers(monkeypatch, make, law, backend):
    p = make()
    rng = np.random.default_rng(3)
    k = 40 if backend == "clarabel" else 300
    U, V = rng.standard_normal((k, p.n_dof)), rng.standard_normal((k, p.n_dof))
    ref = iq.solve_batch(p, law, U, backend)
    monkeypatch.setattr(batch, "CHUNK_ROWS", 64)  # several chunks, threads on them
    for n_jobs in (1, 2):
        out = spoiled(iq.solve_batch(p, law, V, backend))
        b = iq.solve_batch(p, law, U, backend, n_jobs=n_jobs, out=out)
        assert b.u_plus is out.u_plus and b.impulses is out.impulses
        assert all(b.residuals[key] is value for key, value in out.residuals.items())
        assert b.backend == ref.backend and b.ok.all()
        np.testing.assert_array_equal(b.u_plus, ref.u_plus)
        np.testing.assert_array_equal(b.impulses, ref.impulses)
        assert list(b.residuals) == list(ref.residuals)
        for key, value in ref.residuals.items():
            np.testing.assert_array_equal(b.residuals[key], value)


def test_out_streams_and_forms_pass_it():
    p = iq.newtons_cradle(3)
    rng = np.random.default_rng(4)
    r = iq.moreau_batch(p, rng.standard_normal((50, 3)))
    for _ in range(3):
        U = rng.standard_normal((50, 3))
        r = iq.moreau_batch(p, U, 0.4, out=r)
        np.testing.assert_array_equal(r.u_plus, iq.moreau_batch(p, U, 0.4).u_plus)
    s = iq.sector_law_batch(p, rng.standard_normal((50, 3)))
    U = rng.standard_normal((50, 3))
    assert iq.sector_law_batch(p, U, out=s).u_plus is s.u_plus
    np.testing.assert_array_equal(s.u_plus, np.sort(U, axis=1))


def test_failing_rows_are_resolved_into_out(monkeypatch):
    solve = ChainRows.solve

    def corrupt(self, U, Up, Lam):
        solve(self, U, Up, Lam)
        Up[3, 1] += 1e-3  # row 3 of each chunk breaks the impact equation

    p = iq.newtons_cradle(3)
    U = np.random.default_rng(2).standard_normal((40, 3))
    ref = iq.moreau_batch(p, U, 0.2)
    out = spoiled(iq.moreau_batch(p, U, 0.2))
    monkeypatch.setattr(ChainRows, "solve", corrupt)
    monkeypatch.setattr(batch, "CHUNK_ROWS", 16)
    b = iq.moreau_batch(p, U, 0.2, out=out)
    assert b.resolved == 3 and b.ok.all()  # rows 3, 19, 35
    for i in (3, 19, 35):
        assert p.norm(b.u_plus[i] - ref.u_plus[i]) <= 1e-12 * p.norm(U[i])


@pytest.fixture
def batch3():
    p = iq.newtons_cradle(3)
    U = np.random.default_rng(6).standard_normal((20, 3))
    return p, U, iq.moreau_batch(p, U)


def test_out_must_be_a_result(batch3):
    p, U, r = batch3
    with pytest.raises(InputError, match="BatchResult of an earlier batch, got tuple"):
        iq.moreau_batch(p, U, out=(r.u_plus, r.impulses, r.residuals))


@pytest.mark.parametrize("field, value, error, message", [
    ("u_plus", np.zeros((19, 3)), ShapeError, r"out.u_plus must have shape \(20, 3\)"),
    ("impulses", np.zeros((20, 3)), ShapeError, r"out.impulses must have shape \(20, 2\)"),
    ("u_plus", np.zeros((20, 3), dtype=np.float32), InputError, "dtype float64"),
    ("u_plus", [[0.0] * 3] * 20, InputError, "out.u_plus must be a numpy array"),
    ("impulses", np.zeros((2, 20)).T, InputError, "out.impulses must be C-contiguous"),
    ("u_plus", np.zeros((20, 6))[:, ::2], InputError, "out.u_plus must be C-contiguous"),
])
def test_bad_arrays_are_refused(batch3, field, value, error, message):
    p, U, r = batch3
    with pytest.raises(error, match=message):
        iq.moreau_batch(p, U, out=dataclasses.replace(r, **{field: value}))


def test_read_only_and_aliased_buffers_are_refused(batch3):
    p, U, r = batch3
    frozen = r.u_plus.copy()
    frozen.flags.writeable = False
    with pytest.raises(InputError, match="out.u_plus is read-only"):
        iq.moreau_batch(p, U, out=dataclasses.replace(r, u_plus=frozen))
    with pytest.raises(InputError, match="out.u_plus shares memory with U_minus"):
        iq.moreau_batch(p, r.u_plus, out=r)  # u⁺ written over the u⁻ it is checked against
    memory = np.zeros(100)  # u⁺ and Λ overlapping in one buffer
    overlapping = dataclasses.replace(r, u_plus=memory[:60].reshape(20, 3),
                                      impulses=memory[50:90].reshape(20, 2))
    with pytest.raises(InputError, match="out.u_plus and out.impulses share memory"):
        iq.moreau_batch(p, U, out=overlapping)
    s = iq.sector_law_batch(p, U)  # its residuals are separate arrays
    residuals = dict(s.residuals, law_residual=s.residuals["momentum"])
    with pytest.raises(InputError, match=r"out.residuals\['momentum'\] and "
                                            r"out.residuals\['law_residual'\] share memory"):
        iq.sector_law_batch(p, U, out=dataclasses.replace(s, residuals=residuals))


def test_residuals_of_another_law_or_layout_are_refused(batch3):
    p, U, r = batch3
    sector = iq.sector_law_batch(p, U)
    with pytest.raises(InputError, match="out holds the residuals"):
        iq.moreau_batch(p, U, out=sector)
    with pytest.raises(InputError, match="out holds the residuals"):
        iq.sector_law_batch(p, U, out=r)
    with pytest.raises(InputError, match="residuals must be a dict"):
        iq.moreau_batch(p, U, out=dataclasses.replace(r, residuals=list(r.residuals.values())))


def test_residuals_apart_from_a_table_are_filled_too():
    """The chain pass writes its residual columns side by side; an out whose residuals are
    separate arrays, or strided columns (a result of the one-by-one route), gets the same
    numbers through a scratch block."""
    p = iq.newtons_cradle(3)
    U = np.random.default_rng(7).standard_normal((100, 3))
    ref = iq.moreau_batch(p, U, 0.3)
    r = iq.moreau_batch(p, U, 0.3)
    loose = dataclasses.replace(r, residuals={key: np.full(100, np.nan)
                                              for key in r.residuals})
    one_by_one = spoiled(iq.moreau_batch(p, U[::-1], 0.3, backend="clarabel"))
    for out in (loose, one_by_one):
        b = iq.moreau_batch(p, U, 0.3, out=out)
        assert b.backend == "isotonic" and b.u_plus is out.u_plus
        assert all(b.residuals[key] is value for key, value in out.residuals.items())
        np.testing.assert_array_equal(b.u_plus, ref.u_plus)
        for key, value in ref.residuals.items():
            np.testing.assert_array_equal(b.residuals[key], value)
