"""The reflection law of chains with contact angles π/k (docs/theory.md §1, §2, §6, §7)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

import impactqp as iq
from impactqp.laws.sector import wedge_angles
from impactqp.tables.coxeter import (
    contact_angles,
    coxeter_labels,
    coxeter_type,
    extended_masses,
    shared_mass,
)
from impactqp.tables.reflection_group import check_reflection_problem, elastic_collisions
from impactqp.tables.reflection_table import reflection_law_table
from impactqp.tables.sector_table import sector_gamma_map, sector_law_table
from impactqp.verification.sampled import sample_u_minus

RNG = np.random.default_rng(11)
M4, M6 = iq.tables.continuous_mass_ratios(4), iq.tables.continuous_mass_ratios(6)


def path_masses(ks: tuple[int, ...], x2: float) -> np.ndarray:
    """Masses of a free chain with angles π/k_i: 1/m₁ = 1, 1/m₂ = x2, then each next inverse
    mass solves cos²(π/k)(x_{i}+x_{i+1})(x_{i+1}+x_{i+2}) = x_{i+1}² (docs/theory.md §1)."""
    x = [1.0, x2]
    for k in ks:
        a, b = x[-2], x[-1]
        x.append(b * b / (math.cos(math.pi / k) ** 2 * (a + b)) - b)
    assert min(x) > 0
    return 1.0 / np.array(x)


B3, H3, F4 = path_masses((4, 3), 4.0), path_masses((5, 3), 10.0), path_masses((3, 4, 3), 5.0)


def problem(masses: np.ndarray, u=None, **walls) -> iq.ImpactProblem:
    return iq.chain(masses, np.zeros(len(masses)) if u is None else u, **walls)


def samples(p: iq.ImpactProblem, k: int) -> np.ndarray:
    """u⁻ of both signs of γ⁻ (inconsistent ones included)."""
    return RNG.normal(size=(k, p.n_dof)) / np.sqrt(np.diag(p.M))


# --------------------------------------------------------------------------- geometry
def test_one_collision_is_the_textbook_elastic_collision() -> None:
    """The reflection u − 2(γ/G₁₁)M⁻¹w of docs/theory.md §1 is the two-body elastic collision."""
    for m1, m2, v1, v2 in RNG.uniform(0.2, 3.0, size=(20, 4)):
        u, lam, n = elastic_collisions(problem(np.array([m1, m2]), [v1, -v2]))
        assert n == 1 and lam[0] > 0
        np.testing.assert_allclose(u, [((m1 - m2) * v1 - 2 * m2 * v2) / (m1 + m2),
                                       (-(m2 - m1) * v2 + 2 * m1 * v1) / (m1 + m2)])
    u, _, n = elastic_collisions(problem(np.array([2.0]), [-3.0], left_wall=True))
    assert n == 1 and u[0] == pytest.approx(3.0, rel=1e-15)  # a wall reflects the ball


def test_angles_formula_and_range() -> None:
    for _ in range(20):
        m = RNG.uniform(0.1, 10.0, size=5)
        theta = contact_angles(problem(m).delassus)
        np.testing.assert_allclose(np.degrees(theta), wedge_angles(m), rtol=1e-12)
        assert np.all((theta > 0) & (theta < math.pi / 2))  # 90° (k = 2) is never reached
        w = contact_angles(problem(m, left_wall=True).delassus)[0]  # wall | ball 1 | ball 2
        assert math.cos(w) == pytest.approx(math.sqrt(m[1] / (m[0] + m[1])))
    assert np.degrees(contact_angles(problem(np.ones(2), left_wall=True).delassus))[0] == \
        pytest.approx(45.0)  # equal balls at a wall: B_n


@pytest.mark.parametrize("k, m2", [(3, 1.0), (4, math.sqrt(2) - 1), (5, math.sqrt(5) - 2),
                                   (6, 2 / math.sqrt(3) - 1)])
def test_continuous_mass_ratios(k: int, m2: float) -> None:
    m = iq.tables.continuous_mass_ratios(k)
    assert m[1] == pytest.approx(m2, rel=1e-12) and m[0] == m[2] == 1.0
    assert coxeter_labels(contact_angles(problem(m).delassus)) == [k]
    m = iq.tables.continuous_mass_ratios(k, m1=2.0, m3=0.3)
    assert math.degrees(contact_angles(problem(m).delassus)[0]) == pytest.approx(180 / k)
    wall = shared_mass(math.pi / k, math.inf, 1.0)  # wall | ball | ball: m/1 = tan²(π/k)
    assert wall == pytest.approx(math.tan(math.pi / k) ** 2)


def test_unattainable_ratios_are_refused() -> None:
    with pytest.raises(iq.errors.SectorInputError, match="infinitely heavy middle ball"):
        iq.tables.continuous_mass_ratios(2)
    with pytest.raises(iq.errors.SectorInputError, match="integer"):
        iq.tables.continuous_mass_ratios(1)
    with pytest.raises(iq.errors.SectorInputError, match="90"):
        shared_mass(math.pi / 2, 1.0, 1.0)
    # (6, 3) and (4, 4) are affine diagrams: 1 − cos²θ₁ − cos²θ₂ > 0 for real masses
    assert coxeter_type((6, 3)) is None and coxeter_type((4, 4)) is None
    for m in RNG.uniform(0.01, 100.0, size=(60, 4)):
        c = np.cos(contact_angles(problem(m).delassus))
        assert 1 - c @ c > 0


# --------------------------------------------------------------------------- equal masses
@pytest.mark.parametrize("n", [2, 3, 4, 6])
def test_equal_masses_is_the_sector_law(n: int) -> None:
    p0 = problem(np.full(n, 0.7))
    for u in samples(p0, 15):
        r, s = iq.reflection_law(p0.with_u_minus(u)), iq.sector_law(p0.with_u_minus(u))
        np.testing.assert_allclose(r.u_plus, s.u_plus, atol=1e-12)
        np.testing.assert_allclose(r.impulses, s.impulses, atol=1e-12)
        assert (r.law, r.backend) == ("reflection", "reflections") and r.certificate.ok


def test_long_equal_chain_and_sector_table() -> None:
    u = RNG.normal(size=80)
    r = iq.reflection_law(iq.chain(np.ones(80), u, sparse=True))
    np.testing.assert_allclose(r.u_plus, np.sort(u), atol=1e-12)
    for n in (3, 4):
        table, sector = reflection_law_table(np.ones(n)), sector_law_table(n)
        assert len(table.cones) == len(sector.cones) == math.factorial(n)
        key = lambda Q: np.round(Q, 9).tobytes()  # noqa: E731
        assert {key(c.Q) for c in table.cones} == {key(c.Q) for c in sector.cones}
        g = RNG.normal(size=(200, n - 1))
        np.testing.assert_allclose(table.apply(g), sector_gamma_map(g), atol=1e-12)


# --------------------------------------------------------------------------- groups, tables
@pytest.mark.parametrize("masses, walls, name, order, reflections", [
    (M4, {}, "B2", 8, 4), (iq.tables.continuous_mass_ratios(5), {}, "I2(5)", 10, 5),
    (M6, {}, "G2", 12, 6), (np.ones(4), {}, "A3", 24, 6), (B3, {}, "B3", 48, 9),
    (H3, {}, "H3", 120, 15), (np.ones(3), {"left_wall": True}, "B3", 48, 9),
    (np.ones(2), {"right_wall": True}, "B2", 8, 4)])
def test_group_table_and_certificate(masses, walls, name, order, reflections) -> None:
    table = reflection_law_table(masses, **walls)
    assert (table.group.name, table.group.order, len(table.cones)) == (name, order, order)
    assert max(len(c.word) for c in table.cones) == reflections  # longest element
    d = table.G.shape[0]
    for c in table.cones:  # Q maps its cone into the orthant (T_C)
        assert (c.Q @ c.rays.T).min() >= -1e-12, c.label
    g = RNG.normal(size=(400, d))  # the cones tile γ-space with disjoint interiors
    slack = np.einsum("cij,kj->kci", table.stacked_Q, g).min(axis=2)
    assert np.all((slack > 1e-12).sum(axis=1) == 1)
    cert = table.certificate
    assert cert.maximal_monotone and cert.admissible, cert.summary()
    assert cert.n_neighbour_pairs == order * d // 2
    # a consistent u⁻ (γ⁻ < 0 everywhere) lies in −T_C = w₀T_C: every hyperplane collides
    p = problem(masses, **walls)
    gamma = -RNG.uniform(0.5, 1.5, size=d)
    u = np.linalg.lstsq(p.W.T, gamma, rcond=None)[0]
    assert elastic_collisions(p.with_u_minus(u))[2] == reflections


def test_big_groups() -> None:
    p = problem(F4)
    assert check_reflection_problem(p).name == "F4"
    assert check_reflection_problem(problem(np.ones(8))).order == 40320
    with pytest.raises(iq.errors.SectorTableTooLarge, match="A7 has 40320"):
        reflection_law_table(np.ones(8))
    u = RNG.normal(size=8)  # the law itself needs no table (checked by the opposite order)
    np.testing.assert_allclose(iq.reflection_law(iq.chain(np.ones(8), u)).u_plus, np.sort(u))


# --------------------------------------------------------------------------- the law
@pytest.mark.parametrize("masses, walls", [(M4, {}), (M6, {}), (B3, {}), (H3, {}), (F4, {}),
                                           (np.array([1.0, 1.0 / 3.0]),
                                            {"right_wall": True})])
def test_law_is_order_independent_in_S_and_elastic(masses, walls) -> None:
    p0 = problem(masses, **walls)
    V = samples(p0, 40)
    out = []
    for u in V:
        p = p0.with_u_minus(u)
        (a, la, na), (b, lb, nb) = (elastic_collisions(p, o) for o in ("left", "right"))
        np.testing.assert_allclose(a, b, atol=1e-12 * p.velocity_scale)
        np.testing.assert_allclose(la, lb, atol=1e-11 * p.velocity_scale)
        assert na == nb  # each collision removes one separating reflecting hyperplane
        r = iq.reflection_law(p)
        np.testing.assert_array_equal(r.u_plus, a)
        assert r.certificate.ok and r.certificate.law_residual < 1e-12
        S = p.admissible_set()
        assert S.contains(r.u_plus)  # also for inconsistent u⁻ (some γ⁻ᵢ > 0)
        assert r.energy_after == pytest.approx(r.energy_before, rel=1e-12)
        if np.all(p.gamma_minus >= 0):
            np.testing.assert_array_equal(r.u_plus, u)
        out.append(r.u_plus)
    du_minus = V[:, None] - V[None]
    du_plus = np.array(out)[:, None] - np.array(out)[None]
    norm = lambda d: np.sqrt(np.einsum("...i,ij,...j->...", d, p0.M, d))  # noqa: E731
    assert np.all(norm(du_plus) <= norm(du_minus) * (1 + 1e-12) + 1e-14)  # non-expansive


@pytest.mark.parametrize("masses", [M4, M6])
def test_continuous_across_every_cone_boundary(masses) -> None:
    table = reflection_law_table(masses)
    p0 = problem(masses)
    R = np.linalg.pinv(p0.W.T)  # a lift of γ to u
    for cone in table.cones:
        for ray in cone.rays:  # boundary ray of two chambers, approached from both sides
            normal = np.array([-ray[1], ray[0]])
            for h in (1e-3, 1e-6):
                a, b = (iq.reflection_law(p0.with_u_minus(R @ (ray + s * h * normal))).u_plus
                        for s in (1, -1))
                assert p0.norm(a - b) <= p0.norm(R @ (2 * h * normal)) * (1 + 1e-9)


@pytest.mark.parametrize("k", [4, 6])
def test_even_k_consistent_impacts_are_moreau_elastic(k: int) -> None:
    """For even k, w₀ = −1: on consistent u⁻ the law is u⁺ = 2 v_cm − u⁻, Moreau ε = 1,
    because an acute T_C lies in N, so u⁻ ∈ −T_C has z = prox(u⁻) = common velocity."""
    p0 = problem(iq.tables.continuous_mass_ratios(k))
    for u in sample_u_minus(p0, 20, RNG, consistent_only=True):
        p = p0.with_u_minus(u)
        np.testing.assert_allclose(iq.reflection_law(p).u_plus,
                                   iq.moreau(p, eps=1.0).u_plus, atol=1e-9)
    cradle = problem(np.ones(3), [1.0, 0.0, 0.0])  # k = 3 is odd: (0, 0, 1) ≠ Moreau
    assert np.abs(iq.reflection_law(cradle).u_plus - iq.moreau(cradle, eps=1.0).u_plus
                  ).max() > 0.3


def test_verify_law_reports_ok() -> None:
    rep = iq.verify_law(iq.reflection_law, problem(M6), samples=300, seed=3)
    assert rep.ok, rep.summary()
    table = reflection_law_table(np.ones(2), left_wall=True)
    exact = iq.verify_law(table)
    assert exact.ok and exact.method == "exact" and exact.certificate.maximal_monotone
    table.cones = [replace(c, Q=1.1 * c.Q) for c in table.cones]  # expands: caught exactly
    bad = iq.verify_law(table)
    assert not bad.ok and bad.violations["energetic"] == 8
    ce = bad.counterexamples["energetic"]  # recheck on the wall problem itself
    p = problem(np.ones(2), ce.u_minus, left_wall=True)
    assert p.kinetic_energy(ce.u_plus) > p.kinetic_energy() * (1 + 1e-3)


# --------------------------------------------------------------------------- no law
@pytest.mark.parametrize("masses, angle, k, fix", [([1.0, 2.0, 1.0], "70.5288°", 3, "m2 = 1 "),
                                                   ([1.0, 0.5, 1.0], "48.1897°", 4,
                                                    "m2 = 0.414214")])
def test_angle_not_pi_over_k_has_no_continuous_law(masses, angle, k, fix) -> None:
    p = problem(np.array(masses), [1.0, 0.0, -1.0])
    with pytest.raises(iq.errors.SectorLawError, match="no continuous elastic law") as err:
        iq.reflection_law(p)
    msg = str(err.value)
    assert angle in msg and f"180°/{k} = " in msg and fix in msg and "discontinuous" in msg
    with pytest.raises(iq.errors.SectorLawError, match=angle):
        reflection_law_table(masses)
    (a, _, _), (b, _, _) = (elastic_collisions(p, o) for o in ("left", "right"))
    assert np.abs(a - b).max() > 0.3  # two collision orders, two different outcomes
    assert p.admissible_set().contains(a) and p.admissible_set().contains(b)
    # the discontinuity: tiny gaps decide the order; the outcome jumps as they → 0
    for eps in (1e-6, 1e-9):
        np.testing.assert_allclose(simulate(masses, p.u_minus, [0.0, eps]), a, atol=1e-5)
        np.testing.assert_allclose(simulate(masses, p.u_minus, [eps, 0.0]), b, atol=1e-5)


def simulate(masses, u, gaps) -> np.ndarray:
    """Event-driven free balls on a line: the next closing gap collides elastically."""
    m, u, g = np.asarray(masses), np.array(u, dtype=float), np.array(gaps, dtype=float)
    for _ in range(1000):
        closing = [(g[i] / -d, i) for i, d in enumerate(np.diff(u)) if d < 0]
        if not closing:
            return u
        t, i = min(closing)
        g = g + t * np.diff(u)
        g[i] = 0.0
        (m1, m2), (v1, v2) = m[i:i + 2], u[i:i + 2].copy()
        u[i:i + 2] = ((m1 - m2) * v1 + 2 * m2 * v2, (m2 - m1) * v2 + 2 * m1 * v1)
        u[i:i + 2] /= m1 + m2
    raise AssertionError("no end of collisions")


def test_gap_limits_agree_when_the_angle_is_pi_over_k() -> None:
    for masses in (M4, M6, np.ones(3)):
        u = np.array([1.0, 0.0, -1.0])
        left, right = (simulate(masses, u, g) for g in ([0.0, 1e-9], [1e-9, 0.0]))
        np.testing.assert_allclose(left, right, atol=1e-6)
        np.testing.assert_allclose(left, iq.reflection_law(problem(masses, u)).u_plus,
                                   atol=1e-6)


def test_other_refusals() -> None:
    with pytest.raises(iq.errors.SectorLawError, match=r"T_C = \{0\}"):
        iq.reflection_law(problem(np.ones(2), left_wall=True, right_wall=True))
    with pytest.raises(iq.errors.SectorLawError, match="chains"):
        iq.reflection_law(iq.random_impact(3, 2))
    with pytest.raises(iq.InputError, match="order"):
        elastic_collisions(problem(np.ones(2)), "middle")
    single = iq.reflection_law(problem(np.array([2.0]), [3.0]))
    assert single.u_plus.tolist() == [3.0] and single.impulses.shape == (0,)
    with pytest.raises(iq.errors.SectorLawError, match="reflection_law gives the continuous"):
        iq.sector_law(problem(M4))
    assert extended_masses(np.ones(2), left_wall=True).tolist() == [math.inf, 1.0, 1.0]
