"""Coulomb's certificate in one compiled pass (impactqp.kernels.coulomb_certificate) against
its numpy reference (``Coulomb.reference_residuals``, docs/theory.md §8, §16): the same
residuals on random frictional impacts, the same verdict on corrupted answers, and the
reference where the compiled pass does not apply."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import impactqp as iq
from impactqp.laws.base import Answer
from impactqp.laws.certificate import Certificate

TOL = 1e-8


def random_impact(rng: np.random.Generator, d: int, contacts: int, sparse: bool = False
                  ) -> iq.ImpactProblem:
    """A random frictional impact with independent columns (a solution exists), u⁻ pushing
    into the contacts."""
    n = d * contacts + int(rng.integers(0, 3))
    A = rng.normal(size=(n, n))
    M = A @ A.T + n * np.eye(n) * 10.0 ** rng.uniform(-2, 2)
    W = rng.normal(size=(n, d * contacts)) * 10.0 ** rng.uniform(-3, 3)
    push = W[:, ::d] @ np.abs(rng.normal(size=contacts))  # into the normals, mostly
    u = (0.3 * rng.normal(size=n) - push / np.linalg.norm(push)) * 10.0 ** rng.uniform(-4, 4)
    if sparse:
        M, W = sp.csc_matrix(M), sp.csc_matrix(W)
    return iq.ImpactProblem(M, W, u, contact_dim=d)


def both(law: iq.Coulomb, problem: iq.ImpactProblem, answer: Answer
         ) -> tuple[dict[str, float], dict[str, float]]:
    """(compiled, reference) residuals of ``answer``; the compiled pass must apply."""
    st = problem.structure
    compiled = law._compiled_residuals(st, problem.u_minus, answer.u_plus, answer.impulses)
    assert compiled is not None
    reference = law.reference_residuals(st, problem.u_minus, answer.u_plus, answer.impulses)
    np.testing.assert_equal(law.residuals(st, problem.u_minus, answer.u_plus, answer.impulses),
                            compiled)  # residuals() is the compiled pass here
    return compiled, {k: float(v) for k, v in reference.items()}


def agree(compiled: dict[str, float], reference: dict[str, float]) -> None:
    """The same names; each value equal to rounding: relative 1e-9, or both below 1e-12 —
    1e-10 for the momentum, which the compiled pass measures with an M⁻¹W of its own (LU,
    not the structure's Cholesky factor), still 100 times below the tolerance."""
    assert list(compiled) == list(reference)
    for name, value in compiled.items():
        ref = reference[name]
        floor = 1e-10 if name == "momentum" else 1e-12
        assert value == pytest.approx(ref, rel=1e-9, abs=floor), name


def corruptions(rng: np.random.Generator, problem: iq.ImpactProblem, answer: Answer, d: int
                ) -> list[tuple[str, Answer]]:
    """Wrong answers: u⁺ off the impact equation, a tangential impulse outside its cone (u⁺
    moved with it), a normal impulse made negative, the impulses halved, a NaN."""
    st = problem.structure
    scale = np.abs(answer.impulses).max()
    lam = answer.impulses
    moved = problem.u_minus + st.impulse_velocity(lam * 0.5)
    out_of_cone = lam.copy()
    out_of_cone[1] += 5.0 * scale + 1.0
    pulled = lam.copy()
    pulled[0] = -abs(pulled[0]) - scale - 1.0
    nan = answer.u_plus.copy()
    nan[0] = np.nan
    kick = rng.normal(size=answer.u_plus.size)
    return [
        ("momentum", Answer(answer.u_plus + 1e-3 * np.abs(answer.u_plus).max() * kick,
                            lam, None)),
        ("cone", Answer(problem.u_minus + st.impulse_velocity(out_of_cone), out_of_cone,
                        None)),
        ("pulled", Answer(problem.u_minus + st.impulse_velocity(pulled), pulled, None)),
        ("halved", Answer(moved, lam * 0.5, None)),
        ("nan", Answer(nan, lam, None)),
    ]


@pytest.mark.parametrize("d", [2, 3])
def test_compiled_and_reference_residuals_agree_on_random_impacts(d: int) -> None:
    rng = np.random.default_rng(25 + d)
    checked = refused = 0
    for trial in range(12):
        problem = random_impact(rng, d, int(rng.integers(1, 5)))
        mu = rng.uniform(0.0, 1.0, size=problem.n_contacts) if trial % 2 else 0.3
        law = iq.Coulomb(mu, float(rng.uniform(0.0, 1.0)))
        try:
            result = iq.solve(problem, law)
        except iq.CertificateError:
            continue  # not every random impact is certified; the rest must agree
        if not result.impulses.any():
            continue  # separating: halving Λ = 0 changes nothing
        answer = Answer(result.u_plus, result.impulses, None)
        compiled, reference = both(law, problem, answer)
        agree(compiled, reference)
        assert Certificate(compiled, TOL).ok and Certificate(reference, TOL).ok
        checked += 1
        for label, wrong in corruptions(rng, problem, answer, d):
            bad, bad_ref = both(law, problem, wrong)
            if label != "nan":
                agree(bad, bad_ref)
            assert not Certificate(bad, TOL).ok, label
            assert not Certificate(bad_ref, TOL).ok, label
            refused += 1
    assert checked >= 8 and refused == 5 * checked


def test_the_solve_is_judged_by_the_compiled_pass() -> None:
    """iq.solve's certificate holds the compiled pass's values (the reference agrees)."""
    problem = iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0])
    law = iq.Coulomb(0.3, 0.5)
    result = iq.solve(problem, law)
    answer = Answer(result.u_plus, result.impulses, None)
    compiled, reference = both(law, problem, answer)
    assert dict(result.certificate.residuals) == pytest.approx(compiled, abs=0.0)
    agree(compiled, reference)


def test_the_reference_answers_where_the_compiled_pass_does_not_apply() -> None:
    """Sparse structures, velocities beyond the range of squares and answers that are not
    float64 vectors are judged by the reference computation, to the same verdict."""
    rng = np.random.default_rng(7)
    problem = random_impact(rng, 3, 2, sparse=True)
    law = iq.Coulomb(0.4)
    result = iq.solve(problem, law)
    st = problem.structure
    assert law._compiled_residuals(st, problem.u_minus, result.u_plus, result.impulses) is None
    assert result.ok

    sphere = iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0])
    huge = sphere.with_u_minus(sphere.u_minus * 1e200)
    law = iq.Coulomb(0.3)
    result = iq.solve(huge, law)
    st = huge.structure
    assert law._compiled_residuals(st, huge.u_minus, result.u_plus, result.impulses) is None
    assert law.certificate(huge, Answer(result.u_plus, result.impulses, None), TOL).ok
    wrong = result.impulses.copy()
    wrong[1] = 10.0 * abs(wrong[0]) + 1e200
    assert not law.certificate(huge, Answer(result.u_plus, wrong, None), TOL).ok

    small = iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0])
    result = iq.solve(small, law)
    single = result.impulses.astype(np.float32)  # not float64: the reference judges it
    assert law._compiled_residuals(small.structure, small.u_minus, result.u_plus,
                                   single) is None
    as_single = law.residuals(small.structure, small.u_minus, result.u_plus, single)
    assert Certificate(as_single, 1e-6).ok
    assert not Certificate(law.residuals(small.structure, small.u_minus, result.u_plus,
                                         single * 2), 1e-6).ok
