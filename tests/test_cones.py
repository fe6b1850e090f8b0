"""Cone programs in the solver layer: Clarabel and cvxpy agree with each other and with closed
forms, every answer passes the certificate impactqp recomputes, the backends that take no cones
refuse by name, and bad cone specifications are named errors (docs/theory.md §9)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import impactqp as iq
from impactqp.kernels.friction import project_cones
from impactqp.qp import backends
from impactqp.qp.cone_solve import solve_cone
from impactqp.qp.cones import Cone, ConeProgram, friction_cone_rows

CONE_BACKENDS = ("clarabel", "cvxpy", "cvxpy:CLARABEL", "cvxpy:SCS")


def mixed_program(seed: int, sparse: bool = False) -> ConeProgram:
    """A strictly feasible, strongly convex program over every kind of cone: a zero cone,
    orthants, second-order cones of sizes 1, 3 and 4 (x₀ is a strictly feasible point)."""
    rng = np.random.default_rng(seed)
    n = 7
    cones = [Cone("zero", 2), Cone("nonnegative", 3), Cone("soc", 3), Cone("soc", 4),
             Cone("soc", 1), Cone("soc", 3), Cone("nonnegative", 1)]
    s0 = np.concatenate([[0.0, 0.0], [1.0, 0.2, 0.5], [2.0, 0.3, 0.1], [3.0, 0.5, -0.2, 1.0],
                         [1.0], [1.5, -0.4, 0.9], [0.5]])
    A = rng.standard_normal((s0.size, n))
    B = rng.standard_normal((n, n))
    P = B.T @ B + 0.1 * np.eye(n)
    b = A @ rng.standard_normal(n) + s0
    c = 3.0 * rng.standard_normal(n)
    if sparse:
        return ConeProgram(sp.csc_matrix(P), c, sp.csc_matrix(A), b, cones)
    return ConeProgram(P, c, A, b, cones)


def soc_projection(p: np.ndarray) -> ConeProgram:
    """min ½‖x − p‖² over the second-order cone: A = −I, b = 0, so s = x."""
    k = p.size
    return ConeProgram(np.eye(k), -p, -np.eye(k), np.zeros(k), [Cone("soc", k)])


@pytest.mark.parametrize("sparse", [False, True])
@pytest.mark.parametrize("seed", range(3))
def test_clarabel_and_cvxpy_agree_with_a_recomputed_certificate(seed: int, sparse: bool) -> None:
    program = mixed_program(seed, sparse)
    ref = solve_cone(program, "clarabel")
    assert ref.backend == "clarabel" and ref.checks.ok and ref.iterations > 0
    # the solution is unique (P ≻ 0) and so are its multipliers (strict feasibility and
    # active rows that vary with the seed); the certificate is ours, not the solver's
    assert set(ref.checks.residuals) == {"primal", "dual", "stationarity", "complementarity",
                                         "gap"}
    for name in CONE_BACKENDS[1:]:
        sol = solve_cone(program, name)
        assert sol.backend.startswith("cvxpy:") and sol.checks.ok, (name, sol.checks)
        np.testing.assert_allclose(sol.x, ref.x, atol=1e-6, err_msg=name)
        np.testing.assert_allclose(sol.z, ref.z, atol=1e-5, err_msg=name)
        # the certificate recomputed at the tighter of the two answers passes for both
        assert program.certificate(sol.x, sol.z, 1e-6).ok
    # something is actually constrained: some multipliers of the cones are non-zero
    assert np.abs(ref.z).max() > 1e-3


@pytest.mark.parametrize("backend", ["clarabel", "cvxpy", "cvxpy:ECOS", "auto"])
@pytest.mark.parametrize("point", [(0.5, 2.0, -1.0), (3.0, 1.0, 1.0), (-3.0, 1.0, 1.0),
                                   (0.0, 0.3, 0.4, 1.2), (-1.0, 0.2, 0.0)])
def test_projection_onto_a_second_order_cone_matches_its_closed_form(backend: str,
                                                                     point: tuple) -> None:
    p = np.array(point)
    k = p.size
    # ECOS sees the quadratic objective through cvxpy's conic rewriting and stops near 1e-6
    accept, close = (1e-5, 1e-4) if backend == "cvxpy:ECOS" else (1e-8, 1e-6)
    sol = solve_cone(soc_projection(p), backend, accept=accept)
    expected = project_cones(p, np.ones(1), k)  # the one closed form of the projection
    np.testing.assert_allclose(sol.x, expected, atol=close)
    # by hand, for the first point: ((x_n + ‖x_T‖)/2)·(1, x_T/‖x_T‖) with ‖x_T‖ = √5
    if point == (0.5, 2.0, -1.0):
        a = (0.5 + np.sqrt(5.0)) / 2.0
        np.testing.assert_allclose(sol.x, [a, a * 2 / np.sqrt(5), -a / np.sqrt(5)], atol=close)
    # Moreau's decomposition: p = P_K(p) − z with z ∈ K (the multiplier), z ⟂ P_K(p)
    np.testing.assert_allclose(sol.x - sol.z, p, atol=close)
    assert abs(sol.x @ sol.z) <= close


def test_linear_objective_and_zero_sized_cones() -> None:
    # min −x₁ subject to ‖(x₁, x₂)‖ ≤ 2 (s = (2, x₁, x₂)) and x₂ = 1 (a zero cone), with an
    # empty orthant listed first: x = (√3, 1)
    A = np.array([[0.0, 0.0], [-1.0, 0.0], [0.0, -1.0], [0.0, 1.0]])
    program = ConeProgram(None, [-1.0, 0.0], A, [2.0, 0.0, 0.0, 1.0],
                          [Cone("nonnegative", 0), Cone("soc", 3), Cone("zero", 1)])
    for backend in ("clarabel", "cvxpy"):
        sol = solve_cone(program, backend)
        np.testing.assert_allclose(sol.x, [np.sqrt(3.0), 1.0], atol=1e-7)


@pytest.mark.parametrize("name", [b.name for b in backends.REGISTRY.values()
                                  if b.name not in ("clarabel", "cvxpy")])
def test_every_other_backend_refuses_cones_by_name(name: str) -> None:
    program = soc_projection(np.array([1.0, 2.0, 0.0]))
    with pytest.raises(iq.BackendUnsuitableError,
                       match=f"'{name}' does not solve cone programs.*'clarabel', 'cvxpy'"):
        solve_cone(program, name)


def test_the_registry_lists_the_cone_form() -> None:
    listed = {b["name"]: b["forms"] for b in iq.available_backends()}
    assert {name for name, forms in listed.items() if "cone" in forms} == {"clarabel", "cvxpy"}
    assert backends.cone_backends() == ("clarabel", "cvxpy")
    with pytest.raises(iq.errors.UnknownBackendError, match="not installed"):
        solve_cone(soc_projection(np.ones(3)), "cvxpy:NOSUCHSOLVER")


def test_an_answer_that_fails_its_certificate_is_an_error(monkeypatch) -> None:
    from impactqp.qp.backends import clarabel_
    real = clarabel_.solve_cone

    def corrupted(program, **kwargs):
        sol = real(program, **kwargs)
        return type(sol)(sol.x + 1e-3, sol.z, sol.s, sol.status, sol.backend, sol.iterations)

    monkeypatch.setattr(clarabel_, "solve_cone", corrupted)
    with pytest.raises(iq.CertificateError, match="clarabel.*certificate failed"):
        solve_cone(mixed_program(0), "clarabel")
    # the certificate itself sees each kind of violation
    program = soc_projection(np.array([0.5, 2.0, -1.0]))
    good = solve_cone(program, "cvxpy")
    assert program.certificate(good.x, good.z, 1e-8).ok
    outside = program.certificate(np.array([1.0, 2.0, 0.0]), good.z, 1e-8)
    assert outside.residuals["primal"] > 1e-2 and not outside.ok
    wrong_dual = program.certificate(good.x, -good.z, 1e-8)
    assert wrong_dual.residuals["dual"] > 1e-2


BAD = [
    (dict(cones=[Cone("soc", 2)]), iq.errors.ShapeError, "add up to 2 rows but A has 3"),
    (dict(cones=[Cone("soc", 0), Cone("soc", 3)]), iq.InputError, "size of cone 0.*≥ 1"),
    (dict(cones=[Cone("cone", 3)]), iq.InputError, "kind 'cone'"),
    (dict(cones=[("soc", 1.5), ("soc", 1.5)]), iq.InputError, "whole number"),
    (dict(cones=[Cone("nonnegative", -1), Cone("soc", 4)]), iq.InputError, "≥ 0"),
    (dict(cones="soc"), iq.InputError, "sequence of"),
    (dict(cones=[3]), iq.InputError, "pair"),
    (dict(c=[np.nan, 0.0, 0.0]), iq.errors.NonFiniteError, "c must be finite"),
    (dict(b=[0.0, np.inf, 0.0]), iq.errors.NonFiniteError, "b must be finite"),
    (dict(A=sp.csc_matrix([[np.nan, 0, 0], [0, 1, 0], [0, 0, 1]])), iq.errors.NonFiniteError,
     "A must be finite"),
    (dict(P=[[1.0, 2.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]), iq.InputError,
     "symmetric"),
    (dict(P=np.eye(2)), iq.errors.ShapeError, "P must be 3 × 3"),
    (dict(b=[0.0, 0.0]), iq.errors.ShapeError, "b must have 3 entries"),
    (dict(A=np.eye(3)[:, :2]), iq.errors.ShapeError, "A must have 3 columns"),
]


@pytest.mark.parametrize("change,error,words", BAD)
def test_bad_cone_programs_are_named_errors(change: dict, error: type, words: str) -> None:
    data = dict(P=np.eye(3), c=np.zeros(3), A=-np.eye(3), b=np.zeros(3),
                cones=[Cone("soc", 3)])
    data.update(change)
    with pytest.raises(error, match=words):
        ConeProgram(**data)


def test_solve_cone_checks_its_arguments() -> None:
    program = soc_projection(np.ones(3))
    with pytest.raises(iq.InputError, match="ConeProgram"):
        solve_cone("not a program")
    with pytest.raises(iq.InputError, match="tol"):
        solve_cone(program, tol=0.0)
    with pytest.raises(iq.errors.UnknownBackendError, match="unknown backend"):
        solve_cone(program, "mosek")
    with pytest.raises(iq.InputError, match="clarabel has no setting"):
        solve_cone(program, "clarabel", options={"no_such_setting": 1})


def test_the_admissible_sets_socp_is_a_certified_cone_program(monkeypatch) -> None:
    from impactqp.model import admissible
    seen = []

    def spy(program, backend="clarabel", **kwargs):
        sol = solve_cone(program, backend, **kwargs)
        seen.append((program.cones, sol.checks))
        return sol

    monkeypatch.setattr(admissible, "solve_cone", spy)
    p = iq.newtons_cradle(3)
    S = p.admissible_set()
    y = S.project([0.2, -0.1, 0.4])
    assert S.contains(y, tol=1e-7)
    assert [c.kind for c in seen[-1][0]] == ["zero", "nonnegative", "soc", "soc"]
    assert seen[-1][1].ok
    # support: the cvxpy form of S (another solver, another formulation) gives the same value
    c = np.array([1.0, -2.0, 0.5])
    value, u = S.support(c)
    import cvxpy as cp
    v = cp.Variable(3)
    cp.Problem(cp.Maximize(c @ v), S.constraints(v)).solve(solver="ECOS")
    assert abs(value - c @ v.value) <= 1e-5 and S.contains(u, tol=1e-7)


def test_admissible_set_without_an_approaching_contact_is_one_point() -> None:
    # two balls already separating (γ⁻ > 0): S = {u⁻}, answered exactly, no SOCP needed
    p = iq.ImpactProblem(np.diag([1.0, 2.0]), [[-1.0], [1.0]], [-0.5, 0.25])
    assert p.gamma_minus[0] > 0
    S = p.admissible_set()
    u = np.array([0.3, 0.1])
    m = S.contains(u, method="optimizer")
    exact = p.norm(u - p.u_minus) / p.norm(p.u_minus)
    assert not m and m.distance == pytest.approx(exact, rel=1e-12)
    np.testing.assert_array_equal(S.project(u), p.u_minus)
    assert S.contains(p.u_minus, method="optimizer") and S.contains(p.u_minus)
    assert S.support([1.0, 1.0])[0] == pytest.approx(-0.25, rel=1e-12)


@pytest.mark.parametrize("d", [2, 3])
def test_friction_cone_rows_hold_exactly_the_coulomb_cones(d):
    # C r ∈ K (checked cone by cone) exactly when r is its own projection onto the Coulomb
    # cones (the closed form of the kernel layer), for rough and frictionless contacts
    rng = np.random.default_rng(d)
    mu = np.array([0.0, 0.4, 0.0, 1.5, 0.7])
    C, cones = friction_cone_rows(mu, d)
    assert C.shape == (2 * d + 3 * d, mu.size * d)
    assert [c.kind for c in cones] == ["nonnegative", "zero", "soc", "soc", "soc"]
    for _ in range(200):
        r = rng.standard_normal(mu.size * d)
        if rng.random() < 0.5:
            r = project_cones(r, mu, d)
        s, k, inside = C @ r, 0, True
        for cone in cones:
            block = s[k:k + cone.size]
            inside &= {"nonnegative": bool((block >= -1e-12).all()),
                       "zero": bool((np.abs(block) <= 1e-12).all()),
                       "soc": bool(np.linalg.norm(block[1:]) <= block[0] + 1e-12)}[cone.kind]
            k += cone.size
        assert inside == bool(np.allclose(project_cones(r, mu, d), r, atol=1e-12))
