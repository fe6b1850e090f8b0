"""Local frictional contact problems: closed forms, random problems solved by two methods,
the certificate's verdicts on corrupted answers, the cone projection against its variational
characterization, and bad inputs as named errors (docs/theory.md §15)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import impactqp as iq
from impactqp.kernels.friction import (
    alart_curnier,
    local_steps,
    modified_velocity,
    natural_map,
    nsgs_rows,
    project_cones,
)
from impactqp.kernels.friction_jacobians import modified_velocity_jacobian, projection_jacobian
from impactqp.kernels.friction_newton import lu_solve, scales, solve_small
from impactqp.model.friction import certify_friction
from impactqp.qp.friction import methods as friction_methods
from impactqp.qp.friction import newton as friction_newton

BACKENDS = ("auto", "newton", "clarabel", "nsgs")


def random_problem(m: int, d: int, mu: float, seed: int, skew: float = 0.0):
    """W = AᵀA/n + 0.01 I (plus a skew part), q standard normal."""
    rng = np.random.default_rng(seed)
    n = m * d
    A = rng.standard_normal((n, n))
    W = A.T @ A / n + 1e-2 * np.eye(n)
    if skew:
        S = rng.standard_normal((n, n))
        W = W + skew * (S - S.T)
    return iq.FrictionContactProblem(W, rng.standard_normal(n), mu, contact_dim=d)


# --- closed forms -----------------------------------------------------------------------------

CLOSED = [  # (W diagonal, q, mu, r, u)
    ((1, 1, 1), (-1.0, 0.3, -0.2), 0.0, (1.0, 0.0, 0.0), (0.0, 0.3, -0.2)),  # frictionless
    ((1, 1, 1), (2.0, 0.3, -0.2), 0.7, (0.0, 0.0, 0.0), (2.0, 0.3, -0.2)),  # separating
    ((1, 1, 1), (-1.0, 0.1, 0.0), 0.5, (1.0, -0.1, 0.0), (0.0, 0.0, 0.0)),  # sticking
    ((1, 1, 1), (-1.0, 2.0, 0.0), 0.5, (1.0, -0.5, 0.0), (0.0, 1.5, 0.0)),  # sliding
    ((1, 1, 1), (-1.0, 0.0, -2.0), 0.5, (1.0, 0.0, 0.5), (0.0, 0.0, -1.5)),  # sliding along y
    ((2, 4, 4), (-2.0, 1.0, 0.0), 0.5, (1.0, -0.25, 0.0), (0.0, 0.0, 0.0)),  # sticking
    ((2, 4, 4), (-2.0, 3.0, 0.0), 0.5, (1.0, -0.5, 0.0), (0.0, 1.0, 0.0)),  # sliding
    ((1, 1), (-1.0, -2.0), 0.5, (1.0, 0.5), (0.0, -1.5)),  # planar sliding
    ((2, 4), (-2.0, 1.0), 0.5, (1.0, -0.25), (0.0, 0.0)),  # planar sticking
]


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("case", CLOSED)
def test_one_contact_closed_forms(case, backend: str) -> None:
    w, q, mu, r, u = case
    problem = iq.FrictionContactProblem(np.diag(w), q, mu, contact_dim=len(q))
    res = iq.solve_friction(problem, backend=backend)
    assert res.certificate.ok and res.error <= 1e-8
    np.testing.assert_allclose(res.r, r, atol=1e-8)
    np.testing.assert_allclose(res.u, u, atol=1e-8 * np.linalg.norm(q))  # ABH: ‖F‖ ≤ tol‖q‖


@pytest.mark.parametrize("case", CLOSED)
def test_one_contact_closed_forms_in_the_compiled_call(case) -> None:
    """A dense W of one contact is answered by the compiled call, to the closed form; the
    Alart–Curnier function vanishes at the closed form and not beside it."""
    w, q, mu, r, u = case
    d = len(q)
    problem = iq.FrictionContactProblem(np.diag(w), q, mu, contact_dim=d)
    res = iq.solve_friction(problem)
    assert res.backend == "kernel" and res.certificate.ok
    np.testing.assert_allclose(res.r, r, atol=1e-8)
    mus, rho = np.array([mu]), np.array([1.0 / np.mean(w)])
    A, B = np.empty((1, d, d)), np.empty((1, d, d))
    zero = alart_curnier(np.array(r, float), np.array(u, float), mus, rho, d, False, A, B)
    np.testing.assert_allclose(zero, 0.0, atol=1e-15)
    for j in range(d):
        bad = np.array(r, float)
        bad[j] += 1e-3
        ub = np.diag(w) @ bad + q
        assert np.linalg.norm(alart_curnier(bad, ub, mus, rho, d, False, A, B)) > 1e-5


def test_sliding_reaction_on_the_cone_opposite_to_the_slip() -> None:
    rng = np.random.default_rng(3)
    for _ in range(20):
        mu = rng.uniform(0.1, 1.0)
        qt = rng.standard_normal(2) * 5.0
        problem = iq.FrictionContactProblem(np.eye(3), [-1.0, *qt], mu)
        r = iq.solve_friction(problem).r
        if np.linalg.norm(qt) > mu:  # slides: |r_T| = μ r_n, r_T against u_T = q_T + r_T
            assert r[0] == pytest.approx(1.0)
            np.testing.assert_allclose(r[1:], -mu * qt / np.linalg.norm(qt), atol=1e-9)
        else:  # sticks: u = 0
            np.testing.assert_allclose(r, [1.0, *(-qt)], atol=1e-9)


# --- random problems ----------------------------------------------------------------------------

@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("mu", [0.1, 0.5, 1.0])
@pytest.mark.parametrize("skew", [0.0, 0.02])
def test_random_problems_two_methods_agree(d: int, mu: float, skew: float) -> None:
    problem = random_problem(8, d, mu, seed=int(10 * mu) + d, skew=skew)
    qn = np.linalg.norm(problem.q)
    results = {b: iq.solve_friction(problem, backend=b, tol=1e-8) for b in BACKENDS}
    for b, res in results.items():
        assert res.certificate.ok, (b, res.certificate.summary())
        assert res.error <= 1e-8
        again = certify_friction(problem, res.r, res.u, tol=1e-8)
        # the compiled route of a few contacts sums W̃r̂ in its own order: equal to rounding
        assert again.ok and again.error == pytest.approx(res.error, rel=1e-6, abs=1e-15)
        np.testing.assert_allclose(res.u, problem.W @ res.r + problem.q, atol=1e-12 * qn)
    np.testing.assert_allclose(results["clarabel"].u, results["nsgs"].u, atol=1e-6 * qn)


@pytest.mark.parametrize("mu", [0.0, 0.5])
def test_rank_deficient_W_with_a_known_solution(mu: float) -> None:
    """W = HᵀH of rank n/2 and q built from a De Saxcé solution: every method certifies an
    answer. Without friction u = Wr + q is unique (r is not); with friction even u need not
    be (the answers found here differ by 1e-2 and are each certified)."""
    rng = np.random.default_rng(7)
    m, d = 6, 3
    n = m * d
    H = rng.standard_normal((n // 2, n))
    W = H.T @ H / n
    r, u = np.zeros(n), np.zeros(n)
    for c in range(m):
        k = c * d
        kind = c % 3
        if kind == 0:  # separated
            u[k:k + d] = [1.0, *rng.standard_normal(d - 1)]
        elif kind == 1 or mu == 0.0:  # sticking
            r[k:k + d] = [1.0, *(0.3 * mu * rng.standard_normal(d - 1))]
        else:  # sliding
            t = rng.standard_normal(d - 1)
            u[k + 1:k + d] = t
            r[k:k + d] = [2.0, *(-2.0 * mu * t / np.linalg.norm(t))]
    problem = iq.FrictionContactProblem(W, u - W @ r, mu)
    assert certify_friction(problem, r, u).ok
    qn = np.linalg.norm(problem.q)
    for backend in BACKENDS:
        res = iq.solve_friction(problem, backend=backend)
        assert res.certificate.ok
        if mu == 0.0:
            np.testing.assert_allclose(res.u, u, atol=1e-6 * qn)


def general_route(problem):
    """``auto`` without the compiled call of a few contacts."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(friction_methods, "SMALL_CONTACTS", 0)
        return iq.solve_friction(problem)


