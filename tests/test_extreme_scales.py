"""iq.solve and classify at velocity scales whose norms and products leave the floats: the
laws of docs/theory.md are homogeneous, so they are answered in order-one units and scaled
back; an answer floats cannot hold is an OutOfRangeError, never a bare exception."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq

SCALES = [1e-310, 1e-300, 1e-200, 1e-160, 1e-120, 1e120, 1e154, 1e200, 1e300]
LAWS = [iq.Moreau(0.5), iq.Newton([0.3, 0.8]), iq.Fremond([[0.5, 0.1], [0.0, 0.5]]),
        iq.SectorLaw()]


@pytest.mark.parametrize("scale", SCALES)
@pytest.mark.parametrize("law", LAWS, ids=lambda law: law.name)
def test_laws_answer_at_every_representable_scale(scale, law):
    reference = iq.solve(iq.newtons_cradle(3), law)
    r = iq.solve(iq.newtons_cradle(3, v=scale), law)
    assert r.certificate.ok and np.isfinite(r.u_plus).all()
    rtol = 1e-12 if scale > 1e-300 else 1e-6  # subnormal inputs carry fewer digits
    np.testing.assert_allclose(r.u_plus / scale, reference.u_plus, rtol=rtol, atol=rtol)
    np.testing.assert_allclose(r.impulses / scale, reference.impulses, rtol=rtol, atol=rtol)
    assert r.attempts[0].startswith("solved in units of u⁻/")
    assert bool(r.admissible) == bool(reference.admissible)


@pytest.mark.parametrize("scale", SCALES)
def test_classify_and_moreau_split_at_every_scale(scale):
    p1, p = iq.newtons_cradle(3), iq.newtons_cradle(3, v=scale)
    c1, c = iq.classify(p1, [0, 0, 1.0]), iq.classify(p, [0, 0, scale])
    assert c.alpha_deg == pytest.approx(c1.alpha_deg, abs=1e-9)
    assert c.dissipation == pytest.approx(c1.dissipation, abs=1e-9)
    assert c.intensity / scale == pytest.approx(c1.intensity, rel=1e-6)
    np.testing.assert_allclose(p.moreau_split[0] / scale, p1.moreau_split[0], rtol=1e-6)


def test_tiny_masses_and_huge_velocities_classify_finitely():
    p = iq.ImpactProblem(np.eye(2) * 1e-300, [[-1.0], [1.0]], [1e300, 0.0])
    c = iq.classify(p, [0.0, 1e300])  # Λ = 1 while ‖Λ‖² of the unit problem underflows
    np.testing.assert_allclose(c.topology, [1.0])
    assert c.alpha_deg < 1e-9 and c.dissipation == pytest.approx(1.0)


def test_an_answer_beyond_the_floats_is_named():
    with pytest.raises(iq.OutOfRangeError, match="overflows floats"):
        iq.moreau(iq.newtons_cradle(3, v=1.7e308), 1.0)  # u⁺ fits, Λ = 1.7e308·4/3 does not


def test_an_answer_among_the_subnormals_is_accurate_or_named():
    """Hit at 1e-320 the cradle's answer (−1/3, 2/3, 2/3)·v lands where floats are spaced
    4.9e-324 apart, 5e-4 of it: refused by name, not returned as a success; at 1e-312 the
    spacing is 7e-12 of it and the answer is returned to that."""
    with pytest.raises(iq.OutOfRangeError, match="subnormal"):
        iq.moreau(iq.newtons_cradle(3, 1e-320), 1.0)
    r = iq.moreau(iq.newtons_cradle(3, 1e-312), 1.0)
    np.testing.assert_allclose(r.u_plus / 1e-312, [-1 / 3, 2 / 3, 2 / 3], rtol=1e-10)


@pytest.mark.parametrize("make", [
    lambda: iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0]).admissible_set(mu=0.3).contains(
        [1e200, 0.0, 0.0]),
    lambda: iq.newtons_cradle(3, 1e-200).admissible_set().contains([0.0, 0.0, 1e16]),
    lambda: iq.newtons_cradle(3, 1.0).admissible_set().contains([0.0, 0.0, 1e300]),
])
def test_a_point_far_outside_s_is_simply_not_in_it(make):
    membership = make()  # was a bare OverflowError (‖u‖²/‖u⁻‖² beyond the floats)
    assert not membership.member and membership.energetic == np.inf
