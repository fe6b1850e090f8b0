"""The sector law as an impact law, checked against the admissible set S (docs/theory.md §2, §4,
§6)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import impactqp as iq
from impactqp.tables.sector_table import sector_law_table

RNG = np.random.default_rng(7)


def lift(gamma: np.ndarray) -> np.ndarray:
    """Velocities with u₁ = 0 and gaps γ."""
    return np.concatenate([[0.0], np.cumsum(gamma)])


# --------------------------------------------------------------------------- reference
def test_classic_cradle() -> None:
    r = iq.sector_law(iq.newtons_cradle(3, v=2.0))
    np.testing.assert_allclose(r.u_plus, [0, 0, 2])
    np.testing.assert_allclose(r.impulses, [2, 2])  # Λ = (mv, mv), docs/theory.md §5
    assert (r.law, r.backend, r.coefficients) == ("sector", "sort", None)
    assert r.certificate.ok and "ok" in r.certificate.summary()
    assert r.classification.alpha_deg == pytest.approx(30.0, abs=1e-9)
    assert r.classification.dissipation == pytest.approx(1.0, abs=1e-12)


def test_five_balls_two_released() -> None:
    r = iq.sector_law(iq.newtons_cradle(5, v=1.5, mass=2.0, released=2))
    np.testing.assert_allclose(r.u_plus, [0, 0, 0, 1.5, 1.5])
    np.testing.assert_allclose(r.impulses, 2.0 * 1.5 * np.array([1, 2, 2, 1]))


@pytest.mark.parametrize("n", range(3, 8))
def test_random_velocities_are_sorted(n: int) -> None:
    for u in RNG.normal(size=(10, n)):
        p = iq.chain(np.full(n, 0.7), u)
        r = iq.sector_law(p)
        np.testing.assert_array_equal(r.u_plus, np.sort(u))
        st = p.structure
        np.testing.assert_allclose(st.M @ (r.u_plus - u), st.W @ r.impulses, atol=1e-12)
        assert r.certificate.ok and r.admissible


def test_long_sparse_chain_and_single_ball() -> None:
    u = RNG.normal(size=500)
    r = iq.sector_law(iq.chain(np.ones(500), u))
    assert r.problem.structure.sparse and r.certificate.ok
    np.testing.assert_array_equal(r.u_plus, np.sort(u))
    single = iq.sector_law(iq.chain([2.0], [3.0]))
    np.testing.assert_array_equal(single.u_plus, [3.0])
    assert single.impulses.shape == (0,)


# --------------------------------------------------------------------------- certificate
def test_certificate_measures_each_condition() -> None:
    p = iq.newtons_cradle(3)
    good = iq.sector_law(p)
    cert = iq.sector_law(p).certificate
    assert set(cert.residuals) == {"momentum", "impulse_sign", "kinematic", "energy_balance",
                                   "law_residual"}
    from impactqp.laws.sector import certify_sector

    # Moreau ε = 1 conserves energy and is kinetically fine, but is not the sector law
    moreau = iq.moreau(p, eps=1.0)
    other = certify_sector(p, moreau.u_plus, moreau.impulses)
    assert not other.ok and other.worst[0] == "law_residual"
    assert other.momentum < 1e-12 and other.energy_balance < 1e-12
    wrong_impulses = certify_sector(p, good.u_plus, good.impulses - 1.5)
    assert wrong_impulses.momentum > 0.1 and wrong_impulses.impulse_sign > 0.1
    assert not bool(wrong_impulses)


def test_failed_certificate_raises() -> None:
    class Broken(iq.SectorLaw):  # a wrong closed form must never come back as a success
        def closed_form(self, problem):
            a = super().closed_form(problem)
            return iq.Answer(a.u_plus * 1.01, a.impulses)

    with pytest.raises(iq.CertificateError, match="certificate failed"):
        iq.solve(iq.newtons_cradle(3), Broken())
    with pytest.raises(iq.InputError, match="tol"):
        iq.sector_law(iq.newtons_cradle(3), tol=-1.0)


# --------------------------------------------------------------------------- errors
def test_errors_say_why() -> None:
    with pytest.raises(iq.errors.SectorLawError, match="no continuous sorting law for unequal"):
        iq.sector_law(iq.chain([1.0, 2.0, 1.0], [1.0, 0.0, 0.0]))
    with pytest.raises(iq.errors.SectorLawError, match=r"180°/k \(here 70.53°\)"):
        iq.sector_law(iq.chain([1.0, 2.0, 1.0], [1.0, 0.0, 0.0]))  # cos = (1/2)/(3/2)
    with pytest.raises(iq.errors.SectorLawError, match=r"unequal masses\. impactqp\.reflection_law "
                       r"gives the elastic law of any two balls\.$"):
        iq.sector_law(iq.chain([1.0, 2.0], [1.0, 0.0]))
    from impactqp.laws.sector import wedge_angles

    np.testing.assert_allclose(wedge_angles(np.ones(4)), [60.0, 60.0])  # π/3: k = 3
    with pytest.raises(iq.errors.SectorLawError, match="walls"):
        iq.sector_law(iq.chain([1.0, 1.0], [1.0, 0.0], left_wall=True))
    with pytest.raises(iq.errors.SectorLawError, match="chains"):
        iq.sector_law(iq.random_impact(3, 2))
    with pytest.raises(iq.InputError, match="ImpactProblem"):
        iq.sector_law(np.eye(3))
    for exc in (iq.errors.SectorLawError, iq.errors.SectorInputError,
                iq.errors.SectorTableTooLarge):
        assert issubclass(exc, iq.InputError) and issubclass(exc, ValueError)


# --------------------------------------------------------------------------- u⁺ ∈ S
def cone_samples(n: int, per_cone: int) -> list[tuple[str, np.ndarray]]:
    """u⁻ from every cone of the table: each extreme ray (a boundary) and interior points."""
    out = []
    for cone in sector_law_table(n).cones:
        gammas = np.vstack([cone.rays, RNG.random((per_cone, n - 1)) @ cone.rays])
        out += [(cone.label, lift(g)) for g in gammas]
    return out


@pytest.mark.parametrize("n, per_cone, optimizer_every", [(3, 6, 1), (4, 2, 3), (5, 1, 12)])
def test_sector_velocity_is_in_S_in_every_cone(n: int, per_cone: int,
                                               optimizer_every: int) -> None:
    """Every cone, also inconsistent ones (γ⁻ᵢ > 0) and on boundary rays: sort(u⁻) ∈ S.

    True for every u⁻: Λ_k = m(Σ_{j≤k} u⁻_j − Σ_{j≤k} u⁺_j) ≥ 0 because the k smallest
    velocities have the smallest sum, γ⁺ ≥ 0 since u⁺ is sorted, and a permutation keeps
    the kinetic energy.
    """
    p0 = iq.chain(np.ones(n), np.zeros(n))
    for k, (label, u) in enumerate(cone_samples(n, per_cone)):
        p = p0.with_u_minus(u)
        r = iq.sector_law(p)
        S = p.admissible_set()
        assert S.contains(r.u_plus), label
        if k % optimizer_every == 0:
            assert S.contains(r.u_plus, method="optimizer"), label
        assert r.energy_after == pytest.approx(r.energy_before, rel=1e-12)
        c = r.classification
        if np.all(p.gamma_minus >= 0):  # u⁻ ∈ T_C: z⊥ = 0, nothing happens
            np.testing.assert_array_equal(r.u_plus, u)
            assert math.isnan(c.alpha_deg)
            continue
        assert c.dissipation == pytest.approx(1.0, abs=1e-9), label
        # α < 90°: ⟨u⁺ − u⁻, −z⊥⟩ = ⟨u⁺, −z⊥⟩ + ‖z⊥‖² ≥ ‖z⊥‖² as u⁺ ∈ T_C and −z⊥ ∈ N
        assert 0.0 <= c.alpha_deg < 90.0
        if n == 3:  # docs/theory.md §5: 30° is the largest deviation three equal balls can show
            assert c.alpha_deg <= 30.0 + 1e-6, (label, u, c.alpha_deg)


@pytest.mark.parametrize("n", range(3, 8))
def test_single_ball_cradle_angle(n: int) -> None:
    """(v, 0, …, 0) ↦ (0, …, 0, v): z = (v/n, …), so cos α = √(n / (2(n − 1))).

    30° for three balls, 35.26° for four, → 45° for many: the 30° bound of docs/theory.md §5 is a
    three-ball fact.
    """
    r = iq.sector_law(iq.newtons_cradle(n))
    expected = math.degrees(math.acos(math.sqrt(n / (2 * (n - 1)))))
    assert r.classification.alpha_deg == pytest.approx(expected, abs=1e-6)
    assert (expected > 30.0 + 1e-9) == (n > 3)


def test_three_ball_angle_on_inconsistent_cones() -> None:
    """Contact 2 separates (γ⁻₂ > 0) in both cases, and sort(u⁻) is still in S."""
    # Moreau's z closes both contacts (z = (½, ½, ½)): the full 30° of docs/theory.md §5
    p = iq.chain(np.ones(3), [1.0, 0.0, 0.5])
    r = iq.sector_law(p)
    np.testing.assert_array_equal(r.u_plus, [0.0, 0.5, 1.0])
    assert p.gamma_minus[1] > 0 and r.admissible
    assert r.classification.alpha_deg == pytest.approx(30.0, abs=1e-6)
    # z closes contact 1 only: the sector law is Moreau ε = 1 there (α = 0)
    p = iq.chain(np.ones(3), [1.0, 0.0, 1.0])
    r = iq.sector_law(p)
    np.testing.assert_allclose(r.u_plus, iq.moreau(p, eps=1.0).u_plus, atol=1e-12)
    assert r.classification.alpha_deg == pytest.approx(0.0, abs=1e-6)


# --------------------------------------------------------------------------- CLI
def test_sector_law_command(capsys: pytest.CaptureFixture[str]) -> None:
    from impactqp import cli

    assert cli.main(["sector-law", "--balls", "3"]) == 0
    out = capsys.readouterr().out
    assert "6 cones" in out and "u2 ≤ u3 ≤ u1" in out and "[0 1; -1 -1]" in out
    assert "maximal monotone: True" in out and "FAIL" not in out
    assert cli.main(["sector-law", "--balls", "9"]) == 2
    assert "sector_gamma_map" in capsys.readouterr().err


def test_a_chain_is_recognized_from_its_matrices_however_it_was_built():
    from impactqp.model.builders import chain_directions, recognize_chain

    rng = np.random.default_rng(5)
    for left, right in ((False, False), (True, False), (False, True)):
        built = iq.chain(np.ones(4), rng.standard_normal(4), left_wall=left, right_wall=right)
        plain = iq.ImpactProblem(np.eye(4), chain_directions(4, left_wall=left,
                                                             right_wall=right),
                                 built.u_minus)
        info = recognize_chain(plain)
        assert info is not None and (info.left_wall, info.right_wall) == (left, right)
        if not (left or right):
            a, b = iq.sector_law(built), iq.sector_law(plain)
            np.testing.assert_array_equal(a.u_plus, b.u_plus)
            np.testing.assert_allclose(a.impulses, b.impulses, atol=1e-15)
    W = chain_directions(4)
    assert recognize_chain(iq.ImpactProblem(np.eye(4), W[:, ::-1], np.ones(4))) is None
    assert recognize_chain(iq.ImpactProblem(np.eye(4), 2 * W, np.ones(4))) is None
    M = np.eye(4)
    M[0, 1] = M[1, 0] = 0.1
    assert recognize_chain(iq.ImpactProblem(M, W, np.ones(4))) is None
    with pytest.raises(iq.errors.SectorLawError, match="1-D chains"):
        iq.sector_law(iq.ImpactProblem(np.eye(4), W[:, ::-1], np.ones(4)))


@pytest.mark.parametrize("law", [iq.SectorLaw(), iq.ReflectionLaw()])
@pytest.mark.parametrize("scheme", ["event-driven", "moreau-jean"])
def test_chain_laws_simulate_a_system_whose_gaps_are_a_chain(law, scheme):
    from impactqp.model.builders import chain_directions

    system = iq.LinearSystem(np.eye(3), [0.0, 0.3, 0.6], [1.0, 0.0, 0.0], None,
                             chain_directions(3), [-0.3, -0.3])
    tr = iq.simulate(system, law, 1.0, scheme=scheme, h=1e-3)
    assert len(tr.events) == 1 and all(e.certified for e in tr.events)
    np.testing.assert_allclose(tr.v[-1], [0.0, 0.0, 1.0], atol=1e-12)
