"""The compiled LZB integration (impactqp.kernels.lzb, lzb_model; docs/theory.md §13) against
scipy's DOP853 reference on the same model, the rates against the energy balance they must
keep, the options' validation, the budgets and the velocity scale."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.errors import IntegrationBudgetError
from impactqp.kernels import lzb_model as km
from impactqp.laws.lzb import LZB, LZBDynamics
from impactqp.laws.lzb import integration as lzb_integration
from impactqp.model.physical_chains import monodisperse_chain, tapered_chain

CASES = {  # name: (problem, law)
    "2 balls Hertz e=1": (iq.newtons_cradle(2), LZB(1e6)),
    "3 balls linear e=1": (iq.newtons_cradle(3), LZB(1.0, exponent=1.0)),
    "3 balls Hertz e=0.6": (iq.newtons_cradle(3), LZB(1e6, restitution=0.6)),
    "3 balls plastic": (iq.newtons_cradle(3), LZB(1e6, restitution=0.0)),
    "4 balls mixed e, exponents": (iq.newtons_cradle(4),
                                   LZB([1e6, 2e5, 1e6], exponent=[1.5, 1.0, 2.0],
                                       restitution=[1.0, 0.5, 0.8])),
    "wall": (iq.chain([1.0, 2.0, 1.0], [0.0, 0.0, -1.0], left_wall=True),
             LZB(1e5, restitution=0.9)),
    "unequal masses": (tapered_chain(5).problem, LZB(tapered_chain(5).stiffness,
                                                     restitution=[0.9, 0.5, 0.7, 0.2])),
    "10 balls Siconos": (monodisperse_chain(10).problem, LZB(monodisperse_chain(10).stiffness)),
}


@pytest.mark.parametrize("name", list(CASES))
def test_compiled_matches_reference(name: str) -> None:
    p, law = CASES[name]
    fast, ref = law.integrate(p), law.integrate(p, reference=True)
    energy = p.kinetic_energy()
    assert np.abs(fast.u_plus - ref.u_plus).max() <= 1e-8 * np.abs(p.u_minus).max()
    assert np.abs(fast.impulses - ref.impulses).max() <= 1e-8 * ref.impulses.max()
    for field in ("dissipated", "potential_energy"):
        a, b = getattr(fast.record, field), getattr(ref.record, field)
        assert np.abs(a - b).max() <= 1e-9 * energy, field
    assert fast.record.method.endswith(ref.record.method.removesuffix(", scipy"))
    assert ref.record.method.endswith("scipy")
    cert = iq.solve(p, law).certificate
    assert cert.ok and cert.energy_balance <= 1e-9


def test_fixed_steps_match_reference_and_place_kinks_by_real_steps() -> None:
    p = iq.newtons_cradle(3)
    law = LZB(1e6, step=4e-3)  # elastic: no kink, the same steps as scipy's
    fast, ref = law.integrate(p), law.integrate(p, reference=True)
    assert fast.record.method == "fixed step 0.004" and fast.record.steps == ref.record.steps
    assert np.abs(fast.u_plus - ref.u_plus).max() <= 1e-13
    # e < 1: the rates have a kink where compression turns to expansion; scipy takes the
    # state there from the dense output of the step across it, the compiled stepper by
    # real steps up to it, an order of magnitude closer to the converged answer
    for h in (4e-3, 1e-3):
        law = LZB(1e6, restitution=0.5, step=h)
        best = LZB(1e6, restitution=0.5, rtol=1e-13, energy_target=None).integrate(p).u_plus
        fast, ref = law.integrate(p), law.integrate(p, reference=True)
        assert np.abs(fast.u_plus - best).max() <= 0.5 * np.abs(ref.u_plus - best).max()
        assert np.abs(fast.u_plus - best).max() <= 10 * fast.record.error_estimate


def _state(m: int, k: int, seed: int) -> tuple[LZBDynamics, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    p = iq.random_impact(m + 2, m, seed=seed)
    st = p.structure
    gamma = st.Wt_times(p.u_minus)
    gamma[0] = -abs(gamma[0]) - 0.1
    dyn = LZBDynamics(st.delassus, gamma, rng.uniform(0.5, 2.0, m), rng.choice([1.0, 1.5, 2.0], m),
                      rng.uniform(0.3, 1.0, m))
    x = np.concatenate([rng.uniform(0.1, 1.0, m), rng.uniform(0.0, 0.5, m), np.zeros(m)])
    return dyn, x, np.arange(m)


@pytest.mark.parametrize("k", [-1, 0, 2])
def test_rates_keep_the_energy_balance(k: int) -> None:
    """d(T + ΣE + ΣD) = 0 along the rates, with dT = γᵀdP (docs/theory.md §13), against time
    (k < 0) and against a primary impulse, whose slot holds Eₖ itself."""
    for seed in range(4):
        dyn, x, live = _state(4, k, seed)
        m = dyn.m
        out, gamma = np.zeros(3 * m), np.empty(m)
        km.rates(x, k, live, m, *dyn.structure[:4], dyn.law, gamma, out)
        y, eta = x[:m].copy(), dyn.law[km.ETA]
        if k >= 0:
            y[k] = x[k] ** (1 / (eta[k] + 1))
        assert np.allclose(gamma, dyn.gamma(x[m:2 * m]), rtol=1e-14, atol=1e-14)
        dE = (eta + 1) * y ** eta * out[:m]
        if k >= 0:
            dE[k] = out[k]
            assert out[m + k] == 1.0
        force = dyn.law[km.KAPPA] * y ** eta
        assert np.allclose(out[m:2 * m] / out[m:2 * m].max(), force / force.max(), rtol=1e-13)
        total = gamma @ out[m:2 * m] + dE.sum() + out[2 * m:].sum()
        assert abs(total) <= 1e-12 * np.abs(gamma * out[m:2 * m]).sum()
        assert np.all(out[2 * m:] >= 0)  # restitution dissipates, never creates


def test_open_contacts_have_no_rates_and_no_watched_close_far_away() -> None:
    dyn, x, _ = _state(5, -1, 0)
    m = dyn.m
    frozen = np.array([False, False, True, True, True])
    gamma = dyn.gamma(x[m:2 * m])
    kinds = np.empty(3 * m + 3, dtype=np.int64)
    contacts, directions = kinds.copy(), np.empty(3 * m + 3)
    live = np.empty(m, dtype=np.int64)
    ne, nlive = km.piece_events(-1, frozen, gamma, dyn.law, dyn.indptr, dyn.indices, kinds,
                                contacts, directions, live)
    assert live[:nlive].tolist() == [0, 1]
    closing = contacts[:ne][kinds[:ne] == km.CLOSE]
    rows = [set(dyn.indices[dyn.indptr[j]:dyn.indptr[j + 1]]) for j in range(m)]
    assert all(rows[j] & {0, 1} for j in closing)  # a close event only where G links it
    assert kinds[ne - 1] == km.HIGH


def test_velocity_scale_invariance() -> None:
    for p, law in (CASES["3 balls Hertz e=0.6"], CASES["unequal masses"]):
        base = iq.solve(p, law).u_plus
        for s in (1e-200, 1e-100, 1e-8, 1e8, 1e100, 1e200):
            r = iq.solve(p.with_u_minus(s * p.u_minus), law)
            assert np.abs(r.u_plus / s - base).max() <= 1e-10 * np.abs(base).max()
            assert r.certificate.ok and np.all(np.isfinite(r.impulses)) and r.impulses.max() > 0


def test_options_are_validated_by_name() -> None:
    for bad in (0.5, 3.5, np.nan):
        with pytest.raises(iq.InputError, match="exponent"):
            LZB(1.0, exponent=bad)
    for bad in (0.0, -1e-3, np.inf, np.nan):
        with pytest.raises(iq.InputError, match="step"):
            LZB(1.0, step=bad)
    for bad in (np.inf, 0.0, np.nan):
        with pytest.raises(iq.InputError, match="stiffness"):
            LZB(bad)
    p = iq.newtons_cradle(3)  # κ ratios beyond the floating-point range
    with pytest.raises(iq.InputError, match="stiffness"):
        iq.solve(p.with_u_minus(1e200 * p.u_minus), LZB([1e300, 1e-300], exponent=[3.0, 1.0]))


def test_step_too_small_is_refused_before_integrating() -> None:
    chain = monodisperse_chain(10)
    with pytest.raises(IntegrationBudgetError, match=r"step=1e-09 N·s .* budget"):
        LZB(chain.stiffness, step=1e-9).integrate(chain.problem)
    assert issubclass(IntegrationBudgetError, iq.CertificateError)


@pytest.mark.parametrize("reference", [False, True])
def test_spent_budget_names_itself(monkeypatch, reference: bool) -> None:
    monkeypatch.setattr(lzb_integration, "step_budget", lambda m: 20)
    p = iq.newtons_cradle(3)
    with pytest.raises(IntegrationBudgetError, match="budget of 20 steps"):
        LZB(1e6).integrate(p, reference=reference)


@pytest.mark.parametrize("reference", [False, True])
def test_endless_elastic_impact_stops_within_its_budget(monkeypatch, reference: bool) -> None:
    # one ball between two walls given as a general problem (check() sees no chain): an
    # elastic impact bounces for ever, and the budget of pieces ends it with its cause
    monkeypatch.setattr(lzb_integration, "MAX_PIECES", 200)
    p = iq.ImpactProblem(np.eye(1), np.array([[1.0, -1.0]]), [-1.0])
    with pytest.raises(IntegrationBudgetError, match=r"200 pieces .*T_C = \{0\}"):
        LZB(1e6).integrate(p, reference=reference)
    assert iq.solve(p, LZB(1e6, restitution=0.5)).certificate.ok  # dissipation ends it
