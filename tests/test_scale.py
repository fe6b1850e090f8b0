"""The same physics in other units: velocities from 1e-150 to 1e150, masses from 1e-12 to 1e12.

Moreau's law, the other laws and S are positively homogeneous in u⁻ and invariant under
M → cM (docs/theory.md §8). For every installed backend and every law: no answer returned as
a success may differ from an independent reference by more than 1e-8 (relative), Moreau's
law never reports "no solution", and the answer at scale c is c times the answer at scale 1.
Every case has its expected outcome: the answer, or the named refusal listed in REFUSALS.
S-membership at every scale agrees with an exact test written here, u⁻ = 0 included.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import qpsolvers
import scipy.sparse as sp

import impactqp as iq

VELOCITY_SCALES = [1e-150, 1e-16, 1.0, 1e10, 1e150]
MASS_SCALES = [1e-12, 1.0, 1e12]
BACKENDS = (["auto", "kernel", "isotonic", "exact", "nnls", "clarabel", "osqp", "cvxpy"]
            + [f"qpsolvers:{s}" for s in sorted(qpsolvers.available_solvers)
               if s in ("daqp", "piqp", "highs", "quadprog", "proxqp", "ecos")])


def base_problems() -> dict[str, iq.ImpactProblem]:
    return {"dense": iq.random_impact(6, 4, seed=3),
            "redundant": iq.random_impact(6, 5, seed=4, redundant=2),
            "chain": iq.chain([1.0, 2.0, 0.5, 3.0], [2.0, -1.0, 0.5, -2.0]),
            "sparse": iq.chain([1.0, 2.0, 0.5, 3.0, 1.0], [2.0, -1.0, 0.5, -2.0, 1.0],
                               sparse=True),
            "cradle": iq.newtons_cradle(3)}


def scaled(p: iq.ImpactProblem, velocity: float, mass: float) -> iq.ImpactProblem:
    if p.chain is not None:
        return iq.chain(p.chain.masses * mass, p.u_minus * velocity,
                        sparse=p.structure.sparse)
    return iq.ImpactProblem(p.M * mass, p.W, p.u_minus * velocity)


def laws(p: iq.ImpactProblem) -> dict[str, iq.ImpactLaw]:
    m = p.n_contacts
    out = {"moreau0": iq.Moreau(0.0), "moreau1": iq.Moreau(1.0),
           "newton": iq.Newton(np.linspace(0.2, 0.9, m)),
           "fremond": iq.Fremond(0.4 * np.eye(m) + 0.05 * np.ones((m, m)))}
    return out


def reference(p: iq.ImpactProblem, E: np.ndarray) -> np.ndarray:
    """u⁺ of 0 ≤ Λ ⟂ GΛ + (I + E)γ⁻ ≥ 0 by brute force over supports (dense, written here
    independently of impactqp's solvers); u⁺ is unique although Λ may not be."""
    M, W = np.asarray(p.M.toarray() if sp.issparse(p.M) else p.M), p.W
    W = W.toarray() if sp.issparse(W) else np.asarray(W)
    Minv_W = np.linalg.solve(M, W)
    G = W.T @ Minv_W
    g = W.T @ p.u_minus
    q = g + E @ g
    m = q.size
    scale = np.abs(q).max()
    for size in range(m + 1):
        for J in itertools.combinations(range(m), size):
            J = list(J)
            lam = np.zeros(m)
            if J:
                lam[J] = np.linalg.lstsq(G[np.ix_(J, J)], -q[J], rcond=None)[0]
            w = G @ lam + q
            if lam.min() >= -1e-12 * scale and w.min() >= -1e-10 * scale and \
                    np.abs(w[J]).max(initial=0.0) <= 1e-10 * scale:
                return p.u_minus + Minv_W @ lam
    raise AssertionError("no support solves the reference LCP")


def law_matrix(law: iq.ImpactLaw, p: iq.ImpactProblem) -> np.ndarray:
    """E of 0 ≤ Λ ⟂ γ⁺ + Eγ⁻ ≥ 0 as a matrix."""
    coef = np.asarray(law.coefficients_for(p), dtype=float)
    return coef * np.eye(p.n_contacts) if coef.ndim < 2 else coef


REFUSALS = {(backend, "redundant", law): "CertificateError"
            for backend in ("qpsolvers:ecos", "qpsolvers:quadprog")
            for law in ("newton", "fremond")}
"""The refusals expected, at every scale: (backend, problem, law) → the named error. The
impulse form of Newton's and Frémond's laws has the Delassus matrix of the redundant contacts,
which is singular, and these two backends need a positive definite one (quadprog by its
method, ECOS through its conic reformulation); their answers are not certified. Every case
not listed must be answered correctly: a correct answer that becomes a refusal fails."""


@pytest.mark.parametrize("backend", BACKENDS)
def test_every_backend_at_every_scale(backend: str) -> None:
    wrong, not_homogeneous = [], []
    outcomes, expected = {}, {}
    for name, p in base_problems().items():
        for lname, law in laws(p).items():
            ref = reference(p, law_matrix(law, p))
            at_one = None
            for v, mu in itertools.product(VELOCITY_SCALES, MASS_SCALES):
                q = scaled(p, v, mu)
                case = (name, lname, v, mu)
                try:
                    r = iq.solve(q, law, backend=backend)
                except iq.BackendUnsuitableError:
                    break
                except (iq.NoSolutionError, iq.CertificateError) as exc:
                    outcomes[case] = type(exc).__name__
                    expected[case] = REFUSALS.get((backend, name, lname), "answer")
                    continue
                outcomes[case] = "answer"
                expected[case] = REFUSALS.get((backend, name, lname), "answer")
                assert r.ok and np.all(np.isfinite(r.u_plus))
                err = np.abs(r.u_plus / v - ref).max() / np.abs(ref).max()
                if not err <= 1e-8:
                    wrong.append((name, lname, v, mu, err))
                if v == 1.0 and mu == 1.0:
                    at_one = r.u_plus
                elif at_one is not None:
                    dev = np.abs(r.u_plus / v - at_one).max() / np.abs(at_one).max()
                    if not dev <= 1e-10:
                        not_homogeneous.append((name, lname, v, mu, dev))
    assert wrong == []
    assert {c: o for c, o in outcomes.items() if o != expected[c]} == {}
    assert not_homogeneous == []


def test_auto_never_refuses_moreau_at_any_scale() -> None:
    for p in base_problems().values():
        for v, mu in itertools.product(VELOCITY_SCALES, MASS_SCALES):
            for eps in (0.0, 0.5, 1.0):
                r = iq.moreau(scaled(p, v, mu), eps)
                assert r.certificate.ok and r.backend != "none"


@pytest.mark.parametrize("v", VELOCITY_SCALES)
def test_sector_law_at_every_scale(v: float) -> None:
    for n, mu in itertools.product((3, 5), MASS_SCALES):
        p = iq.newtons_cradle(n, v=v, mass=mu)
        r = iq.sector_law(p)
        np.testing.assert_array_equal(r.u_plus, np.sort(p.u_minus))
        assert r.certificate.ok and r.admissible
        U = np.random.default_rng(0).standard_normal((50, n)) * v
        assert iq.sector_law_batch(p, U).ok.all()


def test_a_wrong_answer_fails_at_every_scale() -> None:
    # the certificate judges in the problem's own units: tiny or huge, no impulse is wrong
    for v, mu in itertools.product(VELOCITY_SCALES, MASS_SCALES):
        p = scaled(iq.chain([1.0, 2.0, 0.5, 3.0], [2.0, -1.0, 0.5, -2.0]), v, mu)
        law = iq.Moreau(0.5)
        cert = law.certificate(p, iq.Answer(p.u_minus.copy(), np.zeros(p.n_contacts)), 1e-9)
        assert not cert.ok, (v, mu)
        good = iq.moreau(p, 0.5)
        assert law.certificate(p, iq.Answer(good.u_plus, good.impulses), 1e-9).ok


def test_zero_velocity_is_exact() -> None:
    for p in base_problems().values():
        q = p.with_u_minus(np.zeros(p.n_dof))
        for law in laws(p).values():
            r = iq.solve(q, law)
            assert not np.any(r.u_plus) and not np.any(r.impulses) and r.ok
        S = q.admissible_set()
        assert S.contains(np.zeros(p.n_dof)).member
        assert not S.contains(np.full(p.n_dof, 1e-300)).member
        assert not S.contains(np.full(p.n_dof, 1e-300), method="optimizer").member


def exact_membership(p: iq.ImpactProblem, u: np.ndarray, tol: float = 1e-9) -> bool:
    """u ∈ S for W of full column rank, written here: Λ is the unique solution of
    WΛ = M(u − u⁻); then Λ ≥ 0, Wᵀu ≥ 0 and uᵀMu ≤ u⁻ᵀMu⁻, all relative to ‖u⁻‖."""
    M = np.asarray(p.M.toarray() if sp.issparse(p.M) else p.M)
    W = p.W.toarray() if sp.issparse(p.W) else np.asarray(p.W)
    c = np.abs(p.u_minus).max()
    un, umn = u / c, p.u_minus / c
    lam, *_ = np.linalg.lstsq(W, M @ (un - umn), rcond=None)
    V = np.sqrt(umn @ M @ umn)
    Mi = np.linalg.inv(M)
    s = np.sqrt(np.diag(W.T @ Mi @ W))
    kinetic = np.sqrt(max((un - umn - Mi @ W @ lam) @ M @ (un - umn - Mi @ W @ lam), 0)) / V
    return bool(kinetic <= tol and (lam * s / V).min() >= -tol
                and (W.T @ un / (s * V)).min() >= -tol and un @ M @ un <= V**2 * (1 + tol))


@pytest.mark.parametrize("v", VELOCITY_SCALES + [1e-300, 1e300])
def test_membership_at_every_scale(v: float) -> None:
    rng = np.random.default_rng(7)
    # at 1e±300 only unit masses: momenta of 1e312 are not representable in floating point
    for mu in MASS_SCALES if abs(np.log10(v)) < 200 else [1.0]:
        for p in (iq.random_impact(5, 3, seed=11), iq.newtons_cradle(3),
                  iq.chain([1.0, 3.0, 2.0], [1.0, 0.0, -1.0])):
            q = scaled(p, v, mu)
            S = q.admissible_set()
            z = q.moreau_split[0]
            candidates = [z, iq.moreau(q, 1.0).u_plus, q.u_minus, 0.5 * z, -q.u_minus,
                          *(q.u_minus + rng.standard_normal(q.n_dof) * v * 0.7
                            for _ in range(6))]
            for u in candidates:
                want = exact_membership(q, u)
                assert S.contains(u).member == want, (v, mu, u / v)


@pytest.mark.parametrize("v", VELOCITY_SCALES + [1e-200, 1e200])
def test_optimizer_membership_at_every_scale(v: float) -> None:
    for mu in (1e-12, 1.0, 1e12):
        p = iq.newtons_cradle(3, v=v, mass=mu)
        S = p.admissible_set()
        inside = [np.array([1, 1, 1]) / 3, np.array([0.0, 0.0, 1.0]), np.array([0.2, 0.3, 0.5])]
        outside = [np.array([1.0, 0.0, 0.0]), np.array([-7.0, 0.0, 8.0]),
                   np.array([0.0, 1.0, 0.0])]
        for u in inside:
            assert S.contains(u * v, method="optimizer").member, (v, mu, u)
        for u in outside:
            assert not S.contains(u * v, method="optimizer").member, (v, mu, u)
