"""verify_law and the Frémond admissibility map (docs/theory.md §2, §3, §6, §7)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import impactqp as iq
from impactqp.tables.sector_table import SectorTable
from impactqp.verification.fremond_map import fremond_matrix

CRADLE = iq.newtons_cradle(3)
SAMPLES = 150


def energy_gain(law, u_minus: np.ndarray) -> float:
    """T⁺ − T⁻ of ``law`` recomputed from scratch on the 3-ball cradle."""
    r = law(CRADLE.with_u_minus(u_minus))
    return r.energy_after - r.energy_before


# --------------------------------------------------------------------------- sector law
@pytest.mark.parametrize("n", [3, 4, 5])
def test_sector_law_passes(n: int) -> None:
    rep = iq.verify_law(iq.sector_law, iq.newtons_cradle(n), samples=SAMPLES, seed=n,
                        consistent_only=False)  # in S even from inconsistent u⁻
    assert rep.ok and rep.worst is None and rep.method == "sampled"
    assert rep.violations == dict.fromkeys(
        ["kinematic", "kinetic", "energetic", "non_expansive", "law_error"], 0)
    assert rep.samples == SAMPLES and rep.pairs == SAMPLES * (SAMPLES - 1) // 2
    assert rep.summary().startswith("ok")


def test_plain_array_law_is_accepted_and_pairs_are_capped(monkeypatch) -> None:
    import impactqp.verification.sampled as verify

    monkeypatch.setattr(verify, "MAX_PAIR_SAMPLES", 10)
    rep = iq.verify_law(lambda q: np.sort(q.u_minus), CRADLE, samples=20)
    assert rep.ok and rep.samples == 20 and rep.pairs == 45


# --------------------------------------------------------------------------- Moreau
def test_moreau_elastic_penetrates_on_arbitrary_u_minus() -> None:
    law = lambda q: iq.moreau(q, eps=1.0)  # noqa: E731
    rep = iq.verify_law(law, CRADLE, samples=SAMPLES, seed=0, consistent_only=False)
    assert not rep.ok and rep.violations["kinematic"] > 0
    assert rep.violations["kinetic"] == rep.violations["energetic"] == 0
    assert rep.violations["non_expansive"] == 0  # 2 prox − I is non-expansive
    ce = rep.counterexamples["kinematic"]
    gamma_plus = CRADLE.structure.W.T @ law(CRADLE.with_u_minus(ce.u_minus)).u_plus
    assert gamma_plus.min() < 0 and np.any(CRADLE.structure.W.T @ ce.u_minus > 0)
    assert rep.worst is ce and "kinematic" in rep.summary()
    consistent = iq.verify_law(law, CRADLE, samples=SAMPLES, seed=0)  # the default
    assert consistent.ok


def test_consistent_sampling() -> None:
    import inspect

    from impactqp.verification.sampled import sample_u_minus

    assert inspect.signature(iq.verify_law).parameters["consistent_only"].default is True

    u = sample_u_minus(CRADLE, 200, np.random.default_rng(0), consistent_only=True)
    gammas = u @ CRADLE.structure.W
    assert gammas.max() <= 1e-12 and np.all(gammas.min(axis=0) < -1.0)
    redundant = iq.random_impact(4, 3, redundant=1, seed=3)  # G singular: the prox path
    u = sample_u_minus(redundant, 20, np.random.default_rng(0), consistent_only=True)
    assert (u @ redundant.structure.W).max() <= 1e-9 and np.linalg.norm(u) > 0
    rep = iq.verify_law(lambda q: iq.moreau(q, 1.0), redundant, samples=20,
                        consistent_only=True)
    assert rep.ok


# --------------------------------------------------------------------------- local Newton
def test_newton_unequal_coefficients() -> None:
    """ΔT = ½Λᵀ(γ⁺ + γ⁻) = ½Σ Λᵢ(1 − eᵢ)γ⁻ᵢ: never positive for γ⁻ ≤ 0, positive once a
    separating contact (γ⁻ᵢ > 0) carries an impulse."""
    law = lambda q: iq.newton(q, [1.0, 0.5])  # noqa: E731
    consistent = iq.verify_law(law, CRADLE, samples=SAMPLES, seed=1, consistent_only=True)
    assert consistent.violations["energetic"] == 0
    assert consistent.violations["kinematic"] == consistent.violations["kinetic"] == 0
    pair = consistent.counterexamples["non_expansive"]  # not maximal monotone
    before = CRADLE.norm(pair.u_minus[0] - pair.u_minus[1])
    after = [law(CRADLE.with_u_minus(u)).u_plus for u in pair.u_minus]
    assert CRADLE.norm(after[0] - after[1]) > before * (1 + 1e-3)

    anywhere = iq.verify_law(law, CRADLE, samples=SAMPLES, seed=1, consistent_only=False)
    ce = anywhere.counterexamples["energetic"]
    assert anywhere.violations["energetic"] > 0
    assert energy_gain(law, ce.u_minus) > 1e-3 * CRADLE.with_u_minus(ce.u_minus).kinetic_energy()
    assert CRADLE.with_u_minus(ce.u_minus).gamma_minus.max() > 0


# --------------------------------------------------------------------------- Frémond
def test_fremond_gains_energy_on_consistent_u_minus() -> None:
    E = np.array([[1.0, 0.5], [0.5, 1.0]])
    law = lambda q: iq.fremond(q, E)  # noqa: E731
    rep = iq.verify_law(law, CRADLE, samples=SAMPLES, seed=2, consistent_only=True)
    ce = rep.counterexamples["energetic"]
    assert CRADLE.with_u_minus(ce.u_minus).gamma_minus.max() <= 1e-12
    gain = energy_gain(law, ce.u_minus)
    assert gain > 0.1 * CRADLE.with_u_minus(ce.u_minus).kinetic_energy()
    assert ce.amount == pytest.approx(
        gain / CRADLE.with_u_minus(ce.u_minus).kinetic_energy(), rel=1e-6)  # ΔT / T⁻


def test_fremond_map_cells() -> None:
    a = [0.0, 0.5, 1.0]
    b = [-0.5, 0.0, 0.5]
    grid = iq.verification.fremond_admissibility_map(CRADLE, a, b, samples=60, seed=0)
    assert grid.shape == (3, 3) and grid.dtype == bool
    # b = 0: E = aI is Moreau's law, in S for every consistent u⁻ (docs/theory.md §3)
    assert grid[:, 1].all()
    # b < 0 lets a contact stay penetrating: classic cradle, a = 0, b = −½ ends with γ⁺₂ = −½
    r = iq.fremond(CRADLE, [[0.0, -0.5], [-0.5, 0.0]])
    np.testing.assert_allclose(r.gamma_plus, [0.0, -0.5], atol=1e-9)
    assert not grid[0, 0]
    # a = 1, b = ½: classic cradle leaves at (−½, ½, 1), 50 % more energy
    r = iq.fremond(CRADLE, [[1.0, 0.5], [0.5, 1.0]])
    np.testing.assert_allclose(r.u_plus, [-0.5, 0.5, 1.0], atol=1e-9)
    assert r.energy_after == pytest.approx(1.5 * r.energy_before)
    assert not grid[2, 2]
    triangular = iq.verification.fremond_admissibility_map(CRADLE, [0.5], [0.0], samples=20,
                                              family="triangular")
    assert triangular.tolist() == [[True]]
    np.testing.assert_array_equal(fremond_matrix(1, 2, 2, "triangular"),
                                  [[1, 2], [0, 1]])


# --------------------------------------------------------------------------- exact path
def test_exact_certificate_of_tables() -> None:
    rep = iq.verify_law(iq.tables.sector_law_table(4))
    assert rep.ok and rep.method == "exact" and rep.certificate.maximal_monotone
    table = iq.tables.sector_law_table(3)
    expanding = SectorTable(cones=[replace(c, Q=1.1 * c.Q) for c in table.cones],
                            G=table.G, W=table.W, n_balls=3)
    bad = iq.verify_law(expanding, CRADLE)
    assert not bad.ok and not bad.certificate.maximal_monotone
    assert bad.violations["energetic"] == bad.violations["non_expansive"] == 6
    assert bad.violations["continuity"] == 0 and bad.violations["kinetic"] == 0
    ce = bad.counterexamples["energetic"]  # recheck: the energy really grows
    p = CRADLE.with_u_minus(ce.u_minus)
    assert p.kinetic_energy(ce.u_plus) > p.kinetic_energy() * (1 + 1e-3)
    pair = bad.counterexamples["non_expansive"]
    assert CRADLE.norm(pair.u_plus[0] - pair.u_plus[1]) > \
        1.05 * CRADLE.norm(pair.u_minus[0] - pair.u_minus[1])


# --------------------------------------------------------------------------- failures
def test_law_errors_are_counted_not_raised() -> None:
    def flaky(q: iq.ImpactProblem) -> np.ndarray:
        if q.u_minus[0] > 0:
            raise iq.NoSolutionError("no answer here")
        return np.sort(q.u_minus)

    rep = iq.verify_law(flaky, CRADLE, samples=40, seed=0, consistent_only=False)
    assert 0 < rep.violations["law_error"] < 40 and not rep.ok
    assert rep.counterexamples["law_error"].u_minus[0] > 0
    assert rep.violations["kinematic"] == 0


def test_bad_input() -> None:
    with pytest.raises(iq.errors.ShapeError, match="u⁺ must have shape"):
        iq.verify_law(lambda q: np.zeros(2), CRADLE, samples=5)
    with pytest.raises(iq.InputError, match="callable"):
        iq.verify_law(42, CRADLE)
    with pytest.raises(iq.InputError, match="ImpactProblem"):
        iq.verify_law(iq.sector_law, None)
    with pytest.raises(iq.InputError, match="samples"):
        iq.verify_law(iq.sector_law, CRADLE, samples=1)
    with pytest.raises(iq.InputError, match="family"):
        iq.verification.fremond_admissibility_map(CRADLE, [0], [0], family="lower")
    with pytest.raises(iq.InputError, match="family"):
        fremond_matrix(0, 0, 2, family="lower")
    with pytest.raises(iq.InputError, match="1-D"):
        iq.verification.fremond_admissibility_map(CRADLE, [[0, 1]], [0])


def test_a_laws_own_exception_is_reported_with_its_type_and_message():
    p = iq.newtons_cradle(3)

    def fragile(problem):
        if problem.u_minus[0] > 0.5:
            raise ZeroDivisionError("the spring broke")
        return iq.sector_law(problem).u_plus

    report = iq.verify_law(fragile, p, samples=64, seed=1)
    assert report.violations["law_error"] > 0 and not report.ok
    ce = report.counterexamples["law_error"]
    assert ce.error == "ZeroDivisionError: the spring broke"
    assert ce.u_minus[0] > 0.5 and np.isnan(ce.u_plus).all()
    assert "ZeroDivisionError: the spring broke" in report.summary()


def test_a_law_answering_nan_is_a_law_error_and_complex_output_is_refused():
    p = iq.newtons_cradle(3)
    report = iq.verify_law(lambda q: np.full(3, np.nan), p, samples=8)
    assert report.violations["law_error"] == 8
    assert report.counterexamples["law_error"].error.startswith("NonFiniteError")
    with pytest.raises(iq.InputError, match="complex"):
        iq.verify_law(lambda q: iq.sector_law(q).u_plus + 1e-3j, p, samples=8)
