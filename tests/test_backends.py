"""Every backend agrees with the exact active-set enumeration; laws agree across forms."""

import numpy as np
import pytest
import scipy.sparse as sp

import impactqp as iq

QP_BACKENDS = ["nnls", "clarabel", "osqp", "cvxpy", "qpsolvers:daqp", "qpsolvers:piqp",
               "qpsolvers:highs"]
CASES = [(4, 3, 0), (6, 5, 0), (5, 6, 2), (8, 8, 3), (3, 4, 2)]


def rel_err(a, b):
    return np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300)


@pytest.mark.parametrize("n,m,red", CASES)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_moreau_backends_match_exact(n, m, red, seed):
    p = iq.random_impact(n, m, seed=seed, redundant=red, consistent=seed != 2)
    ref = iq.moreau(p, 0.7, backend="exact", form="velocity")
    ref_imp = iq.moreau(p, 0.7, backend="exact", form="impulse")
    assert rel_err(ref_imp.u_plus, ref.u_plus) < 1e-9
    for backend in QP_BACKENDS:
        forms = ["impulse"] if backend == "nnls" else ["impulse", "velocity"]
        for form in forms:
            r = iq.moreau(p, 0.7, backend=backend, form=form)
            assert r.certificate.ok
            assert rel_err(r.u_plus, ref.u_plus) < 1e-6, (backend, form)
            # impulses may differ with redundant contacts; W Λ may not
            np.testing.assert_allclose(p.W @ r.impulses, p.W @ ref.impulses,
                                       atol=1e-6 * max(1.0, np.abs(p.W @ ref.impulses).max()))


@pytest.mark.parametrize("seed", range(4))
def test_newton_and_fremond_backends_match_exact(seed):
    rng = np.random.default_rng(seed)
    p = iq.random_impact(6, 4, seed=seed)
    e = rng.random(4)
    E = 0.3 * rng.random((4, 4))
    for law, coef in ((iq.newton, e), (iq.fremond, E)):
        ref = law(p, coef, backend="exact")
        for backend in ["auto", "nnls", "clarabel", "osqp", "qpsolvers:daqp"]:
            r = law(p, coef, backend=backend)
            assert rel_err(r.u_plus, ref.u_plus) < 1e-6, (law.__name__, backend)


def test_newton_with_equal_coefficients_is_moreau():
    p = iq.random_impact(7, 5, seed=11)
    np.testing.assert_allclose(iq.newton(p, 0.4).u_plus, iq.moreau(p, 0.4).u_plus, atol=1e-10)
    np.testing.assert_allclose(iq.fremond(p, 0.4 * np.eye(5)).u_plus,
                               iq.moreau(p, 0.4).u_plus, atol=1e-10)


def test_local_newton_can_gain_energy_and_says_so():
    # 3-ball cradle, first contact elastic and second plastic: a known case where the
    # local law leaves S; the result is returned (certified) and admissibility is False.
    found = False
    p0 = iq.newtons_cradle()
    rng = np.random.default_rng(3)
    for _ in range(200):
        p = p0.with_u_minus(rng.standard_normal(3))
        r = iq.newton(p, [1.0, 0.0])
        assert r.certificate.ok
        if r.energy_after > r.energy_before * (1 + 1e-9):
            assert not r.admissible
            assert "energetic" in r.admissible.failed()
            found = True
            break
    assert found, "expected a pre-impact velocity where local Newton gains energy"


def test_auto_large_problem_uses_qp_solver():
    p = iq.random_impact(60, 50, seed=5)
    r = iq.moreau(p, 0.5)
    ref = iq.moreau(p, 0.5, backend="clarabel", form="velocity")
    assert rel_err(r.u_plus, ref.u_plus) < 1e-6
    assert r.certificate.ok


def test_sparse_chain_solves_without_densifying():
    n = 400
    u = np.zeros(n)
    u[0] = 1.0
    p = iq.chain(np.ones(n), u, sparse=True)
    r = iq.moreau(p, 0.0)
    np.testing.assert_allclose(r.u_plus, 1.0 / n, rtol=1e-6)
    assert r.certificate.ok


