"""Coulomb's law of frictional impacts (docs/theory.md §16): closed forms of a sphere and a
point mass hitting a plane (stick and slip), μ = 0 against Newton's law on the normal
problem, planar against spatial models, two solution methods, scale invariance, the
certificate's verdict on corrupted answers, S with friction decided two ways, verify_law,
batches and bad input as named errors."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.laws.base import Answer


def sphere_closed_form(m, R, inertia, u, mu, e):
    """The planar impact of a sphere on the plane y = 0 by hand: the normal impulse stops
    (e = 0) or reverses the normal velocity, the tangential one stops the slip s = vₓ + Rω if
    the cone allows it, else it is μ times the normal one against the slip."""
    vx, vn, w = u
    pn = m * (1 + e) * -vn
    slip = vx + R * w
    m_t = 1.0 / (1.0 / m + R * R / inertia)  # the effective tangential mass
    stick = m_t * abs(slip) <= mu * pn
    pt = -m_t * slip if stick else -mu * pn * np.sign(slip)
    return np.array([vx + pt / m, -e * vn, w + R * pt / inertia]), stick


CASES = [  # (u⁻ planar, μ, e)
    ((3.0, -1.0, 0.0), 0.1, 0.5),   # slides
    ((3.0, -1.0, 0.0), 2.0, 0.5),   # sticks
    ((0.5, -2.0, 1.0), 0.3, 0.0),   # slides
    ((0.5, -2.0, 1.0), 0.7, 0.0),   # sticks
    ((-1.0, -1.0, -4.0), 0.4, 1.0),  # slides backwards
    ((1.0, -1.0, -2.0), 0.2, 0.3),  # rolls already: no tangential impulse
]


@pytest.mark.parametrize("u, mu, e", CASES)
def test_sphere_on_plane_matches_the_closed_form(u, mu, e) -> None:
    m, R = 2.0, 0.5
    expected, stick = sphere_closed_form(m, R, 0.4 * m * R * R, u, mu, e)
    # the effective tangential mass of a solid sphere is 2/7 m: stick iff |s| ≤ 7/2 μ(1+e)|vₙ|
    assert stick == (abs(u[0] + R * u[2]) <= 3.5 * mu * (1 + e) * abs(u[1]))
    result = iq.solve(iq.friction.sphere_on_plane(m, R, u), iq.Coulomb(mu, e))
    assert result.ok and result.certificate.natural_map <= 1e-9
    np.testing.assert_allclose(result.u_plus, expected, rtol=1e-9, atol=1e-9 * max(map(abs, u)))
    slip_after = result.u_plus[0] + R * result.u_plus[2]
    assert (abs(slip_after) <= 1e-9) == (stick or u[0] + R * u[2] == 0)
    assert result.admissible.member
    assert result.energy_after <= result.energy_before * (1 + 1e-12)


def test_both_regimes_are_met() -> None:
    m, R = 2.0, 0.5
    regimes = {sphere_closed_form(m, R, 0.4 * m * R * R, u, mu, e)[1] for u, mu, e in CASES}
    assert regimes == {True, False}


@pytest.mark.parametrize("mu", [0.1, 0.5, 3.0])
def test_point_mass_in_space_slides_along_its_slip(mu) -> None:
    u = np.array([3.0, 4.0, -2.0])
    e = 0.25
    result = iq.solve(iq.friction.point_on_plane(1.5, u), iq.Coulomb(mu, e))
    loss = min(5.0, mu * (1 + e) * 2.0)  # the tangential speed lost, at most all of it
    expected = np.array([3.0, 4.0, 0.0]) * (5.0 - loss) / 5.0
    expected[2] = e * 2.0
    np.testing.assert_allclose(result.u_plus, expected, rtol=1e-9, atol=1e-9)


def test_separating_contact_gets_no_impulse() -> None:
    result = iq.solve(iq.friction.point_on_plane(1.0, [1.0, 2.0]), iq.Coulomb(0.5, 0.5))
    np.testing.assert_allclose(result.u_plus, [1.0, 2.0], atol=1e-12)
    np.testing.assert_allclose(result.impulses, 0.0, atol=1e-12)


def random_frictional(n: int, m: int, d: int, seed: int, approaching: bool = True):
    """Random SPD M, W with d columns per contact, u⁻ whose normals approach."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    M = A @ A.T / n + np.eye(n)
    W = rng.standard_normal((n, m * d))
    u = rng.standard_normal(n)
    p = iq.ImpactProblem(M, W, u, contact_dim=d)
    if approaching:  # push u⁻ along −M⁻¹W_n so every normal approaches
        Wn = W[:, ::d]
        u = u - np.linalg.solve(M, Wn) @ (np.abs(np.linalg.lstsq(
            Wn.T @ np.linalg.solve(M, Wn), Wn.T @ u, rcond=None)[0]) + 1.0)
        p = p.with_u_minus(u)
    return p


