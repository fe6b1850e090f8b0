"""solve_friction over W and q scaled over 1e-200…1e200 (issue 25): 0 wrong answers certified,
0 bare exceptions, and no correct answer turned into a refusal.

Each answer is judged here, independently of impactqp's certificate: the problem (a·W₀, b·q₀)
has the answers (b/a)·r₀, b·u₀ of (W₀, q₀); De Saxcé's natural map of (W₀, q₀) at r·a/b is
computed in numpy, in velocity units (each contact's rows over σ_c = √(W₀)_nn, written here),
with the closed-form projection onto K_μ written below (docs/theory.md §15), and u/b is
compared with W₀(r·a/b) + q₀ in the same units.
"""

import numpy as np
import pytest
from cone_reference import project_onto_cone

import impactqp as iq
from impactqp.errors import ImpactError, OutOfRangeError

W_SCALES = [1e-200, 1e-12, 1.0, 1e12, 1e200]
Q_SCALES = [1e-200, 1e-50, 1.0, 1e50, 1e200]
BACKENDS = ["auto", "clarabel", "nsgs", "newton"]
JUDGE_TOL = 1e-6
"""Independent natural-map error ‖F‖/‖q₀‖ above which a certified answer is wrong (the
certificate's tolerance is 1e-8 in contact units; W₀'s diagonal is within [0.05, 20])."""
HELD = (1e-280, 1e280)
"""Magnitudes of the exact r and u within which floats hold the answer: a refusal there is a
correct answer lost."""


def _problems() -> list[tuple[str, np.ndarray, np.ndarray, np.ndarray, int]]:
    """(name, W₀, q₀, μ, d): the issue's sphere, small closed forms and random well-posed
    problems with μ = 0.3 or mixed (μ = 0 among them), columns of unequal lengths."""
    out = [("eye3", np.eye(3), np.array([-1.0, 0.5, 0.0]), np.array([0.3]), 3),
           ("eye2-stick", np.diag([2.0, 4.0]), np.array([-2.0, 1.0]), np.array([0.5]), 2),
           ("eye3-open", np.eye(3), np.array([2.0, 0.3, -0.2]), np.array([0.7]), 3)]
    rng = np.random.default_rng(25)
    for i, (m, d, mixed) in enumerate([(2, 3, False), (3, 3, True), (4, 2, True), (3, 2, False),
                                       (5, 3, True), (2, 3, True)]):
        n = m * d
        A = rng.standard_normal((n, n))
        W = A.T @ A / n + 0.1 * np.eye(n)
        if i == 5:  # contacts whose columns differ in length by 1e±3
            D = np.repeat([1e-3, 1e3][:m], d)
            W = D[:, None] * W * D[None, :]
        q = rng.standard_normal(n)
        q[::d] = -np.abs(q[::d])  # every contact approaching
        mu = rng.uniform(0.0, 1.0, m) if mixed else np.full(m, 0.3)
        if mixed:
            mu[0] = 0.0
        out.append((f"random{i}", W, q, mu, d))
    return out


PROBLEMS = _problems()




def _judge(W0, q0, mu, d, r, u, a, b) -> float:
    """max(‖F‖, ‖ũ − (W̃₀r̃₀ + q̃₀)‖) / ‖q̃₀‖ in the contacts' velocity units of (W₀, q₀):
    r̃₀ = σ∘(r·a/b), ũ = u/(bσ), W̃₀ = W₀/σσᵀ, q̃₀ = q₀/σ with σ = √(W₀)_nn of each contact
    (so that r̃₀ is a velocity whatever the length of a contact's columns); F is De Saxcé's
    natural map at r̃₀ with the velocity recomputed."""
    sigma = np.repeat(np.sqrt(np.diag(W0)[::d]), d)
    Wt, qt = W0 / np.outer(sigma, sigma), q0 / sigma
    r0 = sigma * ((r * a) / b)
    u0 = Wt @ r0 + qt
    F = np.empty_like(r0)
    for c in range(mu.size):
        k = slice(c * d, c * d + d)
        ut = u0[k].copy()
        ut[0] += mu[c] * np.linalg.norm(u0[k][1:])  # De Saxcé's modified velocity
        F[k] = r0[k] - project_onto_cone(r0[k] - ut, mu[c])
    qn = np.linalg.norm(qt)
    return max(np.linalg.norm(F), np.linalg.norm(u / b / sigma - u0)) / qn


def _outcome(W, q, mu, d, backend):
    """The result, or the named error's class; a bare exception fails the test."""
    try:
        return iq.solve_friction(iq.FrictionContactProblem(W, q, mu, contact_dim=d),
                                 backend=backend)
    except ImpactError as exc:
        return type(exc)


def _held(values: np.ndarray, factor_log10: float) -> bool:
    """Floats hold values·10^factor_log10 (exact zeros aside) within :data:`HELD`."""
    big = np.log10(np.abs(values[values != 0.0])) + factor_log10
    return big.size == 0 or (big.min() > np.log10(HELD[0]) and big.max() < np.log10(HELD[1]))


@pytest.mark.parametrize("backend", BACKENDS)
def test_no_wrong_answer_is_certified_at_any_scale(backend):
    """Every case's expected outcome is recorded first: a correct answer where floats hold
    the exact one (an OutOfRangeError allowed only where they do not)."""
    wrong, lost, refused, allowed = [], [], 0, 0
    for name, W0, q0, mu, d in PROBLEMS:
        base = _outcome(W0, q0, mu, d, backend)
        assert not isinstance(base, type), f"{name}: {base.__name__} at unit scale"
        assert _judge(W0, q0, mu, d, base.r, base.u, 1.0, 1.0) <= JUDGE_TOL, name
        for a in W_SCALES:
            for b in Q_SCALES:
                exponent_r = np.log10(b) - np.log10(a)
                must_answer = _held(base.r, exponent_r) and _held(base.u, np.log10(b))
                allowed += not must_answer
                found = _outcome(a * W0, b * q0, mu, d, backend)
                if isinstance(found, type):
                    refused += 1
                    if must_answer or found is not OutOfRangeError:
                        lost.append((name, a, b, found.__name__))
                    continue
                assert found.certificate.ok
                err = _judge(W0, q0, mu, d, found.r, found.u, a, b)
                if not err <= JUDGE_TOL:
                    wrong.append((name, a, b, err))
    assert wrong == [], f"{len(wrong)} wrong answers certified: {wrong[:5]}"
    assert lost == [], f"{len(lost)} correct answers refused: {lost[:5]}"
    assert refused <= allowed
