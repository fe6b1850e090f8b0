"""The float path for single small impacts against the array path: same answers, same
certificate (its residuals recomputed by the general formulas), declines when unsure."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.laws import small, unrolled


@pytest.fixture(autouse=True)
def compile_at_once(monkeypatch):
    """Programs compiled at a structure's first solve, so each test's first call is tested."""
    monkeypatch.setattr(unrolled, "COMPILE_AFTER", 1)


def cases():
    rng = np.random.default_rng(5)
    for seed in range(12):
        n, m = int(rng.integers(2, 7)), int(rng.integers(1, 5))
        p = iq.random_impact(n, min(m, n), seed=seed, consistent=bool(seed % 2))
        k = p.n_contacts
        yield p, iq.Moreau(float(rng.random()))
        yield p, iq.Newton(rng.random(k))
        yield p, iq.Fremond(0.3 * rng.random((k, k)))
    yield iq.newtons_cradle(3), iq.Moreau(1.0)
    yield iq.newtons_cradle(4, v=1e-40, mass=1e9), iq.Moreau(0.5)


@pytest.mark.parametrize("case", list(cases()), ids=lambda c: f"{c[1]!r}"[:40])
def test_float_path_matches_the_array_path(case) -> None:
    p, law = case
    assert small.applies(p, law, "auto", "auto")
    r = iq.solve(p, law)
    general = iq.solve(p, law, backend="exact")
    np.testing.assert_allclose(r.u_plus, general.u_plus, rtol=1e-9,
                               atol=1e-9 * np.abs(p.u_minus).max())
    if r.attempts[-1].startswith("kernel (impulse, on floats)"):
        # the float certificate is the general one, recomputed independently
        again = law.certificate(p, iq.Answer(r.u_plus, r.impulses, r.z), r.certificate.tol)
        # residuals of an exact answer are round-off: equal within the tolerance, not digit
        # for digit (two orders of summation differ in the last bits)
        assert again.residuals.keys() == r.certificate.residuals.keys()
        for key, value in r.certificate.residuals.items():
            assert abs(value - again.residuals[key]) <= r.certificate.tol, key
        assert again.ok


def test_float_path_is_taken_and_declines_out_of_range() -> None:
    p = iq.newtons_cradle(3)
    assert iq.moreau(p, 1.0).attempts == ["kernel (impulse, on floats): certified"]
    tiny = iq.newtons_cradle(3, v=1e-200)
    r = iq.moreau(tiny, 1.0)  # squares would underflow: the general path answers
    assert "on floats" not in r.attempts[-1]
    np.testing.assert_allclose(r.u_plus, np.array([-1, 2, 2]) / 3 * 1e-200, rtol=1e-12)
    assert not small.applies(p, iq.SectorLaw(), "auto", "auto")
    assert not small.applies(p, iq.Moreau(1.0), "clarabel", "auto")
    assert not small.applies(p, iq.Moreau(1.0), "auto", "velocity")


def test_a_failing_float_answer_is_not_returned(monkeypatch) -> None:
    """A program compiled from a wrong kernel (every inverse halved: Λ half the impulse) finds
    candidates, but its own residual checks refuse them; the general path answers."""
    from impactqp.qp.active_set import ActiveSetKernel

    honest = ActiveSetKernel.support

    def halved(self, idx):
        found = honest(self, idx)
        return None if found is None else (found[0], found[1], 0.5 * found[2], found[3])

    monkeypatch.setattr(ActiveSetKernel, "support", halved)
    p = iq.newtons_cradle(3)  # a fresh structure: its program is compiled now, wrongly
    program = unrolled.program_for(p.structure, "moreau", small._kernel)
    assert program(p.u_minus.tolist(), (1.0,), 1e-9) is None
    assert program(p.u_minus.tolist(), (1.0,), 0.9) is not None  # it did find a candidate
    monkeypatch.undo()
    r = iq.moreau(p, 1.0)
    assert "on floats" not in r.attempts[-1] and r.certificate.ok
    np.testing.assert_allclose(r.u_plus, [-1 / 3, 2 / 3, 2 / 3])


def test_programs_are_compiled_for_structures_in_use(monkeypatch) -> None:
    """Structures met once or twice (compiling costs ~100 solves) go by the array path."""
    monkeypatch.setattr(unrolled, "COMPILE_AFTER", 3)
    p = iq.newtons_cradle(3)
    paths = [iq.moreau(p.with_u_minus([1.0, 0.0, -k]), 0.5).attempts[-1] for k in range(4)]
    assert paths[:2] == ["kernel (impulse): certified"] * 2
    assert paths[2:] == ["kernel (impulse, on floats): certified"] * 2
    assert iq.newton(p, 0.5).attempts[-1] == "kernel (impulse): certified"  # per law kind


def test_programs_are_kept_per_structure_and_released() -> None:
    import gc

    p = iq.newtons_cradle(4)
    first = unrolled.program_for(p.structure, "newton", small._kernel)
    assert unrolled.program_for(p.structure, "newton", small._kernel) is first
    key = (id(p.structure), "newton")
    assert key in unrolled._PROGRAMS
    del p, first
    gc.collect()
    assert key not in unrolled._PROGRAMS
    with pytest.raises(ValueError, match="kind"):
        unrolled.program_for(iq.newtons_cradle(3).structure, "sector", small._kernel)


def test_the_certificate_is_built_on_first_read_from_the_checked_residuals() -> None:
    p = iq.newtons_cradle(3)
    r = iq.moreau(p, 0.5)
    assert not isinstance(r._certificate, iq.Certificate)  # not built yet
    cert = r.certificate
    assert isinstance(cert, iq.Certificate) and r.certificate is cert and cert.ok
    assert set(cert.residuals) == {"momentum", "impulse_sign", "law_feasibility",
                                   "complementarity", "energy_balance", "duality_gap"}
    assert isinstance(r.z, np.ndarray) and r.z is r.z
    np.testing.assert_allclose(r.z, [1 / 3] * 3)


@pytest.mark.parametrize("n, m", [(1, 1), (2, 1), (5, 4), (12, 4)])
def test_compiled_programs_of_every_small_shape(n, m) -> None:
    if n == 1:
        p = iq.chain([2.0], [-1.5], left_wall=True)
    else:
        p = iq.random_impact(n, m, seed=n + m)
    for law in (iq.Moreau(0.3), iq.Newton(0.7), iq.Fremond(0.2 * np.eye(m))):
        r = iq.solve(p, law)
        ref = iq.solve(p, law, backend="exact")
        np.testing.assert_allclose(r.u_plus, ref.u_plus, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(r.impulses, ref.impulses, rtol=1e-7,
                                   atol=1e-9 * np.abs(ref.impulses).max())
        assert r.attempts == ["kernel (impulse, on floats): certified"]


def test_operators_beyond_float_literals_are_not_compiled() -> None:
    p = iq.newtons_cradle(3)
    rows = p.structure.float_rows
    p.structure.__dict__["float_rows"] = rows._replace(M=((np.inf, 0.0, 0.0),) + rows.M[1:])
    program = unrolled.program_for(p.structure, "moreau", small._kernel)
    assert program is unrolled._declines and program([1.0, 0.0, 0.0], (0.5,), 1e-9) is None
    del p.structure.__dict__["float_rows"]
    r = iq.moreau(p, 0.5)  # the array path answers
    assert r.attempts[-1] == "kernel (impulse): certified"
    np.testing.assert_allclose(r.u_plus, [0.0, 0.5, 0.5], atol=1e-15)
