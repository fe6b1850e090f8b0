"""The compiled derivative of a dense impact (impactqp.kernels.local_map and the cells of
impactqp.kernels.derivative): the cell it factors gives the map the eigen-decomposition path
gives, its certificate sees a wrong factor, and the batch's kept cells give every row what
the row's own derivative gives."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.derivatives.complementarity import ComplementarityMap
from impactqp.derivatives.impact import ImpactDerivative
from impactqp.kernels import derivative as cells_kernel
from impactqp.kernels.impact import solve_impact_rows

LAWS = [iq.Moreau(0.5), iq.Newton(0.3), iq.Newton([0.1, 0.9, 0.4, 0.0, 0.7]),
        iq.Fremond(0.2 * np.eye(5) + 0.04)]


def smooth_answers(law, count: int = 4):
    """Certified answers of ``law`` on random 5-contact impacts whose derivative is smooth."""
    found = []
    for seed in range(40):
        p = iq.random_impact(9, 5, seed=seed, consistent=False)
        r = iq.solve(p, law)
        if r.derivative().status == "smooth":
            found.append((p, r))
        if len(found) == count:
            return found
    raise AssertionError("too few smooth answers among the random impacts")


def tangents(d: ImpactDerivative, rng: np.random.Generator) -> dict[str, np.ndarray]:
    return {name: rng.standard_normal(shape) for name, shape in d.inputs.items()}


@pytest.mark.parametrize("law", LAWS)
def test_compiled_cell_gives_the_eigen_path_map(law) -> None:
    rng = np.random.default_rng(5)
    for p, r in smooth_answers(law):
        d = r.derivative()
        assert "_cell" in d.local.__dict__  # formed by the compiled kernel
        # the reference: a fresh eigen-decomposition of G_AA in numpy, on the same answer
        ref_map = ComplementarityMap(p.M, p.W, p.u_minus, r.impulses, d.local.parameter,
                                     kink_tol=1e-9)
        ref = ImpactDerivative(p, law, r.u_plus, r.impulses, ref_map)
        assert ref.status == "smooth"
        assert np.array_equal(d.local.active, ref_map.active)
        assert np.allclose(d.local.K, ref_map.K, rtol=1e-9,
                           atol=1e-12 * np.abs(ref_map.K).max())
        assert np.isclose(d.certificate.margin, ref.certificate.margin, rtol=1e-9)
        assert d.certificate.ok and d.certificate.linear_solve < 1e-12
        # the 1-norm condition number bounds the 2-norm one within a factor |A|
        k = max(int(ref_map.active.sum()), 1)
        assert ref_map.condition / k * (1 - 1e-9) <= d.local.condition
        assert d.local.condition <= k * ref_map.condition * (1 + 1e-9)
        for wrt in d.inputs:
            assert np.allclose(d.jacobian(wrt), ref.jacobian(wrt), rtol=1e-9, atol=1e-10)
        t = tangents(d, rng)
        for a, b in zip(d.jvp(**t), ref.jvp(**t), strict=True):
            assert np.allclose(a, b, rtol=1e-9, atol=1e-10)
        ub, lb = rng.standard_normal(p.n_dof), rng.standard_normal(p.n_impulses)
        got, want = d.vjp(ub, lb), ref.vjp(ub, lb)
        for name in want:
            assert np.allclose(got[name], want[name], rtol=1e-9, atol=1e-10)
        # VJP and JVP are transposes: <ū, du⁺> + <Λ̄, dΛ> = Σ <input cotangent, tangent>
        du, dl = d.jvp(**t)
        assert np.isclose(ub @ du + lb @ dl, sum(np.sum(got[k] * t[k]) for k in t), rtol=1e-9)


def test_a_wrong_factor_shows_in_the_residual() -> None:
    p = iq.random_impact(8, 5, seed=3)
    G = np.ascontiguousarray(p.structure.delassus)
    R = 1.5 * np.ascontiguousarray(np.asarray(p.W).T)  # ∂q/∂u⁻ of Moreau's law, ε = ½
    active = np.array([True, True, False, True, True])
    cells = cells_kernel.new_cells(5, 0)
    assert cells_kernel.factor_cell(G, active, cells, 0) == 4
    cells_kernel.measure_cell(G, R, active, cells, 0)
    assert cells.residual[0] < 1e-13
    right = cells.K[0].copy()
    # a factor of a slightly different matrix, measured against G itself
    cells_kernel.factor_cell(G + 1e-3 * np.diag(np.diag(G)), active, cells, 0)
    cells_kernel.measure_cell(G, R, active, cells, 0)
    assert 1e-5 < cells.residual[0] < 1e-1
    assert not np.allclose(cells.K[0][np.ix_(active, active)], right[np.ix_(active, active)])


def test_the_certificate_judges_the_linear_solves() -> None:
    p = iq.random_impact(9, 5, seed=1, consistent=False)
    (p, r), = smooth_answers(iq.Moreau(0.5), count=1)
    d = r.derivative()
    local = ComplementarityMap(p.M, p.W, p.u_minus, r.impulses, d.local.parameter,
                               kink_tol=1e-9)
    assert ImpactDerivative(p, d.impact_law, r.u_plus, r.impulses, local).certificate.ok
    local.K = 1.01 * local.K  # a planted wrong inverse of G_AA
    local.__dict__.pop("_measures", None)
    bad = ImpactDerivative(p, d.impact_law, r.u_plus, r.impulses, local).certificate
    assert not bad.ok and bad.linear_solve > 1e-3


@pytest.mark.parametrize("m", [10, 18])  # cells kept by active set (m ≤ MASK_BITS), or one
def test_batch_cells_give_each_row_its_own_derivative(m) -> None:
    assert (m <= cells_kernel.MASK_BITS) == (m == 10)
    p = iq.random_impact(m + 3, m, seed=4, consistent=False)
    rng = np.random.default_rng(2)
    rows = 80 if m == 10 else 30
    U, dU, Ub = (rng.standard_normal((rows, m + 3)) for _ in range(3))
    U[-10:] = 2.0 * U[:10]  # the same cells again (the map is positively homogeneous)
    law = iq.Moreau(0.3)
    b = iq.derivative_batch(p, law, U, jvp=dU, vjp=Ub)
    assert b.backend == "kernel"
    cells = set()
    for i in range(rows):
        d = iq.derivative(p.with_u_minus(U[i]), law)
        cells.add(tuple(d.local.active))
        assert b.status[i] == d.status
        assert np.allclose(b.jvp[i], d.jvp(u_minus=dU[i]).u_plus, atol=1e-11)
        assert np.allclose(b.vjp[i], d.vjp(u_plus=Ub[i])["u_minus"], atol=1e-11)
        assert np.isclose(b.margin[i], d.certificate.margin, rtol=1e-9)
    if m == 10:  # more cells than a call keeps: the rows met are finished, cells refilled
        assert len(cells) > cells_kernel.CACHED_CELLS + 1


def test_kernel_rows_mark_kinks_and_uncertified_rows() -> None:
    # 3-ball rows through the kernel itself: kinks, rows the compiled solve does not certify
    # (NaN u⁻) and rows after them; then cells that miss the tolerance
    p, law, k = iq.newtons_cradle(3), iq.Moreau(0.0), 60
    rng = np.random.default_rng(7)
    U, dU, Ub = (rng.normal(size=(k, 3)) for _ in range(3))
    U[5], U[6] = [1.0, 0.0, 0.5], [2.0, 0.0, 1.0]  # the three-ball kink, twice
    U[[10, 30]] = np.nan
    Up, Lam, _, solved = solve_impact_rows(p.structure.kernel_pack, U, np.zeros((2, 2)), 0.0,
                                           True, 1e-9, np.zeros(2, dtype=bool))
    assert list(np.flatnonzero(~solved)) == [10, 30]
    out = cells_kernel.Rows(Up, Lam, np.empty((k, 3)), np.empty((k, 3)),
                            np.empty(k, dtype=np.int64), np.empty(k))

    def run(tol: float) -> None:
        settings = cells_kernel.Settings(tol, 1e-9, True, True)
        cells_kernel.derivative_rows(p.structure.kernel_pack, U, dU, Ub, np.eye(2), settings,
                                     solved, out)

    run(1e-9)
    names = {cells_kernel.SMOOTH: "smooth", cells_kernel.KINK: "kink"}
    for i in range(k):
        if i in (10, 30):
            assert out.status[i] == cells_kernel.UNCERTIFIED and np.isnan(out.margin[i])
            continue
        d = iq.derivative(p.with_u_minus(U[i]), law)
        assert names[out.status[i]] == d.status == ("kink" if i in (5, 6) else "smooth")
        assert np.allclose(out.Up[i], d.u_plus, atol=1e-12)
        assert np.allclose(out.dUp[i], d.jvp(u_minus=dU[i]).u_plus, atol=1e-12)
        assert np.allclose(out.Ubar[i], d.vjp(u_plus=Ub[i])["u_minus"], atol=1e-12)
        assert np.isclose(out.margin[i], d.certificate.margin, rtol=1e-9)
    solved[:] = True  # every row again, no cell's residual within the tolerance
    run(-1.0)
    assert (out.status == cells_kernel.UNCERTIFIED).all() and np.isnan(out.margin).all()


def test_a_row_the_compiled_solve_does_not_certify_is_answered_on_its_own(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """derivative_batch differentiates only the rows its compiled solve certified: a row it
    reports uncertified (its u⁺ and Λ left as garbage) is solved and differentiated one by one,
    and gets what that row's own derivative gives."""
    import impactqp.derivatives.batch as batch

    def one_row_uncertified(*args: object) -> tuple:
        Up, Lam, Res, ok = solve_impact_rows(*args)
        Up[3], Lam[3], ok[3] = 1e3, -1e3, False  # the chunk's fourth row
        return Up, Lam, Res, ok

    monkeypatch.setattr(batch, "solve_impact_rows", one_row_uncertified)
    law = iq.Moreau(0.3)
    p = iq.random_impact(6, 4, seed=8, consistent=False)
    rng = np.random.default_rng(3)
    U, dU = rng.normal(size=(8, 6)), rng.normal(size=(8, 6))
    b = iq.derivative_batch(p, law, U, jvp=dU)
    assert b.backend == "kernel"
    for i in range(8):
        d = iq.derivative(p.with_u_minus(U[i]), law)
        assert np.allclose(b.u_plus[i], iq.solve(p.with_u_minus(U[i]), law).u_plus,
                           atol=1e-12)
        assert b.status[i] == d.status
        assert np.allclose(b.jvp[i], d.jvp(u_minus=dU[i]).u_plus, atol=1e-12)