def test_unsolvable_lcp_raises_no_solution():
    # duplicated contact with contradicting coefficients: q ∉ range(G) and infeasible
    M = np.eye(2)
    W = np.array([[1.0, -1.0], [0.0, 0.0]])  # two opposite contacts on the same coordinate
    p = iq.ImpactProblem(M, W, [0.0, 1.0])
    E = np.array([[0.0, 0.0], [0.0, 0.0]])
    # u⁻ = 0 along the contacts: solvable
    assert iq.fremond(p, E).certificate.ok
    with pytest.raises(iq.NoSolutionError):
        iq.solve_lcp(np.zeros((1, 1)), [-1.0])


def test_positive_definite_lcp_is_never_called_unsolvable():
    """A middle ball 10¹² times lighter than its neighbours: G is positive definite, so the
    Newton LCP has a solution, which round-off keeps from certifying at 1e-10; the error
    says so (CertificateError), never that the law has no solution."""
    from impactqp.qp.kinds import positive_definite

    p = iq.chain([1.0, 1e-12, 1.0], [1.0, 0.0, 0.0])
    G = p.delassus
    assert positive_definite(G.toarray() if sp.issparse(G) else np.asarray(G))
    with pytest.raises(iq.CertificateError, match="no backend met the certificate"):
        iq.solve(p, iq.Newton(0.5))
    A = np.random.default_rng(1).standard_normal((5, 3))
    assert not positive_definite(A @ A.T)  # rank 3 of 5: decided by linprog, not here
    assert positive_definite(sp.csr_matrix(A.T @ A + np.eye(3)))


def test_cvxpy_compiles_once_per_structure():
    from impactqp.qp.backends import cvxpy_

    p = iq.random_impact(6, 4, seed=9)
    rng = np.random.default_rng(0)
    answers = []
    for _ in range(3):
        q = p.with_u_minus(rng.standard_normal(6))
        answers.append((q, iq.moreau(q, 0.3, backend="cvxpy:CLARABEL", form="velocity")))
    cached = cvxpy_._CACHE[p.structure]
    assert len(cached) == 1  # one compiled problem served all three solves
    for q, r in answers:  # and each answer is the one for its own u⁻
        ref = iq.moreau(q, 0.3, backend="exact")
        assert q.norm(r.u_plus - ref.u_plus) <= 1e-9 * q.velocity_scale


def test_polish_makes_an_ill_conditioned_chain_exact():
    # the Delassus matrix of a 10⁴-ball cradle has condition ~4e7: Clarabel alone stops
    # with small residuals but velocities off in the 9th digit; polished, they are exact
    n = 10_000
    p = iq.newtons_cradle(n)
    r = iq.moreau(p, 0.0, backend="clarabel")
    assert r.backend == "clarabel" and any("polished" in a for a in r.attempts)
    np.testing.assert_allclose(r.u_plus, 1.0 / n, rtol=1e-9)


def test_polish_keeps_redundant_impulses_feasible():
    # HiGHS answers this degenerate impulse form with an interior point of the optimal face
    p = iq.random_impact(3, 4, seed=0, redundant=2)
    r = iq.moreau(p, 0.7, backend="qpsolvers:highs", form="impulse")
    ref = iq.moreau(p, 0.7, backend="exact")
    assert r.certificate.ok and r.impulses.min() >= 0
    assert p.norm(r.u_plus - ref.u_plus) <= 1e-9 * p.velocity_scale


