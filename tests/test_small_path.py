"""The float path for single small impacts against the array path: same answers, same
certificate (its residuals recomputed by the general formulas), declines when unsure."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.laws import small


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
        for key, value in r.certificate.residuals.items():
            assert value == pytest.approx(again.residuals[key], rel=1e-6, abs=1e-15), key
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
    p = iq.newtons_cradle(3)
    kernel = small.prepared_for(p.structure, "impulse", p.structure.delassus)
    monkeypatch.setattr(kernel, "solve_floats", lambda q, tol=0: [0.0, 0.0])  # no impulse
    r = iq.moreau(p, 1.0)
    assert "on floats" not in r.attempts[-1]
    np.testing.assert_allclose(r.u_plus, [-1 / 3, 2 / 3, 2 / 3])
