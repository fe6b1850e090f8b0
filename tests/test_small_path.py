"""The compiled path for single dense impacts against the general path: same answers, the same
certificate (its residuals recomputed independently), and a corrupted solve never returned."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.laws import small

COMPILED = "kernel (compiled): certified"


def cases():
    rng = np.random.default_rng(5)
    for seed in range(12):
        n, m = int(rng.integers(2, 7)), int(rng.integers(1, 5))
        p = iq.random_impact(n, min(m, n), seed=seed, consistent=bool(seed % 2),
                             redundant=min(seed % 3, min(m, n) - 1))
        k = p.n_contacts
        yield p, iq.Moreau(float(rng.random()))
        yield p, iq.Newton(rng.random(k))
        yield p, iq.Fremond(0.3 * rng.random((k, k)))
    yield iq.newtons_cradle(3), iq.Moreau(1.0)
    yield iq.newtons_cradle(4, v=1e-40, mass=1e9), iq.Moreau(0.5)


@pytest.mark.parametrize("case", list(cases()), ids=lambda c: f"{c[1]!r}"[:40])
def test_compiled_path_matches_the_general_path(case) -> None:
    p, law = case
    assert small.applies(p, law, "auto", "auto")
    r = iq.solve(p, law)
    general = iq.solve(p, law, backend="exact")
    np.testing.assert_allclose(r.u_plus, general.u_plus, rtol=1e-9,
                               atol=1e-9 * np.abs(p.u_minus).max())
    if r.attempts[-1] == COMPILED:
        # the compiled certificate is the general one, recomputed from (u⁺, Λ) alone; residuals
        # of an exact answer are round-off, equal within the tolerance, not digit for digit
        again = law.certificate(p, iq.Answer(r.u_plus, r.impulses, r.z), r.certificate.tol)
        assert again.residuals.keys() == r.certificate.residuals.keys()
        for key, value in r.certificate.residuals.items():
            assert abs(value - again.residuals[key]) <= r.certificate.tol, key
        assert again.ok


@pytest.mark.parametrize("scale", [1e-200, 1e-60, 1.0, 1e60, 1e200])
def test_compiled_path_at_every_velocity_scale(scale) -> None:
    p = iq.newtons_cradle(3, v=scale)
    r = iq.moreau(p, 1.0)
    assert r.attempts[-1] == COMPILED  # in order-one units beyond 1e±100
    np.testing.assert_allclose(r.u_plus, np.array([-1, 2, 2]) / 3 * scale, rtol=1e-12)
    assert r.certificate.ok
    assert not small.applies(p, iq.SectorLaw(), "auto", "auto")
    assert not small.applies(p, iq.Moreau(1.0), "clarabel", "auto")
    assert not small.applies(p, iq.Moreau(1.0), "auto", "velocity")


def test_a_corrupted_compiled_solve_is_not_returned() -> None:
    """Operators corrupted inside the packed structure (M⁻¹W halved: u⁺ misses the impulses)
    give candidates whose own residuals fail; the general path answers instead."""
    p = iq.newtons_cradle(3)
    st = p.structure
    packed = st.kernel_pack.copy()
    n, m = st.n, st.m
    start = n * n + m * n
    packed[start:start + n * m] *= 0.5
    st.__dict__["kernel_pack"] = packed
    try:
        assert small.solve_small(p, iq.Moreau(1.0), 1e-9, 0.0) is None
        assert small.solve_small(p, iq.Newton(0.5), 1e-9, 0.0) is None
        r = iq.moreau(p, 1.0)
        assert r.attempts[-1] != COMPILED and r.certificate.ok
        np.testing.assert_allclose(r.u_plus, [-1 / 3, 2 / 3, 2 / 3])
    finally:
        del st.__dict__["kernel_pack"]
    assert iq.moreau(p, 1.0).attempts == [COMPILED]


def test_warm_starts_do_not_change_answers() -> None:
    """Each solve starts from the support of the one before; any start gives the same answer."""
    rng = np.random.default_rng(11)
    p = iq.random_impact(6, 5, seed=3, redundant=2)
    velocities = rng.standard_normal((40, p.n_dof))
    warm = [iq.moreau(p.with_u_minus(u), 0.4).u_plus for u in velocities]
    for u, w in zip(velocities, warm):
        cold = iq.moreau(iq.ImpactProblem(p.M, p.W, u), 0.4)  # a fresh structure
        np.testing.assert_allclose(w, cold.u_plus, rtol=1e-10, atol=1e-12)


def test_the_certificate_is_built_on_first_read_from_the_checked_residuals() -> None:
    p = iq.newtons_cradle(3)
    r = iq.moreau(p, 0.5)
    assert not isinstance(r._certificate, iq.results.Certificate)  # not built yet
    cert = r.certificate
    assert isinstance(cert, iq.results.Certificate) and r.certificate is cert and cert.ok
    assert set(cert.residuals) == {"momentum", "impulse_sign", "law_feasibility",
                                   "complementarity", "energy_balance", "duality_gap"}
    assert all(type(v) is float for v in cert.residuals.values())
    assert isinstance(r.z, np.ndarray) and r.z is r.z
    np.testing.assert_allclose(r.z, [1 / 3] * 3)


@pytest.mark.parametrize("n, m", [(1, 1), (2, 1), (5, 4), (12, 4), (30, 25)])
def test_compiled_solves_of_every_shape(n, m) -> None:
    if n == 1:
        p = iq.chain([2.0], [-1.5], left_wall=True)
    else:
        p = iq.random_impact(n, m, seed=n + m)
    for law in (iq.Moreau(0.3), iq.Newton(0.7), iq.Fremond(0.2 * np.eye(m))):
        r = iq.solve(p, law)
        ref = iq.solve(p, law, backend="exact" if m <= 14 else "clarabel")
        np.testing.assert_allclose(r.u_plus, ref.u_plus, rtol=1e-8, atol=1e-10)
        assert r.attempts == [COMPILED]


def test_the_rest_shortcut_answers_only_when_certified() -> None:
    """u⁻ = 0 gives u⁺ = 0, Λ = 0 for the laws of the impact; a time-stepping law whose
    previous velocity approaches (γ_prev = −2, e = 0.5) rejects it and is solved in full."""
    from impactqp.simulation.step_law import MoreauJeanStep

    rest = iq.ImpactProblem(np.eye(2), [[-1.0], [1.0]], [0.0, 0.0])
    r = iq.moreau(rest, 0.5)
    assert r.certificate.ok and not r.u_plus.any() and not r.impulses.any()
    step = iq.solve(rest, MoreauJeanStep(0.5, [1.0, -1.0]))
    assert step.certificate.ok
    np.testing.assert_allclose(step.u_plus, [-0.5, 0.5])  # γ⁺ = −e·γ_prev = 1
    np.testing.assert_allclose(step.impulses, [0.5])
