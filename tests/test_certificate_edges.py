"""Every certificate judged at its edge: a corruption at half the tolerance passes, one at
twice the tolerance fails, residual by residual (docs/theory.md §8, §9, §13).

The corruptions are designed by hand on problems small enough to solve on paper, along
directions where the residual is linear in the size of the corruption, so that the residual
equals the chosen multiple of the tolerance to a relative 1e-6; the expected value is written
here from the residual's definition, not read back from the certificate. Where a corruption
cannot move one residual alone (a duality gap moves with complementarity), the others are
checked to stay at or below the targeted one, so the targeted residual decides the verdict.

The two-ball problem: masses (1, μ) with μ = 0.01, one contact γ = u₂ − u₁ (W = (−1, 1)ᵀ),
so G = 1 + 1/μ = 101, s = √G, M⁻¹W = (−1, 1/μ). With u⁻ = (1, 0) (V = 1, γ⁻ = −1) the
contact is active; Newton's law with e gives Λ* = (1 + e)/G, u⁺ = u⁻ + M⁻¹WΛ*. With
u⁻ = (−1, 0) (V = 1, γ⁻ = 1) the balls separate: Λ = 0, u⁺ = u⁻.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import impactqp as iq
from impactqp.base.checks import NamedChecks
from impactqp.laws.batch import BatchCertificate
from impactqp.laws.lzb.certificate import lzb_certificate, lzb_residuals
from impactqp.model.residuals import law_residuals
from impactqp.qp.cones import ConeProgram
from impactqp.qp.lcp import _residuals as lcp_residuals
from impactqp.tables.certificate import TOL as TABLE_TOL
from impactqp.tables.certificate import copositive_2x2

TOL = 1e-9
MU = 0.01
G = 1.0 + 1.0 / MU
S = np.sqrt(G)
MINV_W = np.array([-1.0, 1.0 / MU])
EDGES = [(0.5, True), (2.0, False)]
"""(multiple of the tolerance, verdict)."""


def two_balls(u_minus, kind: str) -> iq.ImpactProblem:
    """The two-ball problem stored as a chain (the O(N) chain pass), dense (the dense kernel)
    or sparse (numpy products): three computations of the same residuals."""
    m = np.array([1.0, MU])
    W = np.array([[-1.0], [1.0]])
    if kind == "chain":
        return iq.chain(m, u_minus)
    if kind == "sparse":
        return iq.ImpactProblem(sp.diags(m).tocsc(), sp.csc_matrix(W), u_minus)
    return iq.ImpactProblem(np.diag(m), W, u_minus)


def active(e: float, dlam: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """u⁻, u⁺ and Λ of the active impact with Λ = Λ* + dlam and u⁺ consistent with Λ (the
    impact equation holds exactly): w = γ⁺ + eγ⁻ = G·dlam."""
    um = np.array([1.0, 0.0])
    lam = (1.0 + e) / G + dlam
    return um, um + MINV_W * lam, np.array([lam])


def separating(dlam: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """u⁻, u⁺ and Λ of the separating case with Λ = dlam and u⁺ consistent with it."""
    um = np.array([-1.0, 0.0])
    return um, um + MINV_W * dlam, np.array([dlam])


def corruption(target: str, c: float, e: float):
    """(u⁻, u⁺, Λ) whose residual ``target`` is c exactly (to first order in c, the
    second-order terms are ~c² ≈ 1e-18), by the definitions of docs/theory.md §8."""
    if target == "momentum":  # u⁺ + c·d, d = (1, 1)/√(1 + μ): ‖d‖_M = 1 and Wᵀd = 0
        um, up, lam = active(e)
        return um, up + c * np.ones(2) / np.sqrt(1.0 + MU), lam
    if target == "impulse_sign":  # Λ = −c/s on the separating contact: (−Λs)₊/V = c
        return separating(-c / S)
    if target == "law_feasibility":  # Λ* − c/s: w = −c·s, (−w/s)₊/V = c
        return active(e, -c / S)
    if target == "complementarity":  # Λ* + t: |Λw| = (Λ* + t)·G·t ≈ (1 + e)t
        return active(e, c / (1.0 + e))
    raise AssertionError(target)


LAWS = {"newton": lambda e: iq.Newton(e), "fremond": lambda e: iq.Fremond([[e]]),
        "moreau": lambda e: iq.Moreau(e)}
TARGETS = ("momentum", "impulse_sign", "law_feasibility", "complementarity")


@pytest.mark.parametrize("kind", ["dense", "chain", "sparse"])
@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("target", TARGETS)
@pytest.mark.parametrize("factor, verdict", EDGES)
def test_impact_certificate_at_its_edge(kind, law, target, factor, verdict):
    e = 0.5
    um, up, lam = corruption(target, factor * TOL, e)
    problem = two_balls(um, kind)
    cert = LAWS[law](e).certificate(problem, iq.Answer(up, lam), TOL)
    res = cert.residuals
    assert res[target] == pytest.approx(factor * TOL, rel=1e-6)
    others = {k: v for k, v in res.items() if k != target and k != "duality_gap"}
    assert max(others.values()) <= 0.7 * res[target], res
    if law == "moreau":  # one contact: the gap is complementarity plus momentum²
        assert res["duality_gap"] <= res[target] * (1 + 1e-6)
    assert cert.ok is verdict and bool(cert) is verdict, cert.summary()


@pytest.mark.parametrize("kind", ["dense", "chain", "sparse"])
@pytest.mark.parametrize("factor, verdict", EDGES)
def test_moreau_energy_balance_at_its_edge(kind, factor, verdict):
    # ε = 1 and u⁺ moved by a·d + b·M⁻¹W with Λ moved by b: momentum a, complementarity
    # ≈ (1 + ε)Λ*G·b/(1 + ε) = 2b·(Λ*G/2) = 2b, and ⟨z, u⁻ − z⟩ = −(a/√(1 + μ) + b)/(1 + ε)
    # to first order (z is the projection, ⟨z, u⁻ − z⟩ = 0 at the answer; γ(z) = 0 and
    # ⟨d, u⁻ − 2z⟩ = −1/√(1 + μ)), so the energy balance 2ε|⟨z, u⁻ − z⟩| = a/√(1 + μ) + b
    # is the largest residual: 1.5× the others with b = a/2.
    eps = 1.0
    target = factor * TOL
    a = target / (1.0 / np.sqrt(1.0 + MU) + 0.5)
    b = a / 2
    um, up, lam = active(eps, b)
    up = up + a * np.ones(2) / np.sqrt(1.0 + MU)
    cert = iq.Moreau(eps).certificate(two_balls(um, kind), iq.Answer(up, lam), TOL)
    res = cert.residuals
    assert res["energy_balance"] == pytest.approx(target, rel=1e-6)
    assert res["momentum"] == pytest.approx(a, rel=1e-6)
    assert res["complementarity"] == pytest.approx(2 * b, rel=1e-6)
    assert max(v for k, v in res.items() if k != "energy_balance") <= res["energy_balance"]
    assert cert.ok is verdict, cert.summary()


def test_exact_answers_pass_with_room():
    # the uncorrupted answers are far inside the tolerance, so the edges above are the
    # corruptions' doing
    for kind in ("dense", "chain", "sparse"):
        for law in LAWS.values():
            for um, up, lam in (active(0.5), separating()):
                cert = law(0.5).certificate(two_balls(um, kind), iq.Answer(up, lam), TOL)
                assert cert.worst[1] <= 1e-3 * TOL, cert.summary()


@pytest.mark.parametrize("target", TARGETS)
def test_batch_certificate_at_its_edge(target):
    # two rows of one problem, corrupted at 0.5× and 2× the tolerance: the per-row verdict
    rows = [corruption(target, f * TOL, 0.5) for f, _ in EDGES]
    if target == "impulse_sign":
        problem = two_balls(separating()[0], "dense")
    else:
        problem = two_balls(active(0.5)[0], "dense")
    Um, Up, Lam = (np.array([r[i] for r in rows]) for i in range(3))
    res = law_residuals(problem.structure, Um, Up, Lam, 0.5)
    np.testing.assert_allclose(res[target], [f * TOL for f, _ in EDGES], rtol=1e-6)
    cert = BatchCertificate(res, TOL)
    assert cert.ok.tolist() == [v for _, v in EDGES]
    assert cert.worst[0] == target


@pytest.mark.parametrize("target", ["momentum", "impulse_sign", "kinematic",
                                    "energy_balance", "potential_left"])
@pytest.mark.parametrize("factor, verdict", EDGES)
def test_lzb_certificate_at_its_edge(target, factor, verdict):
    # an elastic impact (e = 1); the integration's residuals are judged against their own
    # tolerance, here 1e3 × the exact ones'
    tol, itol = TOL, 1e3 * TOL
    exact = target in ("momentum", "impulse_sign")
    c = factor * (tol if exact else itol)
    stored = left = 0.0
    if target == "kinematic":  # at rest after, γ⁺ = γ⁻ = −g: (−γ⁺/s)₊/V = g/(sV) = c
        g = c * S * np.sqrt(1.0 + MU)  # V = √(1 + μ(1 − g)²) = √(1 + μ) to 1e-10
        um = np.array([1.0, 1.0 - g])
        up, lam = um.copy(), np.zeros(1)
    elif exact:
        um, up, lam = corruption(target, c, 1.0)
    else:  # the elastic answer (V = 1); |‖u⁺‖² + 2·stored − ‖u⁻‖²|/V² = 2·stored, and
        um, up, lam = active(1.0)  # 2·left/V² (left is not in stored here: one at a time)
        if target == "energy_balance":
            stored = c / 2
        else:
            left = c / 2
    res = lzb_residuals(two_balls(um, "dense").structure, um, up, lam, stored=stored,
                        left=left)
    assert res[target] == pytest.approx(c, rel=1e-6)
    # the others, each against its own tolerance, stay below: the target decides
    assert max(v / (tol if k in ("momentum", "impulse_sign") else itol)
               for k, v in res.items() if k != target) <= 0.7 * factor
    cert = lzb_certificate({k: float(v) for k, v in res.items()}, tol, itol)
    assert cert.ok is verdict, cert.summary()


@pytest.mark.parametrize("target", ["primal", "dual", "stationarity", "complementarity"])
@pytest.mark.parametrize("factor, verdict", EDGES)
def test_cone_certificate_at_its_edge(target, factor, verdict):
    # programs of one or two rows solved on paper, with s = b − Ax in the nonnegative cone
    t = factor * TOL
    nonneg = [("nonnegative", 1)]
    if target == "primal":  # min 0 s.t. x ≥ 0, at x = −t: s = −t, relative to 1 + t
        prog, x, z, value = ConeProgram(None, np.zeros(1), -np.eye(1), np.zeros(1), nonneg), \
            [-t], [0.0], t / (1 + t)
    elif target == "dual":  # two rows x ≥ 0 twice, z = (−t, t): Aᵀz = 0, z ∉ K*
        prog = ConeProgram(None, np.zeros(1), -np.ones((2, 1)), np.zeros(2),
                           [("nonnegative", 2)])
        x, z, value = [0.0], [-t, t], t / (1 + t)
    elif target == "stationarity":  # min ½x² s.t. x ≥ 0 at x = t, z = 0: Px = t
        prog, x, z, value = ConeProgram(np.eye(1), np.zeros(1), -np.eye(1), np.zeros(1),
                                        nonneg), [t], [0.0], t / (1 + t)
    else:  # min ½x² − x s.t. x ≥ 0 at x = 1 + t, z = t: stationary, s·z = (1 + t)t
        prog = ConeProgram(np.eye(1), -np.ones(1), -np.eye(1), np.zeros(1), nonneg)
        x, z = [1.0 + 2 * t], [2 * t]
        # objectives −½ + 2t² and −½ − 2t − 2t²: size 2 + 2t, s·z = (1 + 2t)·2t ≈ t·size
        value = (1 + 2 * t) * 2 * t / (2 + 2 * t + 4 * t * t)
    cert = prog.certificate(np.array(x), np.array(z), TOL)
    res = cert.residuals
    assert res[target] == pytest.approx(value, rel=1e-6) and value == pytest.approx(t, rel=1e-6)
    # the duality gap moves with complementarity (gap = sᵀz for a feasible stationary pair)
    assert max(v for k, v in res.items() if k not in (target, "gap")) <= 1e-3 * TOL
    assert res["gap"] <= res[target] * (1 + 1e-6)
    assert cert.ok is verdict, cert.summary()


@pytest.mark.parametrize("target", ["z_sign", "w_sign", "complementarity"])
@pytest.mark.parametrize("factor, verdict", EDGES)
def test_lcp_certificate_at_its_edge(target, factor, verdict):
    # 0 ≤ z ⟂ z + q ≥ 0 with one unknown (already normalized: G = 1, |q| = 1), so
    # ‖q‖ + 1 = 2 and max(|z|, 1) = 1 at the corrupted points
    t = factor * TOL
    if target == "z_sign":  # q = 1: z = −t, w = 1 − t; z_sign = t
        q, z, value = np.ones(1), np.array([-t]), t
    elif target == "w_sign":  # q = −1: z = 1 − 2t, w = −2t; w_sign = 2t/2
        q, z, value = -np.ones(1), np.array([1.0 - 2 * t]), t
    else:  # q = −1: z = 1 + 2t, w = 2t; |zw|/(2·z) = t
        q, z, value = -np.ones(1), np.array([1.0 + 2 * t]), t
    _, res = lcp_residuals(np.eye(1), q, z)
    assert res[target] == pytest.approx(value, rel=1e-6)
    # the natural map min(z, w) moves with each of them, by at most as much
    assert max(res.values()) <= value * (1 + 1e-6)
    assert NamedChecks(res, TOL).ok is verdict


@pytest.mark.parametrize("factor, verdict", EDGES)
def test_named_checks_verdict_at_its_edge(factor, verdict):
    # the one verdict every certificate shares, at its edge, with a NaN that never passes
    assert NamedChecks({"a": 0.0, "b": factor * TOL}, TOL).ok is verdict
    assert not NamedChecks({"a": float("nan")}, TOL).ok


@pytest.mark.parametrize("factor, verdict", EDGES)
def test_table_copositivity_at_its_edge(factor, verdict):
    # C = diag(−t, 1) is copositive only to the table's absolute tolerance
    C = np.diag([-factor * TABLE_TOL, 1.0])
    assert bool(copositive_2x2(C)) is verdict
