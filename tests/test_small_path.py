"""The compiled path for single impacts (dense, and Moreau's law on chains) against the general
path: same answers, the same certificate (its residuals recomputed independently), and a
corrupted solve never returned."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.laws import small

COMPILED = "kernel (compiled): certified"
CHAIN = "isotonic (compiled): certified"


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
    assert r.attempts[-1] == CHAIN  # in order-one units beyond 1e±100
    np.testing.assert_allclose(r.u_plus, np.array([-1, 2, 2]) / 3 * scale, rtol=1e-12)
    assert r.certificate.ok
    dense = iq.moreau(p, 1.0, form="impulse")  # the dense compiled call
    assert dense.attempts[-1] == COMPILED and dense.certificate.ok
    np.testing.assert_allclose(dense.u_plus, r.u_plus, rtol=1e-12)
    assert not small.applies(p, iq.SectorLaw(), "auto", "auto")
    assert not small.applies(p, iq.Moreau(1.0), "clarabel", "auto")
    assert small.applies(p, iq.Moreau(1.0), "auto", "velocity")  # the chain's call
    assert not small.applies(p, iq.Newton(0.5), "auto", "velocity")
    assert not small.applies(p, iq.Moreau(1.0), "nnls", "auto")


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
        assert small.solve_small(p, iq.Moreau(1.0), 1e-9, 0.0, form="impulse") is None
        assert small.solve_small(p, iq.Newton(0.5), 1e-9, 0.0) is None
        r = iq.moreau(p, 1.0, form="impulse")
        assert r.attempts[-1] != COMPILED and r.certificate.ok
        np.testing.assert_allclose(r.u_plus, [-1 / 3, 2 / 3, 2 / 3])
    finally:
        del st.__dict__["kernel_pack"]
    assert iq.moreau(p, 1.0, form="impulse").attempts == [COMPILED]


def test_a_corrupted_chain_call_is_not_returned() -> None:
    """The chain's compiled call with its certificate's M⁻¹ corrupted (one inverse mass of
    the pack NaN, which only the impact equation's measure reads): that residual fails, the
    call declines, and the general path answers."""
    p = iq.chain([1.0, 2.0, 3.0, 1.5], [2.0, 0.5, -1.0, 0.0], left_wall=True)
    st = p.structure
    packed = st.chain_pack.copy()
    packed[st.n + 1] = np.nan
    st.__dict__["chain_pack"] = packed
    try:
        assert small.solve_small(p, iq.Moreau(0.5), 1e-9, 0.0) is None
        r = iq.moreau(p, 0.5)
        assert r.attempts[-1] != CHAIN and r.certificate.ok
    finally:
        del st.__dict__["chain_pack"]
    again = iq.moreau(p, 0.5)
    assert again.attempts == [CHAIN]
    np.testing.assert_allclose(again.u_plus, r.u_plus, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("walls", [(False, False), (True, False), (False, True), (True, True)])
@pytest.mark.parametrize("n", [1, 2, 3, 7, 40, 300])
def test_the_chain_call_is_the_isotonic_backend(walls, n) -> None:
    """The chain's compiled call gives the isotonic backend's numbers digit for digit (the same
    regression, recovery and certificate), on every wall layout, with and without restitution."""
    if n == 1 and walls == (False, False):
        return  # no contact
    rng = np.random.default_rng(n)
    p = iq.chain(rng.uniform(0.5, 3.0, n), rng.standard_normal(n), left_wall=walls[0],
                 right_wall=walls[1])
    for eps in (0.0, 0.4, 1.0):
        general = iq.moreau(p, eps, backend="isotonic")
        r = small.solve_small(p, iq.Moreau(eps), 1e-9, 0.0)
        assert r is not None and r.attempts == [CHAIN] and r.form == "velocity"
        np.testing.assert_array_equal(r.u_plus, general.u_plus)
        np.testing.assert_array_equal(r.impulses, general.impulses)
        assert r.certificate.residuals == general.certificate.residuals
        np.testing.assert_allclose(r.z, general.z, rtol=1e-15, atol=1e-15)
        if p.n_contacts <= p.n_dof:  # (two walls on one ball are collapsed first)
            assert iq.moreau(p, eps).attempts == [CHAIN]


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
        on_chain = p.chain is not None and isinstance(law, iq.Moreau)
        assert r.attempts == [CHAIN if on_chain else COMPILED]


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


@pytest.mark.parametrize("n", [8, 40])
def test_batches_of_chains_keep_their_paths(n, monkeypatch) -> None:
    """The chain's call serves single impacts: a batch of a chain beyond the dense call's
    reach does not run the dense call row by row, and every row equals the single impact's
    answer."""
    import impactqp.laws.batch as batch

    p = iq.newtons_cradle(n)
    if not small.dense(p, iq.Moreau(0.3), "auto", "auto"):
        def refuse(*args):
            raise AssertionError("the dense compiled call ran on a chain beyond its reach")
        monkeypatch.setattr(batch, "solve_impact_rows", refuse)
    U = np.random.default_rng(n).standard_normal((20, n))
    b = iq.moreau_batch(p, U, 0.3)
    assert b.ok.all() and b.resolved == 0
    single = np.array([iq.moreau(p.with_u_minus(u), 0.3).u_plus for u in U])
    np.testing.assert_allclose(b.u_plus, single, rtol=1e-12, atol=1e-12)


def decision_cases():
    """Impacts on both sides of each of the planner's decisions that the short route restates:
    the law's family, the velocity's scale, contacts beyond the degrees of freedom, chains and
    dense structures, the tolerance, frictional contacts."""
    rng = np.random.default_rng(29)
    chain = iq.chain([1.0, 2.0, 0.5], [1.0, 0.0, -2.0], left_wall=True)
    dense = iq.random_impact(5, 3, seed=4)
    redundant = iq.random_impact(3, 3, seed=6, redundant=2)
    pinned = iq.chain([2.0], [1.0], left_wall=True, right_wall=True)  # 2 contacts, 1 dof
    crowded = iq.ImpactProblem(np.eye(2), [[1.0, 0.0, 1.0], [0.0, 1.0, 1.0]], [-1.0, -2.0])
    doubled = iq.ImpactProblem(2.0 * np.eye(1), [[1.0, 2.0]], [-1.0])  # parallel contacts
    for p in (chain, dense, redundant, pinned, crowded, doubled, iq.newtons_cradle(3),
              iq.newtons_cradle(12)):
        k = p.n_contacts
        for law in (iq.Moreau(0.5), iq.Newton(rng.random(k)), iq.Fremond(0.2 * np.eye(k))):
            for scale in (1.0, 1e-150, 1e150):
                for tol in (1e-9, 1e-13):
                    yield p.with_u_minus(scale * p.u_minus), law, tol
    cradle = iq.newtons_cradle(3)
    yield cradle, iq.SectorLaw(), 1e-9
    yield cradle, iq.Moreau(1.0), 1  # an int tolerance: the full route says what to fix
    yield iq.friction.point_on_plane(1.0, [1.0, 2.0]), iq.Coulomb(0.5, 0.5), 1e-9
    yield iq.friction.point_on_plane(1.0, [1.0, 2.0]), iq.Moreau(0.5), 1e-9


@pytest.mark.parametrize("case", list(decision_cases()),
                         ids=lambda c: f"{c[0].n_dof}-{c[0].n_contacts}-{c[1]!r}-{c[2]}"[:60])
def test_the_short_route_decides_as_the_planner(case, monkeypatch) -> None:
    """``small.first_try`` restates :func:`validate` and :func:`plan` for the case where they
    all pass: one by one, it answers only when the full route (with it removed) plans the
    compiled call for the problem as given (no rescaling, no collapsed contacts) and that
    call certifies, always then with no more contacts than degrees of freedom (more are left
    to the full route, which collapses parallel ones), and its answer is the full route's
    digit for digit."""
    from impactqp.laws import pipeline

    p, law, tol = case
    planned = []
    real_plan = pipeline.plan

    def recording_plan(*args, **kwargs):
        route = real_plan(*args, **kwargs)
        planned.append(route)
        return route

    fast = small.first_try(p, law, tol)
    monkeypatch.setattr(small, "first_try", lambda *args: None)
    monkeypatch.setattr(pipeline, "plan", recording_plan)
    try:
        full = iq.solve(p, law, tol=tol)
    except (iq.errors.ImpactError, ValueError, TypeError):
        assert fast is None  # what the full route refuses, the short one never answers
        return
    direct = (len(planned) == 1 and planned[0].scale == 1.0 and planned[0].groups is None
              and planned[0].path == "compiled"
              and full.attempts in ([COMPILED], [CHAIN]))
    if fast is not None:
        assert direct
    elif p.n_contacts <= p.n_dof:
        assert not direct
    if fast is not None:
        assert fast.backend == full.backend and fast.attempts == full.attempts
        np.testing.assert_array_equal(fast.u_plus, full.u_plus)
        np.testing.assert_array_equal(fast.impulses, full.impulses)
        assert fast.certificate.residuals == full.certificate.residuals