@pytest.mark.parametrize("mu", [0.0, 0.5])
def test_least_squares_newton_agrees_with_newton_on_alart_curnier(mu: float) -> None:
    """The last-resort least-squares Newton on F and the Newton on Φ, each from a few NSGS
    sweeps, on a rank-deficient W: both certify, and their velocities agree."""
    rng = np.random.default_rng(12)
    m, d = 6, 3
    H = rng.standard_normal((m * d // 2, m * d))
    problem = iq.FrictionContactProblem(H.T @ H / 9.0, H.T @ rng.standard_normal(9), mu)
    data = friction_newton.FrictionData(problem)
    start = friction_methods.nsgs_route(data, np.zeros(m * d), 1e-8, 5)[0]
    found = [friction_newton.lstsq_newton(data, start, 1e-8),
             friction_newton.newton(data, start, 1e-8)]
    for r, _, ok in found:
        assert ok and certify_friction(problem, r).ok
    u = [problem.velocity(r) for r, _, _ in found]
    np.testing.assert_allclose(u[0], u[1], atol=1e-6 * np.linalg.norm(problem.q))


def test_ill_conditioned_problem_general_route_and_kernel() -> None:
    """An ill-conditioned global problem reduced to local form (W = HᵀM⁻¹H, M's masses over
    six decades, μ = 1): ``auto`` by the general route (W sparse) and by the compiled call
    (W dense) certify velocities that are those of the SOCP route from zero."""
    rng = np.random.default_rng(4)
    m, d = 6, 3
    H = rng.standard_normal((12, m * d))
    W = H.T @ np.diag(np.logspace(0, -6, 12)) @ H
    q = H.T @ rng.standard_normal(12)
    problem = iq.FrictionContactProblem(sp.csr_matrix(W), q, 1.0)
    general = general_route(problem)
    assert general.certificate.ok and general.backend != "kernel"
    dense = iq.solve_friction(iq.FrictionContactProblem(W, q, 1.0))
    assert dense.certificate.ok and dense.backend == "kernel"
    cold = iq.solve_friction(problem, backend="clarabel")
    for res in (general, dense):
        np.testing.assert_allclose(res.u, cold.u, atol=1e-6 * np.linalg.norm(q))


@pytest.mark.parametrize("m", [1, 2, 4, 9])
@pytest.mark.parametrize("d", [2, 3])
def test_compiled_call_agrees_with_the_general_route(m: int, d: int) -> None:
    """The compiled call against the general route (W sparse) and the SOCP route: the
    velocities agree."""
    for seed in range(3):
        dense = random_problem(m, d, [0.1, 0.5, 1.0][seed], seed=40 + seed, skew=0.01 * seed)
        sparse = iq.FrictionContactProblem(sp.csr_matrix(dense.W), dense.q, dense.mu,
                                           contact_dim=d)
        qn = np.linalg.norm(dense.q)
        a, b = iq.solve_friction(dense), general_route(sparse)
        c = iq.solve_friction(dense, backend="clarabel")
        assert a.backend == "kernel" and b.backend != "kernel"
        assert a.certificate.ok and b.certificate.ok
        np.testing.assert_allclose(a.u, b.u, atol=1e-6 * qn)
        np.testing.assert_allclose(a.u, c.u, atol=1e-6 * qn)


def test_compiled_call_refuses_a_problem_without_solution() -> None:
    """W = 0 and q_n < 0: the compiled call says it did not get there (and the general route
    then raises, see below); its r is no answer."""
    W, q, mu = np.zeros((3, 3)), np.array([-1.0, 0.0, 0.0]), np.array([0.5])
    r = np.empty(3)
    _, ok = solve_small(W, q, mu, np.ones(1), 3, 1e-8, r, 50, 100, 10)
    assert not ok
    assert not certify_friction(iq.FrictionContactProblem(W, q, mu), r).ok


def test_sparse_W_gives_the_dense_answer() -> None:
    dense = random_problem(5, 3, 0.3, seed=11)
    sparse = iq.FrictionContactProblem(sp.csr_matrix(dense.W), dense.q, dense.mu)
    a, b = iq.solve_friction(dense), iq.solve_friction(sparse)
    assert b.certificate.ok and a.backend == b.backend == "kernel"
    np.testing.assert_allclose(a.u, b.u, atol=1e-7 * np.linalg.norm(dense.q))


def test_per_contact_mu_and_frictionless_contacts() -> None:
    problem = random_problem(6, 3, 0.0, seed=5)
    mu = np.array([0.0, 0.2, 0.0, 1.0, 0.5, 0.0])
    problem = iq.FrictionContactProblem(problem.W, problem.q, mu)
    for backend in BACKENDS:
        res = iq.solve_friction(problem, backend=backend)
        assert res.certificate.ok
        for c in np.flatnonzero(mu == 0.0):
            assert np.all(res.r[3 * c + 1:3 * c + 3] == 0.0)


def test_no_solution_is_a_certificate_error() -> None:
    """u = q whatever r (W = 0) with q_n < 0: nothing can satisfy u_n ≥ 0."""
    problem = iq.FrictionContactProblem(np.zeros((3, 3)), [-1.0, 0.0, 0.0], 0.5)
    with pytest.raises(iq.CertificateError, match="natural_map|clarabel"):
        iq.solve_friction(problem)
    with pytest.raises(iq.CertificateError, match=r"newton \(friction, .*natural_map"):
        iq.solve_friction(problem, backend="newton")


# --- the certificate ----------------------------------------------------------------------------

def test_corrupted_answers_fail_the_certificate() -> None:
    problem = random_problem(6, 3, 0.5, seed=2)
    res = iq.solve_friction(problem)
    rng = np.random.default_rng(0)
    scale = np.linalg.norm(res.r)
    for _ in range(10):
        bad = res.r + 1e-5 * scale * rng.standard_normal(res.r.size)
        assert not certify_friction(problem, bad).ok
    bad_u = res.u.copy()
    bad_u[0] += 1e-6 * np.linalg.norm(problem.q)
    cert = certify_friction(problem, res.r, bad_u)
    assert not cert.ok and cert.worst[0] == "velocity"
    nan = res.r.copy()
    nan[1] = np.nan
    assert not certify_friction(problem, nan).ok
    outside = np.zeros_like(res.r)
    outside[1] = 1.0  # a tangential reaction without a normal one
    cone = certify_friction(problem, outside)
    # ‖r_T‖ = 1 in raw units, s_c ≥ 0.4 in contact units, against max(‖q̂‖, ‖r̂‖)
    assert not cone.ok and cone.residuals["cone"] > 0.1


def test_certificate_reports_and_summary() -> None:
    problem = random_problem(4, 2, 0.5, seed=4)
    cert = iq.solve_friction(problem).certificate
    assert set(cert.residuals) == {"natural_map", "velocity", "cone", "dual_cone",
                                   "complementarity"}
    assert set(cert.reported) == {"siconos_error", "penetration"}
    assert cert.reported["siconos_error"] <= cert.error
    assert cert.summary().startswith("ok (tol 1e-08)") and "complementarity=" in cert.summary()


# --- the kernels --------------------------------------------------------------------------------

@pytest.mark.parametrize("d", [2, 3])
def test_projection_is_the_metric_projection(d: int) -> None:
    """p ∈ K_μ, x − p in the polar cone (−K*_μ) and ⟨p, x − p⟩ = 0: the projection's
    characterization, checked independently of the closed form."""
    rng = np.random.default_rng(d)
    m = 400
    mu = rng.choice([0.0, 0.1, 1.0, 3.0], m)
    x = rng.standard_normal(m * d) * 2.0
    p = project_cones(x, mu, d).reshape(m, d)
    y = x.reshape(m, d) - p
    tn = np.linalg.norm(p[:, 1:], axis=1)
    assert np.all(tn <= mu * p[:, 0] + 1e-12)
    assert np.all(mu * np.linalg.norm(y[:, 1:], axis=1) <= -y[:, 0] + 1e-12)
    np.testing.assert_allclose(np.sum(p * y, axis=1), 0.0, atol=1e-12)
    np.testing.assert_allclose(project_cones(p.ravel(), mu, d), p.ravel(), atol=1e-15)


@pytest.mark.parametrize("d", [2, 3])
def test_jacobians_match_finite_differences(d: int) -> None:
    rng = np.random.default_rng(10 + d)
    m = 50
    mu = rng.uniform(0.1, 2.0, m)
    x = rng.standard_normal(m * d)
    h = 1e-7
    for f, jac in ((project_cones, projection_jacobian),
                   (modified_velocity, modified_velocity_jacobian)):
        J = jac(x, mu, d)
        for j in range(d):
            e = np.zeros(m * d)
            e[j::d] = h
            fd = (f(x + e, mu, d) - f(x - e, mu, d)).reshape(m, d) / (2 * h)
            np.testing.assert_allclose(J[:, :, j], fd, atol=1e-6)


@pytest.mark.parametrize("d", [2, 3])
def test_alart_curnier_jacobian_matches_finite_differences(d: int) -> None:
    """dΦ/dr = A + B W (A, B the kernel's blocks) against central differences of
    r ↦ Φ(r, W r + q), at points where every contact is off its kinks."""
    rng = np.random.default_rng(30 + d)
    m = 40
    problem = random_problem(m, d, 0.5, seed=d, skew=0.05)
    W, q = problem.W, problem.q
    mu = rng.uniform(0.1, 1.5, m)
    rho = rng.uniform(0.5, 2.0, m)
    r = rng.standard_normal(m * d)
    A, B = np.empty((m, d, d)), np.empty((m, d, d))
    alart_curnier(r, W @ r + q, mu, rho, d, True, A, B)
    J = sp.block_diag(list(A)).toarray() + sp.block_diag(list(B)).toarray() @ W
    h = 1e-7
    for j in range(m * d):
        e = np.zeros(m * d)
        e[j] = h
        up, down = r + e, r - e
        fd = (alart_curnier(up, W @ up + q, mu, rho, d, False, A, B)
              - alart_curnier(down, W @ down + q, mu, rho, d, False, A, B)) / (2 * h)
        np.testing.assert_allclose(J[:, j], fd, atol=1e-6)


def test_lu_solve_against_numpy() -> None:
    rng = np.random.default_rng(8)
    for n in (1, 3, 12):
        J = rng.standard_normal((n, n))
        b = rng.standard_normal(n)
        x = b.copy()
        assert lu_solve(J.copy(), x)
        np.testing.assert_allclose(x, np.linalg.solve(J, b), rtol=1e-10, atol=1e-12)
    assert not lu_solve(np.zeros((2, 2)), np.ones(2))


def test_nsgs_reports_the_error_of_the_reaction_it_leaves() -> None:
    # ‖F‖ is evaluated only every few sweeps: the sweeps and error returned must still be
    # those of the r left behind, whether the tolerance is met or the sweeps run out
    p = random_problem(15, 3, 0.5, 4)
    W = sp.csr_matrix(p.W)
    qn = np.linalg.norm(p.q)
    for tol, sweeps in ((1e-6, 5000), (1e-14, 37)):
        r = np.zeros(p.q.size)
        done, err = nsgs_rows(W.indptr, W.indices, W.data, p.q, p.mu, 3, r, tol, sweeps, 3)
        exact = np.linalg.norm(natural_map(r, p.W @ r + p.q, p.mu, 3)) / qn
        assert err == pytest.approx(exact, rel=1e-12)
        assert (err <= tol and done < sweeps) if tol == 1e-6 else (err > tol and done == sweeps)


def test_local_steps_and_scales_closed_forms() -> None:
    # W_cc = diag(a, b, b) plus a skew part: ρ_c = 2/(a + b) from its symmetric part; the
    # Alart–Curnier scale is 1 over the mean of the diagonal, 1 where that is not positive
    blocks = np.array([[[2.0, 0.3, 0.0], [-0.3, 6.0, 0.0], [0.0, 0.0, 6.0]],
                       [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]])
    np.testing.assert_allclose(local_steps(blocks), [2.0 / 8.0, 1.0])
    np.testing.assert_allclose(scales(np.array([2.0, 6.0, 7.0, -1.0, 0.0, 0.0]), 3),
                               [1.0 / 5.0, 1.0])


def test_natural_map_vanishes_at_a_solution_only() -> None:
    mu = np.array([0.5])
    r, u = np.array([1.0, -0.5, 0.0]), np.array([0.0, 1.5, 0.0])  # sliding (W = I above)
    assert np.linalg.norm(natural_map(r, u, mu, 3)) == 0.0
    assert np.linalg.norm(natural_map(r, u + [0.0, 0.0, 0.1], mu, 3)) > 1e-3


def _soc_projection(x: np.ndarray) -> np.ndarray:
    """Projection onto the second-order cone {‖x_T‖ ≤ x_n} (μ = 1) by its spectral
    decomposition: x = λ₁c₁ + λ₂c₂, λ = x_n ∓ ‖x_T‖, c = ½(1, ∓x_T/‖x_T‖), negative λ dropped."""
    out = np.empty_like(x)
    for c, v in enumerate(x):
        t = np.linalg.norm(v[1:])
        w = v[1:] / t if t > 0 else np.zeros(v.size - 1)
        parts = [(v[0] - t, np.r_[0.5, -0.5 * w]), (v[0] + t, np.r_[0.5, 0.5 * w])]
        out[c] = sum(max(lam, 0.0) * vec for lam, vec in parts)
    return out


@pytest.mark.parametrize("d", [2, 3])
def test_certificate_error_against_a_spectral_computation(d: int) -> None:
    """ABH of the compiled certificate against numpy with the spectral SOC projection
    (μ = 1), in contact units (r̃ = s∘r, ũ = u/s, q̃ = q/s, s = √W_nn of each contact), at a
    certified answer and at perturbed ones."""
    problem = random_problem(7, d, 1.0, seed=20 + d, skew=0.05)
    res = iq.solve_friction(problem, backend="clarabel")
    s = np.repeat(np.sqrt(np.diag(problem.W)[::d]), d)
    rng = np.random.default_rng(1)
    for r in [res.r] + [res.r + 1e-3 * rng.standard_normal(res.r.size) for _ in range(5)]:
        u = ((problem.W @ r + problem.q) / s).reshape(-1, d)
        ut = u.copy()
        ut[:, 0] += np.linalg.norm(u[:, 1:], axis=1)
        rs = (s * r).reshape(-1, d)
        F = rs - _soc_projection(rs - ut)
        abh = np.linalg.norm(F) / np.linalg.norm(problem.q / s)
        cert = certify_friction(problem, r)
        assert cert.error == pytest.approx(abh, rel=1e-9, abs=1e-15)
        assert (abh <= 1e-8) or not cert.ok


def test_zero_free_velocity_gives_zero_reaction() -> None:
    problem = iq.FrictionContactProblem(np.eye(6), np.zeros(6), 0.5)
    for backend in BACKENDS:
        res = iq.solve_friction(problem, backend=backend)
        assert res.certificate.ok and not res.r.any() and not res.u.any()


def test_result_fields() -> None:
    res = iq.solve_friction(random_problem(3, 3, 0.5, seed=1), backend="clarabel")
    assert res.backend == "clarabel" and res.iterations >= 1 and res.solve_time > 0
    assert res.success and res.status == "solved" and "clarabel" in res.message
    assert res.attempts[-1].startswith("clarabel (friction)")
    assert len(repr(res)) < 200 and "FrictionResult" in repr(res)
    assert res.error == res.certificate.error


# --- bad inputs ---------------------------------------------------------------------------------

@pytest.mark.parametrize("args, kwargs, error", [
    ((np.eye(3), [1.0, 0, 0], -0.1), {}, iq.InputError),
    ((np.eye(3), [1.0, 0, 0], 0.1), {"contact_dim": 4}, iq.InputError),
    ((np.eye(3), [1.0, 0, 0], 0.1), {"contact_dim": 2}, iq.errors.ShapeError),
    ((np.eye(4), [1.0, 0, 0], 0.1), {}, iq.errors.ShapeError),
    ((np.eye(6), np.zeros(6), [0.1, 0.2, 0.3]), {}, iq.errors.ShapeError),
    ((np.eye(3), [np.nan, 0, 0], 0.1), {}, iq.errors.NonFiniteError),
    ((np.full((3, 3), np.inf), [1.0, 0, 0], 0.1), {}, iq.errors.NonFiniteError),
    ((np.eye(3), [1.0, 0, 0], np.nan), {}, iq.errors.NonFiniteError),
    ((np.eye(3), [1.0, 0, 0], True), {}, iq.InputError),
    ((np.eye(3), np.zeros(0), 0.1), {}, iq.errors.ShapeError),
])
def test_bad_inputs_are_named_errors(args, kwargs, error) -> None:
    with pytest.raises(error):
        iq.FrictionContactProblem(*args, **kwargs)


def test_bad_solver_arguments_are_named_errors() -> None:
    problem = iq.FrictionContactProblem(np.eye(3), [-1.0, 0.0, 0.0], 0.5)
    with pytest.raises(iq.InputError, match="backend"):
        iq.solve_friction(problem, backend="lemke")
    with pytest.raises(iq.InputError, match="tol"):
        iq.solve_friction(problem, tol=2.0)
    with pytest.raises(iq.InputError, match="FrictionContactProblem"):
        iq.solve_friction((np.eye(3), np.zeros(3), 0.5))
    with pytest.raises(iq.errors.ShapeError):
        certify_friction(problem, np.zeros(2))


def test_the_kernels_take_a_writable_copy_of_the_problems_mu() -> None:
    """The solvers hand the kernels μ as the time-step kernels do (a writable array: one
    compiled version of each kernel on μ serves both), while the problem's μ stays read-only
    and unchanged."""
    problem = iq.FrictionContactProblem(np.eye(6), -np.ones(6), [0.3, 0.5])
    data = friction_newton.FrictionData(problem)
    assert data.mu.flags.writeable and not problem.mu.flags.writeable
    assert data.mu is not problem.mu and np.array_equal(data.mu, problem.mu)
    data.mu[0] = 9.0
    assert problem.mu[0] == 0.3
