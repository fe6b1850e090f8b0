"""Physical invariants of Moreau's law over random impacts (hypothesis)."""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import impactqp as iq


@st.composite
def impacts(draw, consistent=None):
    n = draw(st.integers(2, 7))
    m = draw(st.integers(1, 8))
    seed = draw(st.integers(0, 2**31 - 1))
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    M = A @ A.T + draw(st.floats(0.05, 2.0)) * np.eye(n)
    W = rng.standard_normal((n, m))
    redundant = draw(st.integers(0, m - 1))
    for j in range(m - redundant, m):  # duplicated and dependent columns
        W[:, j] = W[:, rng.integers(m - redundant)] if rng.random() < 0.5 else \
            W[:, : m - redundant] @ rng.random(m - redundant)
    u = rng.standard_normal(n) * draw(st.sampled_from([1e-3, 1.0, 1e3]))
    if consistent:
        # at most n independent contacts, so that T_C has interior and u⁻ ≠ 0
        redundant = max(redundant, m - n)
        return iq.random_impact(n, m, seed=seed, redundant=redundant, consistent=True)
    return iq.ImpactProblem(M, W, u)


common = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@common
@given(impacts(), st.floats(0.0, 1.0))
def test_moreau_invariants(p, eps):
    r = iq.moreau(p, eps)
    V = p.velocity_scale
    # momentum balance M(u⁺ − u⁻) = WΛ and Λ ≥ 0
    assert np.linalg.norm(p.M @ (r.u_plus - p.u_minus) - p.W @ r.impulses) <= 1e-8 * V * \
        max(1.0, np.linalg.norm(p.M))
    assert np.all(r.impulses >= 0)
    # complementarity with γ⁺ + εγ⁻ ≥ 0
    w = p.W.T @ r.u_plus + eps * p.gamma_minus
    s = np.sqrt(np.diag(p.delassus))
    assert np.all(w >= -1e-8 * s * V)
    assert np.all(np.abs(r.impulses * w) <= 1e-8 * V**2)
    # z is the M-projection: ⟨z, z⊥⟩ = 0, and energy never grows
    assert abs(p.inner(r.z, r.z_perp)) <= 1e-8 * V**2
    assert r.energy_after <= r.energy_before * (1 + 1e-9) + 1e-12
    # velocity form and impulse form agree
    r2 = iq.moreau(p, eps, form="velocity")
    assert p.norm(r2.u_plus - r.u_plus) <= 1e-7 * V


@common
@given(impacts(consistent=True), st.floats(0.0, 1.0))
def test_moreau_stays_in_S_for_consistent_velocities(p, eps):
    r = iq.moreau(p, eps)
    m = p.admissible_set().contains(r.u_plus, tol=1e-8)
    assert m, m


@common
@given(impacts(), st.floats(0.0, 1.0))
def test_z_is_always_in_S(p, eps):
    z = iq.moreau(p, 0.0).u_plus
    assert p.admissible_set().contains(z, tol=1e-8)
    # classification of Moreau points: α = 0, dissipation = ε (when there is an impact)
    r = iq.moreau(p, eps)
    c = r.classification
    # dissipation is √(⟨u⁺ − z, u⁺ + z⟩/‖z⊥‖²): a round-off δ ≈ 1e-16·V of u⁺ moves it by
    # up to √(2δV)/‖z⊥‖ ≈ 1.5e-8·V/‖z⊥‖ near ε = 0 (the square root's slope is infinite
    # there), so the check allows that beside 1e-6 on every impact
    zp = p.norm(r.z_perp) / p.velocity_scale
    if zp > 1e-3:
        assert c.alpha_deg < 1e-3
    if zp > 0 and c.intensity > 0:  # an impact (without one, the dissipation is NaN)
        assert abs(c.dissipation - eps) < 1e-6 + 1e-7 / zp


def test_inconsistent_velocity_moreau_can_leave_S_and_says_so():
    # ball 2 already separating from ball 1 (γ⁻₁ = 1 > 0) and hitting ball 3 (γ⁻₂ = −1.8):
    # z pools balls 2, 3 at 0.1, and the elastic rebound sends ball 2 back through ball 1
    p = iq.chain([1.0, 1.0, 1.0], [0.0, 1.0, -0.8])
    assert p.gamma_minus[0] > 0
    np.testing.assert_allclose(iq.moreau(p, 1.0).u_plus, [0.0, -0.8, 1.0], atol=1e-12)
    r = iq.moreau(p, 1.0)
    assert r.certificate.ok  # the law was solved correctly ...
    verdict = r.admissible   # ... but its answer penetrates contact 1
    assert not verdict and "kinematic" in verdict.failed()
    assert iq.moreau(p, 0.0).admissible  # z itself is always admissible
