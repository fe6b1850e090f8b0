"""The LZB model with restitution e < 1 against a reference whose rates are written here, in
numpy, from docs/theory.md §13, integrated in time by scipy; impactqp's compiled rates, events
and stepper are not called (its own scipy reference reads the same compiled rates, so it
cannot see an error in them).

Contact i with a linear spring (η = 1) of stiffness K stores Eᵢ = yᵢ², with

    ẏᵢ = −sᵢγᵢc/2,   Ṗᵢ = Fᵢ = c·yᵢ,   c = √(2K),   γ = γ⁻ + GP,

sᵢ = 1 while the contact is compressed (γᵢ < 0) and 1/eᵢ² while it expands (γᵢ > 0): the
expansion gives back eᵢ² of the energy stored. A contact that empties while separating opens
(yᵢ = 0 stays) until it approaches again; the impact ends when every contact is open and
none approaches. Then Λ = P and u⁺ = u⁻ + M⁻¹WΛ.
"""

from __future__ import annotations

from functools import partial

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import impactqp as iq
from impactqp.laws.lzb import LZB


def reference(problem: iq.ImpactProblem, K: float, e: np.ndarray) -> np.ndarray:
    """u⁺ of the LZB model with linear springs K and restitutions e, integrated in time."""
    M = np.asarray(problem.M.toarray() if hasattr(problem.M, "toarray") else problem.M)
    W = np.asarray(problem.W.toarray() if hasattr(problem.W, "toarray") else problem.W)
    Minv_W = np.linalg.solve(M, W)
    G = W.T @ Minv_W
    g0 = W.T @ problem.u_minus
    m, c = g0.size, np.sqrt(2.0 * K)
    live = g0 <= 0  # contacts that approach or touch at rest take part from the start
    x = np.zeros(2 * m)  # (y, P)

    def rates(_t, x, live):
        y, P = x[:m], x[m:]
        gamma = g0 + G @ P
        s = np.where(gamma > 0, 1.0 / e**2, 1.0)
        dy = np.where(live, -s * gamma * c / 2.0, 0.0)
        return np.concatenate([dy, c * np.where(live, y, 0.0)])

    for _ in range(100):  # pieces between changes of the live set
        def empties(_t, x, live, i):  # a live contact's energy reaching 0
            return x[i] if live[i] else 1.0

        def closes(_t, x, live, i):  # an open contact approaching again
            return -(g0 + G @ x[m:])[i] - 1e-14 if not live[i] else -1.0

        events = []
        for i in range(m):
            for f in (empties, closes):
                ev = partial(f, i=i)
                ev.terminal, ev.direction = True, -1 if f is empties else 1
                events.append(ev)
        sol = solve_ivp(rates, (0.0, 1e3), x, method="DOP853", rtol=1e-13, atol=1e-15,
                        events=events, args=(live,))
        x = sol.y[:, -1].copy()
        hit = [k for k, t in enumerate(sol.t_events) if t.size]
        assert hit, "the reference integration did not end the impact"
        k = hit[0]
        i = k // 2
        if k % 2 == 0:
            live = live.copy()
            live[i] = False
            x[i] = 0.0
        else:
            live = live.copy()
            live[i] = True
        gamma = g0 + G @ x[m:]
        if not live.any() and (gamma >= -1e-12 * np.abs(g0).max()).all():
            return problem.u_minus + Minv_W @ x[m:]
    raise AssertionError("the reference integration did not end the impact")


def test_two_balls_give_newton_rebound():
    # two balls: the expansion gives back e² of the energy, so γ⁺ = −eγ⁻ (closed form)
    p = iq.chain([1.0, 2.0], [1.0, -0.5])
    for e in (0.3, 0.7):
        u = reference(p, 1e4, np.array([e]))
        gamma_minus, gamma_plus = p.u_minus[1] - p.u_minus[0], u[1] - u[0]
        assert gamma_plus == pytest.approx(-e * gamma_minus, rel=1e-9)
        got = iq.solve(p, LZB(1e4, exponent=1.0, restitution=e)).u_plus
        np.testing.assert_allclose(got, u, rtol=0, atol=1e-8)


@pytest.mark.parametrize("e", [0.5, 0.8, (0.9, 0.4)])
@pytest.mark.parametrize("masses", [(1.0, 1.0, 1.0), (1.0, 0.5, 2.0)])
def test_three_balls_with_restitution_below_one(e, masses):
    # a striker on two balls at rest: the wave crosses the second contact while the first
    # expands, so the outcome depends on the expansion rate, not only on energy bookkeeping
    p = iq.chain(list(masses), [1.0, 0.0, 0.0])
    e = np.broadcast_to(np.asarray(e, dtype=float), (2,)).copy()
    want = reference(p, 1e4, e)
    got = iq.solve(p, LZB(1e4, exponent=1.0, restitution=e)).u_plus
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-8)
    # the answer is not the elastic one: e < 1 has dissipated energy
    T = lambda u: float(u @ (np.asarray(masses) * u))  # noqa: E731
    assert T(want) < T(p.u_minus) * (1 - 1e-3)
