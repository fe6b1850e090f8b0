"""Friction inside the backend registry (issue 25): the friction methods are registry entries
that ``available_backends()`` lists, ``backend=`` means one thing for ``solve_friction``,
``iq.solve`` with Coulomb's law and the command line, every name a result reports is one the
caller can pass back, and Coulomb's law is solved through the registry and certified once
(docs/theory.md §9, §15, §16)."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.laws.friction import FRICTION_BACKENDS
from impactqp.model.friction import certify_friction
from impactqp.qp import backends
from impactqp.qp.certified import plan, solve_certified

METHODS = [b for b in FRICTION_BACKENDS if b != "auto"]


def random_problem(m: int, mu: float, seed: int) -> iq.FrictionContactProblem:
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((3 * m, 3 * m))
    return iq.FrictionContactProblem(A.T @ A / (3 * m) + 1e-2 * np.eye(3 * m),
                                     rng.standard_normal(3 * m), mu)


def sphere(mu_velocity=(1.0, -2.0, 0.0)) -> iq.ImpactProblem:
    return iq.friction.sphere_on_plane(1.0, 0.1, list(mu_velocity))


def test_available_backends_lists_the_friction_methods() -> None:
    listed = {b["name"] for b in iq.available_backends() if "friction" in b["forms"]}
    assert listed == set(METHODS) == {"kernel", "clarabel", "nsgs-short", "newton",
                                      "newton-damped", "newton-repair", "newton-lstsq",
                                      "nsgs"}
    assert set(backends.AUTO_ORDER["friction"]) == listed
    coulomb = {b["name"]: b["laws"]["coulomb"] for b in iq.available_backends()}
    assert {name for name, forms in coulomb.items() if forms} == listed


@pytest.mark.parametrize("backend", FRICTION_BACKENDS)
def test_every_reported_name_is_accepted_back(backend: str) -> None:
    """Each method named, and auto: the result's backend is a registry name, and passing it
    back solves the problem again to the same velocity (two methods where auto chose)."""
    problem = random_problem(4, 0.4, seed=3)
    first = iq.solve_friction(problem, backend=backend)
    assert first.backend in METHODS
    if backend != "auto":
        assert first.backend == backend
    again = iq.solve_friction(problem, backend=first.backend)
    assert again.backend == first.backend and again.certificate.ok
    np.testing.assert_allclose(again.u, first.u, atol=1e-6 * np.linalg.norm(problem.q))


def test_reported_qp_and_cone_names_are_accepted_back() -> None:
    """Polished QP answers report the backend alone (the polish is in ``attempts``)."""
    p = iq.newtons_cradle(2000)
    r = iq.moreau(p, 0.0, backend="clarabel")
    assert r.backend == "clarabel" and any("polished" in a for a in r.attempts)
    backends.parse_backend(r.backend)
    np.testing.assert_allclose(iq.moreau(p, 0.0, backend=r.backend).u_plus, r.u_plus,
                               atol=1e-9)
    for name in ("auto", "kernel", "isotonic"):
        backends.parse_backend(iq.moreau(iq.newtons_cradle(3), 1.0, backend=name).backend)


def test_coulomb_reports_the_friction_method_and_takes_backend() -> None:
    p = sphere()
    auto = iq.solve(p, iq.Coulomb(0.3, 0.5))
    assert auto.backend in METHODS and auto.attempts[-1].startswith(auto.backend)
    for method in ("newton", "clarabel", "nsgs"):
        named = iq.solve(p, iq.Coulomb(0.3, 0.5), backend=method)
        assert named.backend == method and named.certificate.ok
        np.testing.assert_allclose(named.u_plus, auto.u_plus, atol=1e-7)
        by_law = iq.solve(p, iq.Coulomb(0.3, 0.5, method=method))  # the law's default
        assert by_law.backend == method
    with pytest.raises(iq.BackendUnsuitableError, match="frictional contact problems"):
        iq.solve(p, iq.Coulomb(0.3), backend="osqp")
    with pytest.raises(iq.errors.UnknownBackendError):
        iq.solve(p, iq.Coulomb(0.3), backend="nope")
    with pytest.raises(iq.InputError, match="method"):
        iq.Coulomb(0.3, method="osqp")


def test_coulomb_agrees_with_solve_friction_on_its_local_problem() -> None:
    """Two ways: iq.solve's Λ against solve_friction's r on the law's local problem (r = sΛ),
    and u⁺ against u⁻ + M⁻¹WΛ recomputed from the problem's matrices."""
    rng = np.random.default_rng(7)
    for seed in range(4):
        p = iq.friction.sphere_on_plane(1.0, 0.1, rng.uniform(-2, 2, 6) - [0, 0, 3, 0, 0, 0])
        law = iq.Coulomb(0.4, 0.2)
        res = iq.solve(p, law)
        local, units = law.local_problem(p)
        ref = iq.solve_friction(local, backend="clarabel")
        np.testing.assert_allclose(res.impulses * units, ref.r, atol=1e-6 * np.abs(ref.r).max())
        M, W = p.structure.dense_mass, np.asarray(p.W.toarray() if hasattr(p.W, "toarray")
                                                  else p.W)
        np.testing.assert_allclose(res.u_plus, p.u_minus + np.linalg.solve(M, W @ res.impulses),
                                   atol=1e-9 * np.abs(p.u_minus).max(), err_msg=str(seed))


