"""A law of one's own in a few lines: only a closed form, and iq.solve, iq.solve_batch and
verify_law take it with a certificate impactqp recomputes (momentum and Λ ≥ 0)."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq


class Sorted(iq.ImpactLaw):
    """u⁺ = sort(u⁻), returned alone: the impulses are recovered by impactqp."""

    def closed_form(self, problem):
        return np.sort(problem.u_minus)


class SortedWithImpulses(iq.ImpactLaw):
    name = "sorted-with-impulses"

    def closed_form(self, problem):
        r = iq.sector_law(problem)
        return r.u_plus, r.impulses


def test_a_closed_form_alone_is_a_complete_law():
    p = iq.newtons_cradle(3)
    r = iq.solve(p, Sorted())
    np.testing.assert_allclose(r.u_plus, [0.0, 0.0, 1.0])
    np.testing.assert_allclose(r.impulses, [1.0, 1.0])  # recovered: M(u⁺ − u⁻) = WΛ
    assert r.certificate.ok and set(r.certificate.residuals) == {"momentum", "impulse_sign"}
    assert r.law == "sorted" and r.backend == "closed form" and r.admissible.member
    assert Sorted.title == "Sorted" and SortedWithImpulses.name == "sorted-with-impulses"
    given = iq.solve(p, SortedWithImpulses())
    np.testing.assert_allclose(given.impulses, r.impulses, atol=1e-12)


def test_batches_run_a_closed_form_row_by_row():
    p = iq.newtons_cradle(4)
    U = np.random.default_rng(0).standard_normal((20, 4))
    b = iq.solve_batch(p, Sorted(), U)
    assert b.ok.all()
    for u, up, lam in zip(U, b.u_plus, b.impulses):
        one = iq.solve(p.with_u_minus(u), Sorted())
        np.testing.assert_allclose(up, one.u_plus)
        np.testing.assert_allclose(lam, one.impulses, atol=1e-12)


def test_a_closed_form_that_breaks_momentum_is_refused_in_batches_too():
    p = iq.chain([1.0, 2.0, 1.0], [1.0, 0.0, 0.0])  # sorting is not an impact law here
    with pytest.raises(iq.CertificateError, match="momentum"):
        iq.solve_batch(p, Sorted(), [[0.0, 1.0, 0.0]])  # Σ m u⁻ = 2, Σ m u⁺ = 1


def test_an_answer_no_compressive_impulse_produces_is_refused():
    class Backwards(iq.ImpactLaw):
        def closed_form(self, problem):
            return -problem.u_minus  # the balls pull each other: Λ < 0 would be needed

    with pytest.raises(iq.CertificateError, match="momentum"):
        iq.solve(iq.newtons_cradle(3), Backwards())


@pytest.mark.parametrize("output, word", [
    (lambda p: p.u_minus + 1j, "complex"),
    (lambda p: np.full(p.n_dof, np.nan), "finite"),
    (lambda p: np.zeros(p.n_dof + 1), "shape"),
    (lambda p: (p.u_minus, np.zeros(5)), "shape"),
    (lambda p: "fast", "number"),
])
def test_bad_output_of_a_law_is_named(output, word):
    class Broken(iq.ImpactLaw):
        def closed_form(self, problem):
            return output(problem)

    with pytest.raises(iq.InputError, match=word) as info:
        iq.solve(iq.newtons_cradle(3), Broken())
    assert "Broken" in str(info.value)


def test_verify_law_takes_the_short_law():
    report = iq.verify_law(lambda q: iq.solve(q, Sorted()), iq.newtons_cradle(3), samples=60,
                           seed=1)
    assert report.ok
