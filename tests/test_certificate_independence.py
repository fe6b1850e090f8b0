"""The LCP laws' certificates do not share the solvers' formulas (docs/theory.md §8,
"Independence"): a bug planted in what a solver computes its answer with is caught by the
certificate, which recomputes Λ ≥ 0, w = γ⁺ + Eγ⁻ ≥ 0, Λ·w = 0 and the impact equation
from M, W and u⁻ by formulas of its own."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
import impactqp.qp.backends.isotonic as isotonic_backend
from impactqp.laws import small

COMPILED = "kernel (compiled): certified"
"""The attempt of an impact answered by the compiled single-impact path."""


def dense_problem() -> iq.ImpactProblem:
    """Four bodies with a full mass matrix and three contacts, all active (its own structure:
    nothing else shares what is planted in it)."""
    rng = np.random.default_rng(29)
    A = rng.standard_normal((5, 5))
    M = A @ A.T + 5 * np.eye(5)
    W = rng.standard_normal((5, 3))
    u = -np.linalg.solve(M, W @ np.ones(3))  # approaches on every contact
    return iq.ImpactProblem(M, W, u)


def test_a_wrong_recovery_operand_is_not_certified():
    # the impulse-form solvers recover u⁺ = u⁻ + M⁻¹WΛ with the structure's M⁻¹W; plant an
    # error N in it that Wᵀ does not see (WᵀN = 0): γ⁺, w and complementarity stay exact, so
    # only an impact equation measured with another M⁻¹W catches it
    p = dense_problem()
    st = p.structure
    law = iq.Newton(0.5)
    right = iq.solve(p, law, backend="nnls")
    W = np.asarray(p.W)
    N = (np.eye(5) - W @ np.linalg.pinv(W)) @ np.full((5, 3), 0.05)
    assert np.abs(W.T @ N).max() < 1e-14 and np.abs(N).max() > 1e-3
    wrong = np.asarray(st.Minv_W) + N
    try:
        st.__dict__["Minv_W"] = wrong
        st.__dict__["dense_Minv_W"] = np.ascontiguousarray(wrong)
        with pytest.raises(iq.CertificateError):
            iq.solve(p, law, backend="nnls")
        # the recovered answer, judged: the impact equation is off by ‖NΛ‖ (kinetic norm)
        bad = p.u_minus + wrong @ right.impulses
        cert = law.certificate(p, iq.Answer(bad, right.impulses), 1e-9)
        d = N @ right.impulses
        V = np.sqrt(p.u_minus @ np.asarray(p.M) @ p.u_minus)
        assert cert.momentum == pytest.approx(np.sqrt(d @ np.asarray(p.M) @ d) / V, rel=1e-9)
        assert not cert.ok and cert.law_feasibility <= 1e-12
        # the right answer still passes with the planted operand in the structure
        assert law.certificate(p, iq.Answer(right.u_plus, right.impulses), 1e-9).ok
    finally:
        st.__dict__.pop("Minv_W")
        st.__dict__.pop("dense_Minv_W")


def test_a_wrong_chain_projection_is_not_certified(monkeypatch):
    # the isotonic backend's impulses by anchored sums, off by 1e-6 on one contact: the chain
    # certificate recomputes the impact equation ball by ball and refuses; "auto" then falls
    # back on a general solver whose answer is right
    n = 400
    rng = np.random.default_rng(5)
    p = iq.chain(rng.uniform(0.5, 2.0, n), rng.standard_normal(n))
    good = iq.moreau(p, 0.5)
    assert good.backend == "isotonic"
    true_projection = isotonic_backend.chain_projection

    def off_by_a_little(*args):
        z, lam = true_projection(*args)
        lam = lam.copy()
        lam[np.argmax(lam)] *= 1 + 1e-6
        return z, lam

    monkeypatch.setattr(isotonic_backend, "chain_projection", off_by_a_little)
    monkeypatch.setattr(small, "on_chain", lambda *args: False)  # the general path's backend
    with pytest.raises(iq.CertificateError, match="momentum"):
        iq.moreau(p, 0.5, backend="isotonic")
    fallback = iq.moreau(p, 0.5)
    assert fallback.backend != "isotonic" and fallback.certificate.ok
    np.testing.assert_allclose(fallback.u_plus, good.u_plus, atol=1e-7 * np.abs(good.u_plus).max())


def test_the_compiled_path_measures_momentum_with_its_own_operand():
    # the compiled single-impact path recovers u⁺ with the pack's Cholesky-based M⁻¹W; plant
    # N with WᵀN = 0 there: its candidate satisfies every contact condition and the impact
    # equation as measured with the planted operand, so only the pack's own LU-solved M⁻¹W
    # (docs/theory.md §8, "Independence") refuses it; the general path then answers right
    p = dense_problem()
    st = p.structure
    law = iq.Newton(0.5)
    right = iq.solve(p, law, backend="nnls")
    n, m = st.n, st.m
    W = np.asarray(p.W)
    N = (np.eye(n) - W @ np.linalg.pinv(W)) @ np.full((n, m), 0.05)
    packed = st.kernel_pack.copy()
    start = n * n + m * n
    recovery = packed[start:start + n * m].reshape(n, m)
    np.testing.assert_allclose(recovery, np.linalg.solve(p.M, W), rtol=1e-12)
    recovery += N
    st.__dict__["kernel_pack"] = packed
    try:
        assert small.solve_small(p, law, 1e-9, 0.0) is None
        r = iq.solve(p, law)
        assert r.certificate.ok and r.attempts[-1] != COMPILED
        np.testing.assert_allclose(r.u_plus, right.u_plus, atol=1e-9)
    finally:
        del st.__dict__["kernel_pack"]
    assert iq.solve(p, law).attempts == [COMPILED]


def test_a_wrong_sparse_operand_is_not_certified():
    # sparse problems: the impact equation is formed as M(u⁺ − u⁻) − WΛ from the given M
    # and W and only its size is measured through the factor; an error N in the structure's
    # M⁻¹W (WᵀN = 0) that the recovery used shows there
    import scipy.sparse as sp

    p = dense_problem()
    law = iq.Newton(0.5)
    right = iq.solve(p, law, backend="nnls")
    ps = iq.ImpactProblem(sp.csc_matrix(p.M), sp.csc_matrix(p.W), p.u_minus)
    st = ps.structure
    assert st.sparse and not st.diagonal_mass
    W = np.asarray(p.W)
    N = (np.eye(5) - W @ np.linalg.pinv(W)) @ np.full((5, 3), 0.05)
    wrong_u = p.u_minus + (np.asarray(st.Minv_W) + N) @ right.impulses
    good = law.certificate(ps, iq.Answer(right.u_plus, right.impulses), 1e-9)
    assert good.ok
    st.__dict__["Minv_W"] = np.asarray(st.Minv_W) + N
    try:
        bad = law.certificate(ps, iq.Answer(wrong_u, right.impulses), 1e-9)
        d = N @ right.impulses
        V = np.sqrt(p.u_minus @ np.asarray(p.M) @ p.u_minus)
        assert not bad.ok
        assert bad.momentum == pytest.approx(np.sqrt(d @ np.asarray(p.M) @ d) / V, rel=1e-6)
        assert bad.law_feasibility <= 1e-12
    finally:
        st.__dict__.pop("Minv_W")