def test_coulomb_is_certified_once(monkeypatch) -> None:
    """The local problem is certified once per solve (by the law's certificate: its compiled
    pass, or the reference's certify_friction where that does not apply), not by
    solve_friction and then again."""
    from impactqp.laws import coulomb
    calls = []
    for name in ("certify_friction", "coulomb_residuals"):
        real = getattr(coulomb, name)
        monkeypatch.setattr(coulomb, name, lambda *a, real=real, name=name, **k:
                            calls.append(name) or real(*a, **k))
    iq.solve(sphere(), iq.Coulomb(0.3))
    assert calls == ["coulomb_residuals"]
    calls.clear()
    big = sphere()
    iq.solve(big.with_u_minus(big.u_minus * 1e200), iq.Coulomb(0.3))  # rescaled first
    assert calls == ["coulomb_residuals"]


def test_friction_result_is_of_the_result_family() -> None:
    res = iq.solve_friction(random_problem(3, 0.5, seed=1))
    impact = iq.moreau(iq.newtons_cradle(3), 1.0)
    for r in (res, impact):
        assert r.success and r.ok and r.status == "solved" and r.solve_time > 0
        assert r.attempts and r.backend in r.message
    text = repr(res)
    assert "FrictionResult" in text and "9" in text and len(text) < 200
    assert str(res.r[0]) not in text  # sizes and verdict, not every number
    assert res.error == res.certificate.error and res.iterations >= 1


def test_one_loop_serves_quadratic_cone_and_friction_programs() -> None:
    """solve_certified on a friction plan records each attempt and returns a method's name;
    a named method that fails is reported by name."""
    problem = random_problem(3, 0.5, seed=2)

    def finish(sol):
        return sol, certify_friction(problem, sol.r)

    out = solve_certified(plan("friction", problem, finish, "auto"), named=False, tol=1e-8)
    assert out.backend in METHODS and out.form == "friction" and out.checks.ok
    impossible = iq.FrictionContactProblem(np.zeros((3, 3)), [-1.0, 0.0, 0.0], 0.5)
    with pytest.raises(iq.CertificateError, match=r"nsgs \(friction, tol 1e-08\)"):
        iq.solve_friction(impossible, backend="nsgs")
    with pytest.raises(iq.BackendUnsuitableError, match="at most 32 contacts"):
        iq.solve_friction(random_problem(40, 0.5, seed=0), backend="kernel")