@pytest.mark.parametrize("d", [2, 3])
def test_mu_zero_is_newton_on_the_normal_problem(d) -> None:
    p = random_frictional(8, 3, d, seed=d)
    e = np.array([0.0, 0.4, 0.9])
    friction = iq.solve(p, iq.Coulomb(0.0, e))
    newton = iq.solve(p.normal_problem(), iq.Newton(e))
    np.testing.assert_allclose(friction.u_plus, newton.u_plus, rtol=1e-8, atol=1e-9)
    np.testing.assert_allclose(friction.impulses[::d], newton.impulses, rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(friction.impulses.reshape(3, d)[:, 1:], 0.0, atol=1e-12)


def test_large_mu_sticks() -> None:
    for p in (iq.friction.sphere_on_plane(1.0, 0.3, [2.0, -1.0, 5.0]),
              iq.friction.sphere_on_plane(1.0, 0.3, [2.0, 1.0, -1.0, 0.5, 3.0, 1.0]),
              iq.friction.two_spheres([1.0, 3.0], [0.5, 0.2], [1, 0.3, 2, -1, 0.5, 0],
                                      normal=[1, 0.2])):
        gamma = iq.solve(p, iq.Coulomb(1e3, 0.5)).gamma_plus
        d = p.contact_dim
        np.testing.assert_allclose(gamma.reshape(-1, d)[:, 1:], 0.0, atol=1e-9)
        np.testing.assert_allclose(gamma[::d], -0.5 * p.gamma_minus[::d], rtol=1e-9)


def test_planar_and_spatial_models_agree() -> None:
    u2 = np.array([3.0, -1.0, 2.0])  # (vₓ, v_y = normal, ω about z)
    u3 = np.array([3.0, 0.0, -1.0, 0.0, -2.0, 0.0])  # (vₓ, v_y, v_z = normal, ω): ω_y = −ω
    for mu in (0.05, 0.5):
        a = iq.solve(iq.friction.sphere_on_plane(1.0, 0.5, u2), iq.Coulomb(mu, 0.3)).u_plus
        b = iq.solve(iq.friction.sphere_on_plane(1.0, 0.5, u3), iq.Coulomb(mu, 0.3)).u_plus
        np.testing.assert_allclose(b, [a[0], 0.0, a[1], 0.0, -a[2], 0.0], rtol=1e-9,
                                   atol=1e-12)
    # two spheres moving in the x–y plane: (v, ω_z) per sphere against (v, 0, 0, 0, ω_z)
    planar = np.array([1.0, 0.5, 2.0, -1.0, 0.2, -1.0])
    spatial = np.zeros(12)
    spatial[[0, 1, 5, 6, 7, 11]] = planar
    for mu in (0.05, 0.8):
        a = iq.solve(iq.friction.two_spheres([1, 2], [0.5, 1], planar, normal=[1, 0.3]),
                     iq.Coulomb(mu, 0.4)).u_plus
        b = iq.solve(iq.friction.two_spheres([1, 2], [0.5, 1], spatial, normal=[1, 0.3, 0]),
                     iq.Coulomb(mu, 0.4)).u_plus
        np.testing.assert_allclose(b[[0, 1, 5, 6, 7, 11]], a, rtol=1e-8, atol=1e-10)
        np.testing.assert_allclose(b[[2, 3, 4, 8, 9, 10]], 0.0, atol=1e-10)


def test_two_spheres_conserve_momentum_and_angular_momentum_about_the_contact() -> None:
    masses, radii = np.array([1.0, 2.0]), np.array([0.5, 1.0])
    p = iq.friction.two_spheres(masses, radii, [1.0, 0.5, 2.0, -1.0, 0.2, -1.0], normal=[1, 0])
    u = iq.solve(p, iq.Coulomb(0.3, 0.5)).u_plus
    before, after = p.u_minus.reshape(2, 3), u.reshape(2, 3)
    np.testing.assert_allclose(masses @ after[:, :2], masses @ before[:, :2], rtol=1e-12)
    # each sphere's angular momentum about its contact point is conserved
    inertia = 0.4 * masses * radii ** 2
    lever = np.array([[radii[0], 0.0], [-radii[1], 0.0]])  # contact point from each centre

    def about_contact(v):
        return inertia * v[:, 2] - masses * (lever[:, 0] * v[:, 1] - lever[:, 1] * v[:, 0])
    np.testing.assert_allclose(about_contact(after), about_contact(before), atol=1e-12)


def test_multi_contact_two_methods_agree() -> None:
    for d in (2, 3):
        p = random_frictional(9, 3, d, seed=10 + d)
        a = iq.solve(p, iq.Coulomb([0.2, 0.5, 0.1], 0.3, method="clarabel"))
        b = iq.solve(p, iq.Coulomb([0.2, 0.5, 0.1], 0.3, method="nsgs"))
        assert a.ok and b.ok
        np.testing.assert_allclose(a.u_plus, b.u_plus, rtol=1e-7,
                                   atol=1e-8 * np.abs(p.u_minus).max())
        assert a.admissible.member and b.admissible.member


@pytest.mark.parametrize("factor", [1e-50, 1e50, 1e-150, 1e150])
def test_velocity_scale_invariance(factor) -> None:
    p = random_frictional(6, 2, 3, seed=3)
    law = iq.Coulomb([0.3, 0.6], [0.2, 0.7])
    base = iq.solve(p, law)
    scaled = iq.solve(p.with_u_minus(p.u_minus * factor), law)
    np.testing.assert_allclose(scaled.u_plus / factor, base.u_plus, rtol=1e-8,
                               atol=1e-10 * np.abs(base.u_plus).max())
    np.testing.assert_allclose(scaled.impulses / factor, base.impulses, rtol=1e-7,
                               atol=1e-10 * np.abs(base.impulses).max())


@pytest.mark.parametrize("c", [1e-6, 1e6])
def test_mass_scale_invariance(c) -> None:
    p = random_frictional(6, 2, 3, seed=4)
    law = iq.Coulomb(0.4, 0.5)
    base = iq.solve(p, law)
    heavy = iq.solve(iq.ImpactProblem(c * p.M, p.W, p.u_minus, contact_dim=3), law)
    np.testing.assert_allclose(heavy.u_plus, base.u_plus, rtol=1e-8,
                               atol=1e-10 * np.abs(base.u_plus).max())
    np.testing.assert_allclose(heavy.impulses / c, base.impulses, rtol=1e-7,
                               atol=1e-10 * np.abs(base.impulses).max())


def test_contact_column_scale_invariance() -> None:
    p = random_frictional(7, 2, 3, seed=6)
    law = iq.Coulomb([0.3, 0.8], 0.4)
    base = iq.solve(p, law)
    d = np.repeat([1e-3, 50.0], 3)  # a contact's three columns scaled together
    scaled = iq.solve(iq.ImpactProblem(p.M, p.W * d, p.u_minus, contact_dim=3), law)
    np.testing.assert_allclose(scaled.u_plus, base.u_plus, rtol=1e-8,
                               atol=1e-10 * np.abs(base.u_plus).max())
    np.testing.assert_allclose(scaled.impulses * d, base.impulses, rtol=1e-7,
                               atol=1e-9 * np.abs(base.impulses).max())


@pytest.mark.parametrize("mu, e", [(0.05, 0.5), (0.3, 0.5), (2.0, 0.0)])
def test_two_spheres_match_the_closed_form(mu, e) -> None:
    """In contact coordinates G is diagonal for spheres: the normal velocity is restituted
    and the slip is stopped or reduced by μ(1+e)|γ⁻ₙ| G_tt/G_nn, G_nn = 1/m₁ + 1/m₂,
    G_tt = G_nn + R₁²/I₁ + R₂²/I₂."""
    m, R = np.array([1.0, 3.0]), np.array([0.5, 0.2])
    p = iq.friction.two_spheres(m, R, [1.0, 0.3, 2.0, -1.0, 0.5, 0.0], normal=[1.0, 0.2])
    g_nn = (1 / m).sum()
    g_tt = g_nn + (R ** 2 / (0.4 * m * R ** 2)).sum()
    gn, gt = p.gamma_minus
    assert gn < 0
    slip = max(0.0, abs(gt) - mu * (1 + e) * -gn * g_tt / g_nn) * np.sign(gt)
    np.testing.assert_allclose(iq.solve(p, iq.Coulomb(mu, e)).gamma_plus, [-e * gn, slip],
                               rtol=1e-9, atol=1e-10)


def test_batch_equals_single_solves() -> None:
    p = iq.friction.sphere_on_plane(2.0, 0.5, [1.0, -1.0, 0.0])
    law = iq.Coulomb(0.3, 0.5)
    rows = np.random.default_rng(0).standard_normal((6, 3)) - [0.0, 2.0, 0.0]
    batch = iq.solve_batch(p, law, rows)
    for u, u_plus, lam in zip(rows, batch.u_plus, batch.impulses, strict=True):
        single = iq.solve(p.with_u_minus(u), law)
        np.testing.assert_allclose(u_plus, single.u_plus, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(lam, single.impulses, rtol=1e-10, atol=1e-12)
    assert batch.ok.all()


# --- the certificate ----------------------------------------------------------------------------

def test_certificate_fails_corrupted_answers() -> None:
    p = iq.friction.sphere_on_plane(2.0, 0.5, [3.0, -1.0, 0.0])
    law = iq.Coulomb(0.1, 0.5)
    good = iq.solve(p, law)
    assert law.certificate(p, Answer(good.u_plus, good.impulses), 1e-9).ok
    jump = p.structure.impulse_velocity
    corrupt = {  # what is wrong → (u⁺, Λ)
        "momentum": (good.u_plus + [1e-3, 0, 0], good.impulses),
        "cone": (p.u_minus + jump(good.impulses * [1, 2]), good.impulses * [1, 2]),
        "penetration": (p.u_minus + jump(good.impulses * [0.5, 1]), good.impulses * [0.5, 1]),
        "wrong slip": (p.u_minus + jump(good.impulses * [1, 0.5]), good.impulses * [1, 0.5]),
    }
    for name, (u, lam) in corrupt.items():
        cert = law.certificate(p, Answer(u, lam), 1e-9)
        assert not cert.ok, name
    assert law.certificate(p, Answer(*corrupt["cone"]), 1e-9).cone > 1e-3
    assert law.certificate(p, Answer(*corrupt["penetration"]), 1e-9).non_penetration > 1e-3
    nan = law.certificate(p, Answer(good.u_plus, good.impulses * np.nan), 1e-9)
    assert not nan.ok


# --- S with friction ----------------------------------------------------------------------------

def test_membership_exact_and_optimizer_agree() -> None:
    p = random_frictional(7, 2, 3, seed=5)  # W of full column rank: Λ unique
    assert p.structure.full_column_rank
    small, large = iq.Coulomb(0.1, 0.0), iq.Coulomb(2.0, 0.0)
    S = p.admissible_set(mu=0.1)
    inside = iq.solve(p, small).u_plus
    outside = iq.solve(p, large).u_plus  # sticks harder than μ = 0.1 allows
    for u, member in ((inside, True), (outside, False)):
        exact, opt = S.contains(u), S.contains(u, method="optimizer")
        assert (exact.method, opt.method) == ("exact", "optimizer")
        assert bool(exact) == bool(opt) == member
        assert opt.kinetic <= exact.kinetic + 1e-9  # the SOCP's is the distance itself
    np.testing.assert_allclose(S.contains(inside).impulses, iq.solve(p, small).impulses,
                               rtol=1e-8, atol=1e-10)
    assert iq.solve(p, large).admissible.member  # in its own S


def box_on_two_corners(u_minus):
    """A unit square (x, y, θ) landing flat on two corners: 4 impulse columns for 3 degrees
    of freedom, W of rank 3."""
    M = np.diag([1.0, 1.0, 1.0 / 6.0])
    W = np.array([[0.0, 1.0, 0.0, 1.0], [1.0, 0.0, 1.0, 0.0], [-0.5, 0.5, 0.5, 0.5]])
    return iq.ImpactProblem(M, W, u_minus, contact_dim=2)


@pytest.mark.parametrize("mu", [0.1, 0.5, 2.0])
def test_rank_deficient_two_methods_agree_and_stick_or_slide(mu) -> None:
    p = box_on_two_corners([1.0, -1.0, 0.3])
    a = iq.solve(p, iq.Coulomb(mu, 0.3, method="clarabel"))
    b = iq.solve(p, iq.Coulomb(mu, 0.3, method="nsgs"))
    np.testing.assert_allclose(a.u_plus, b.u_plus, rtol=1e-8, atol=1e-9)
    # by hand: both corners restituted fix v_y⁺ = 0.3 and ω⁺ = −0.09 whatever the friction;
    # the corners share the slip s = vₓ + ω/2, which the horizontal impulse T changes one for
    # one once ω⁺ is fixed: s⁺ = 1 + T − 0.045, with |T| ≤ μ(Λ_n1 + Λ_n2) = 1.3μ
    vx, vy, w = a.u_plus
    assert vy == pytest.approx(0.3, abs=1e-9) and w == pytest.approx(-0.09, abs=1e-9)
    assert vx + 0.5 * w == pytest.approx(max(0.0, 0.955 - 1.3 * mu), abs=1e-9)


def test_membership_rank_deficient_uses_the_cone_program() -> None:
    p = box_on_two_corners([1.0, -1.0, 0.0])
    assert not p.structure.full_column_rank
    result = iq.solve(p, iq.Coulomb(0.3, 0.0))
    member = result.admissible
    assert member.member and member.method == "optimizer"
    frictionless = iq.solve(p.normal_problem(), iq.Moreau(0.0)).u_plus  # no tangential impulse
    assert iq.solve(p, iq.Coulomb(0.0, 0.0)).admissible.member
    assert p.admissible_set(mu=0.0).contains(frictionless).member
    assert not p.admissible_set(mu=0.0).contains(result.u_plus).member  # friction was used
    assert p.admissible_set(mu=0.3).contains(p.u_minus * 1.5).energetic > 0


def test_verify_law_on_coulomb_and_on_a_law_leaving_the_cone() -> None:
    p = iq.friction.sphere_on_plane(2.0, 0.5, [1.0, -1.0, 0.0])
    report = iq.verify_law(iq.Coulomb(0.3, 0.5), p, samples=40)
    assert {k: report.violations[k] for k in ("kinematic", "kinetic", "energetic",
                                              "law_error")} == dict.fromkeys(
        ("kinematic", "kinetic", "energetic", "law_error"), 0)

    def always_sticks(q):  # ignores μ = 0.3: its impulses leave the friction cone
        return iq.solve(q, iq.Coulomb(1e3, 0.5))
    bad = iq.verify_law(always_sticks, p, samples=40, mu=0.3)
    assert bad.violations["kinetic"] > 0 and not bad.ok
    assert bad.counterexamples["kinetic"].amount > 1e-3
    assert iq.verify_law(always_sticks, p, samples=40, mu=1e3).violations["kinetic"] == 0
    with pytest.raises(iq.InputError, match="mu"):
        iq.verify_law(always_sticks, p, samples=40)


def coupled_contact(seed: int):
    """One planar frictional contact whose G couples the normal and the tangent."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((3, 3))
    return iq.ImpactProblem(A @ A.T / 3 + 0.2 * np.eye(3), rng.standard_normal((3, 2)),
                            np.zeros(3), contact_dim=2)


def test_no_restitution_never_gains_energy_and_restitution_may() -> None:
    p = coupled_contact(2)
    assert abs(p.delassus[0, 1]) > 0.1
    calm = iq.verify_law(iq.Coulomb(1.0, 0.0), p, samples=60)
    assert calm.violations["energetic"] == calm.violations["kinetic"] == 0
    lively = iq.verify_law(iq.Coulomb(1.0, 1.0), p, samples=60)
    assert lively.violations["energetic"] > 0 and lively.violations["kinetic"] == 0
    found = lively.counterexamples["energetic"]
    result = iq.solve(p.with_u_minus(found.u_minus), iq.Coulomb(1.0, 1.0))
    assert result.ok  # a certified answer of the law ...
    assert result.energy_after > result.energy_before * 1.01  # ... that gains energy
    assert not result.admissible and result.admissible.failed() == ["energetic"]


# --- bad input ------------------------------------------------------------------------------------

def test_bad_input_named_errors() -> None:
    M, W = np.eye(3), np.ones((3, 5))
    with pytest.raises(iq.errors.ShapeError, match="multiple of contact_dim"):
        iq.ImpactProblem(M, W, np.zeros(3), contact_dim=2)
    for d in (0, 4, 1.5, True):
        with pytest.raises(iq.InputError, match="contact_dim"):
            iq.ImpactProblem(M, np.ones((3, 6)), np.zeros(3), contact_dim=d)
    with pytest.raises(iq.InputError, match="mu"):
        iq.Coulomb(-0.1)
    with pytest.raises(iq.errors.NonFiniteError):
        iq.Coulomb(np.nan)
    with pytest.raises(iq.errors.RestitutionError):
        iq.Coulomb(0.1, 1.5)
    with pytest.raises(iq.errors.RestitutionError):
        iq.Coulomb(0.1, -0.5)
    with pytest.raises(iq.InputError, match="method"):
        iq.Coulomb(0.1, method="simplex")
    with pytest.raises(iq.InputError):
        iq.Coulomb([[0.1]])
    p = iq.friction.point_on_plane(1.0, [1.0, -1.0])
    with pytest.raises(iq.errors.ShapeError, match="mu"):
        iq.solve(p, iq.Coulomb([0.1, 0.2]))
    with pytest.raises(iq.errors.RestitutionError):
        iq.solve(p, iq.Coulomb(0.1, [0.1, 0.2]))
    with pytest.raises(iq.InputError, match="iq.Coulomb"):
        iq.solve(p, iq.Moreau(0.5))
    with pytest.raises(iq.InputError, match="iq.Coulomb"):
        iq.solve_batch(p, iq.Newton(0.5), [[1.0, -1.0]])
    frictionless = iq.ImpactProblem(np.eye(2), [[0.0], [1.0]], [1.0, -1.0])
    with pytest.raises(iq.InputError, match="contact_dim"):
        iq.solve(frictionless, iq.Coulomb(0.1))
    with pytest.raises(iq.InputError, match="mu"):
        p.admissible_set()
    with pytest.raises(iq.InputError, match="frictionless"):
        frictionless.admissible_set(mu=0.1)
    with pytest.raises(iq.InputError):
        p.admissible_set(mu=0.1).project([0.0, 0.0])
    with pytest.raises(iq.InputError, match="normal_problem"):
        iq.classify(p, iq.solve(p, iq.Coulomb(0.1)).u_plus)
    with pytest.raises(iq.InputError):
        iq.friction.sphere_on_plane(-1.0, 0.5, [1.0, -1.0, 0.0])
    with pytest.raises(iq.errors.ShapeError):
        iq.friction.sphere_on_plane(1.0, 0.5, [1.0, -1.0])
    with pytest.raises(iq.errors.ShapeError):
        iq.friction.two_spheres([1.0], [0.5, 0.5], np.zeros(6))
    with pytest.raises(iq.errors.NonFiniteError):
        iq.friction.point_on_plane(1.0, [np.nan, -1.0])


def test_problem_files_keep_the_friction(tmp_path) -> None:
    """A frictional problem reads back with its contact_dim (never silently frictionless);
    its normal problem is a frictionless file (more in tests/test_friction_files.py)."""
    p = iq.friction.point_on_plane(1.0, [1.0, -1.0])
    back = iq.load_problem(iq.save_problem(p, tmp_path / "p.json")).problem
    assert back.contact_dim == 2
    np.testing.assert_array_equal(back.W, p.W)
    iq.save_problem(p.normal_problem(), tmp_path / "n.json")
    normal = iq.load_problem(tmp_path / "n.json").problem
    assert normal.contact_dim == 1
    np.testing.assert_array_equal(normal.W, p.W[:, ::2])


def test_normal_problem_and_frictionless_default_unchanged() -> None:
    p = iq.friction.sphere_on_plane(1.0, 0.5, [1.0, -1.0, 0.0])
    normal = p.normal_problem()
    assert normal.contact_dim == 1 and normal.n_contacts == 1 == p.n_contacts
    assert p.n_impulses == 2 and normal.n_impulses == 1
    np.testing.assert_array_equal(normal.W, p.W[:, ::2])
    frictionless = iq.ImpactProblem(np.eye(2), [[0.0], [1.0]], [1.0, -1.0])
    assert frictionless.normal_problem() is frictionless
    assert frictionless.contact_dim == 1 and "contact_dim" not in repr(frictionless)
    np.testing.assert_allclose(p.moreau_split[0], normal.moreau_split[0])