def test_certificate_bounds_velocity_error_on_large_mass_ratios():
    # alternating masses 1 and 10⁶: Clarabel stops with every residual below 1e-9 while its
    # velocities are off by ~1e-4; the duality-gap residual sees it, so no result is returned
    n = 200
    masses = np.where(np.arange(n) % 2 == 0, 1.0, 1e6)
    u = np.zeros(n)
    u[0] = 1.0
    p = iq.chain(masses, u)
    exact = iq.moreau(p, 1.0)  # isotonic regression
    assert exact.certificate.velocity_error_bound < 1e-12
    with pytest.raises(iq.CertificateError, match="duality_gap"):
        iq.moreau(p, 1.0, backend="clarabel", form="impulse")
    # the velocity form, which chains get by default, is well conditioned: certified and right
    v = iq.moreau(p, 1.0, backend="clarabel")
    assert v.form == "velocity"
    assert p.norm(v.u_plus - exact.u_plus) / p.norm(u) <= v.certificate.velocity_error_bound
    # what passes is as accurate as its bound says
    r = iq.moreau(p, 1.0, backend="qpsolvers:piqp")
    err = p.norm(r.u_plus - exact.u_plus) / p.norm(u)
    assert err <= r.certificate.velocity_error_bound


def test_plain_qpsolvers_takes_the_best_installed_solver():
    import qpsolvers

    from impactqp.qp.backends.qpsolvers_ import PREFERRED_DENSE

    p = iq.newtons_cradle(3)
    r = iq.solve(p, iq.Moreau(1.0), backend="qpsolvers")
    best = next(s for s in PREFERRED_DENSE if s in qpsolvers.available_solvers)
    assert r.backend.startswith(f"qpsolvers:{best}") and r.certificate.ok
    np.testing.assert_allclose(r.u_plus, [-1 / 3, 2 / 3, 2 / 3], atol=1e-12)
    listed = {b["name"] for b in iq.available_backends() if b["installed"]}
    for name in listed:  # every listed backend is accepted by its bare name
        try:
            iq.solve(p, iq.Moreau(1.0), backend=name)
        except iq.BackendUnsuitableError:
            pass  # it serves other programs (the message says which)


@pytest.mark.parametrize("backend, n, words", [("cvxpy", 20_000, "dense n × n"),
                                               ("osqp", 60_000, "converges too slowly")])
def test_large_programs_are_refused_by_size_before_anything_is_allocated(backend, n, words):
    p = iq.chain(np.ones(n), np.r_[1.0, np.zeros(n - 1)])
    with pytest.raises(iq.BackendUnsuitableError, match=words):
        iq.moreau(p, 0.0, backend=backend)
    assert iq.moreau(p, 0.0).certificate.ok  # auto answers it


def test_solver_options_reach_the_named_backend(monkeypatch):
    from impactqp.qp.backends import clarabel_

    seen = {}
    original = clarabel_.settings_with

    def spy(tol, options):
        config = original(tol, options)
        seen["max_iter"] = config.max_iter
        return config

    monkeypatch.setattr(clarabel_, "settings_with", spy)
    p = iq.newtons_cradle(3)
    r = iq.solve(p, iq.Moreau(1.0), backend="clarabel", options={"max_iter": 37})
    assert seen["max_iter"] == 37 and r.certificate.ok
    # a budget too small to converge is the user's choice: the certificate still decides
    with pytest.raises(iq.CertificateError):
        iq.solve(p, iq.Moreau(1.0), backend="osqp", options={"max_iter": 1, "polishing": False})


@pytest.mark.parametrize("backend, options, words", [
    ("clarabel", {"no_such_setting": 1}, "no setting 'no_such_setting'"),
    ("osqp", {"no_such_setting": 1}, "no_such_setting"),
    ("cvxpy", {"no_such_setting": 1}, "no_such_setting"),
    ("kernel", {"max_iter": 3}, "takes no options"),
    ("auto", {"max_iter": 3}, "name the backend"),
    ("clarabel", [("max_iter", 3)], "must be a dict"),
])
def test_bad_solver_options_are_named(backend, options, words):
    with pytest.raises(iq.InputError, match=words):
        iq.solve(iq.newtons_cradle(3), iq.Moreau(1.0), backend=backend, options=options)


def test_every_backend_says_which_options_it_takes():
    listed = {b["name"]: b["options"] for b in iq.available_backends()}
    assert listed["kernel"] == "" and "DefaultSettings" in listed["clarabel"]
    assert all(isinstance(v, str) for v in listed.values())
