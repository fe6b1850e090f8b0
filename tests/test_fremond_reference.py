"""Frémond's law with an asymmetric matrix E in motion, against references written here from
docs/theory.md §14 and §3 (Moreau–Jean; one impact), with numpy and a brute-force LCP.

Every other simulation test uses a symmetric E, for which E and Eᵀ give the same motion; a
transposed E (Eᵢⱼ for Eⱼᵢ) anywhere on the way from the law to a step or an impact changes
these trajectories, and both of impactqp's loops (compiled and Python) read the law the same
way, so only an outside reference can see it.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import impactqp as iq
from impactqp.simulation.time_stepping import moreau_jean

E = np.array([[0.6, 0.3, 0.0],
              [0.0, 0.5, 0.25],
              [0.2, 0.0, 0.4]])
"""Asymmetric on every pair: E₀₁ = 0.3 but E₁₀ = 0, E₁₂ = 0.25 but E₂₁ = 0, E₂₀ = 0.2 but
E₀₂ = 0."""


def column() -> iq.LinearSystem:
    """Three touching beads (spacing = diameter) dropped from 0.3 m: every contact closes
    together at the ground impact, so the coupling of E acts."""
    return iq.simulation.bead_chain(3, radius=0.1, height=0.3, spacing=0.2)


def lcp(G: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The solution of 0 ≤ Λ ⟂ GΛ + q ≥ 0 for symmetric positive definite G (unique), by
    trying every support."""
    m = q.size
    scale = max(np.abs(q).max(), 1e-300)
    for size in range(m + 1):
        for J in map(list, itertools.combinations(range(m), size)):
            lam = np.zeros(m)
            if J:
                lam[J] = np.linalg.solve(G[np.ix_(J, J)], -q[J])
            w = G @ lam + q
            if lam.min() >= -1e-12 * scale and w.min() >= -1e-12 * scale:
                return lam
    raise AssertionError("no support solves the LCP")


def clusters(H: np.ndarray, closed: np.ndarray) -> list[np.ndarray]:
    """The closed contacts split into groups that share a body (M is diagonal here)."""
    groups: list[set] = []
    for c in closed:
        bodies = set(np.flatnonzero(H[:, c]))
        touching = [g for g in groups if g[1] & bodies]
        merged = ({c}.union(*(g[0] for g in touching)), bodies.union(*(g[1] for g in touching)))
        groups = [g for g in groups if g not in touching] + [merged]
    return [np.array(sorted(g[0])) for g in groups]


def reference_moreau_jean(system: iq.LinearSystem, E: np.ndarray, h: float, steps: int):
    """Moreau–Jean with θ = 1/2 and a constant force, step by step as docs/theory.md §14
    states it: closed contacts gᵢ + (h/2)γᵢ ≤ 0, v_free = v_k + hM⁻¹f, for each cluster A the
    LCP 0 ≤ Λ ⟂ GΛ + H_Aᵀv_free + E_AA H_Aᵀv_k ≥ 0 (skipped when q ≥ 0),
    v_{k+1} = v_free + M⁻¹H_AΛ, q_{k+1} = q_k + (h/2)(v_k + v_{k+1})."""
    M, H, b = np.asarray(system.M), np.asarray(system.H), np.asarray(system.b)
    f = np.asarray(system.force(0.0, system.q0, system.v0))
    Minv = np.linalg.inv(M)
    q, v = np.array(system.q0, dtype=float), np.array(system.v0, dtype=float)
    Q, V = [q.copy()], [v.copy()]
    for _ in range(steps):
        closed = np.flatnonzero(H.T @ q + b + 0.5 * h * (H.T @ v) <= 0)
        v_free = v + h * (Minv @ f)
        v_next = v_free.copy()
        for A in clusters(H, closed):
            W = H[:, A]
            G = W.T @ Minv @ W
            rhs = W.T @ v_free + E[np.ix_(A, A)] @ (W.T @ v)
            if rhs.min() >= 0:
                continue
            v_next += Minv @ W @ lcp(G, rhs)
        q = q + 0.5 * h * (v + v_next)
        v = v_next
        Q.append(q.copy())
        V.append(v.copy())
    return np.array(Q), np.array(V)


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "python"])
def test_moreau_jean_with_an_asymmetric_fremond_matrix(compiled):
    system, h, steps = column(), 1e-3, 500
    tr = moreau_jean(system, iq.Fremond(E), steps * h, h, 0.5, compiled=compiled)
    Q, V = reference_moreau_jean(system, E, h, steps)
    assert tr.q.shape == Q.shape
    np.testing.assert_allclose(tr.q, Q, rtol=0, atol=1e-12 * np.abs(Q).max())
    np.testing.assert_allclose(tr.v, V, rtol=0, atol=1e-10 * np.abs(V).max())
    # the asymmetry matters: with Eᵀ the reference moves differently
    _, V_t = reference_moreau_jean(system, E.T, h, steps)
    assert np.abs(V_t - V).max() > 1e-3 * np.abs(V).max()


def test_event_driven_impacts_with_an_asymmetric_fremond_matrix():
    system = column()
    tr = iq.simulate(system, iq.Fremond(E), 0.5, scheme="event-driven")
    M, H = np.asarray(system.M), np.asarray(system.H)
    coupled = 0
    for ev in tr.events:
        W = H[np.ix_(ev.dofs, ev.contacts)]
        Md = M[np.ix_(ev.dofs, ev.dofs)]
        Minv_W = np.linalg.solve(Md, W)
        g = W.T @ ev.u_minus
        E_c = E[np.ix_(ev.contacts, ev.contacts)]
        # docs/theory.md §3: 0 ≤ Λ ⟂ γ⁺ + Eγ⁻ ≥ 0, γ⁺ = γ⁻ + GΛ
        lam = lcp(W.T @ Minv_W, g + E_c @ g)
        u_plus = ev.u_minus + Minv_W @ lam
        scale = np.abs(ev.u_minus).max()
        np.testing.assert_allclose(ev.u_plus, u_plus, rtol=0, atol=1e-10 * scale)
        np.testing.assert_allclose(ev.impulses, lam, rtol=0, atol=1e-10 * np.abs(lam).max())
        # an impact where E's asymmetry changes the answer
        lam_t = lcp(W.T @ Minv_W, g + E_c.T @ g)
        coupled += np.abs(lam_t - lam).max() > 1e-3 * np.abs(lam).max()
    assert coupled >= 1
