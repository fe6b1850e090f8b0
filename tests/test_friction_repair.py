"""Newton with local repairs (docs/theory.md §22): where Newton stalls at a stationary point
of its merit with the residual on a few contacts, the sub-problem of those contacts is solved
with the others held and Newton restarts; what it answers is certified by the one independent
certificate and agrees with a second method, and where nothing certifies the error carries the
best answer and each attempt's work."""

from __future__ import annotations

import re
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp

import impactqp as iq
from benchmarks.friction_data import load
from impactqp.model.friction import certify_friction
from impactqp.qp import backends
from impactqp.qp.friction.newton import FrictionData, newton
from impactqp.qp.friction.order import REPAIR_FIRST, friction_order
from impactqp.qp.friction.repair import REPAIR_MAX, repair, residual_cluster


def granular_patch(rings: int = 5) -> iq.FrictionContactProblem:
    """The grains around contact 544 of the 2,020-contact granular flow (W given to six
    digits), ``rings`` couplings of W deep, as a problem of its own: at 5 rings, 53 contacts
    where Newton, its damped variant, the least-squares Newton and 20000 sweeps all stall
    above 1e-6."""
    p = load("Granular2D-2020").problem
    W = sp.csr_matrix(p.W)
    d = p.contact_dim
    patch = np.array([544])
    for _ in range(rings):
        rows = (patch[:, None] * d + np.arange(d)).ravel()
        patch = np.union1d(patch, W[rows].indices // d)
    rows = (patch[:, None] * d + np.arange(d)).ravel()
    return iq.FrictionContactProblem(W[rows][:, rows], p.q[rows], p.mu[patch], contact_dim=d)


def test_newton_stalls_where_the_repair_certifies() -> None:
    p = granular_patch()
    assert p.n_contacts == 53
    with pytest.raises(iq.CertificateError) as stalled:
        iq.solve_friction(p, backend="newton")
    assert stalled.value.best.error > 1e-6
    res = iq.solve_friction(p, backend="newton-repair")
    assert res.backend == "newton-repair" and res.status == "solved"
    # auto: Newton fails, then the SOCP route from r = 0 (its start rule, STALL_NEAR)
    # certifies before the repairs are reached
    auto = iq.solve_friction(p)
    assert auto.backend == "clarabel" and auto.status == "solved"
    assert "newton (friction, tol 1e-08): certificate failed" in " ".join(auto.attempts)
    assert certify_friction(p, auto.r, tol=1e-8).ok
    np.testing.assert_allclose(auto.r, res.r, atol=1e-6 * np.abs(res.r).max())
    # the independent certificate, recomputed from r alone
    again = certify_friction(p, res.r, tol=1e-8)
    assert again.ok and again.error == pytest.approx(res.error, rel=1e-9)
    # a second method, the SOCP fixed point from r = 0, certifies the same answer
    socp = iq.solve_friction(p, backend="clarabel")
    scale_u, scale_r = np.abs(res.u).max(), np.abs(res.r).max()
    np.testing.assert_allclose(socp.u, res.u, atol=1e-6 * scale_u)
    np.testing.assert_allclose(socp.r, res.r, atol=1e-6 * scale_r)


def banded(m: int, d: int, mu: float, seed: int, reach: int = 1) -> iq.FrictionContactProblem:
    """m contacts in a row, each coupled to its 2·``reach`` neighbours on either side (W
    symmetric positive definite, block-banded), every contact approaching."""
    rng = np.random.default_rng(seed)
    n = m * d
    A = np.zeros((n, n))
    for c in range(m):
        for k in range(max(0, c - reach) * d, min(m, c + reach + 1) * d):
            A[c * d:(c + 1) * d, k] = rng.standard_normal(d)
    W = A @ A.T + 0.1 * np.eye(n)
    q = rng.standard_normal(n)
    q[::d] = -np.abs(q[::d])
    return iq.FrictionContactProblem(sp.csr_matrix(W), q, mu, contact_dim=d)


@pytest.mark.parametrize("d", [2, 3])
def test_a_repair_solves_the_contacts_it_is_given(d: int) -> None:
    p = banded(40, d, 0.5, seed=d)
    exact = iq.solve_friction(p, tol=1e-12)
    data = FrictionData(p)
    broken = exact.r.copy()
    broken[20 * d:23 * d] = 0.0  # three contacts knocked out, the rest at the answer
    rows = residual_cluster(data, broken)
    contacts = set(rows[::d] // d)
    assert {20, 21, 22} <= contacts and len(contacts) <= REPAIR_MAX
    assert rows.size < p.q.size  # a sub-problem, not the whole
    repaired, rounds = repair(data, broken, 1e-10)
    assert rounds > 0
    assert data.error(broken) > 1e-3 > 1e-9 > data.error(repaired)
    assert certify_friction(p, repaired, tol=1e-8).ok
    untouched = np.setdiff1d(np.arange(p.q.size), rows)
    np.testing.assert_array_equal(repaired[untouched], broken[untouched])
    np.testing.assert_allclose(repaired, exact.r, atol=1e-7 * np.abs(exact.r).max())


def test_a_spread_residual_is_not_repaired() -> None:
    # every contact carries the residual (r = 0 with every contact approaching) and is
    # coupled to twelve others: the largest residuals and their neighbours are more than a
    # repair takes, and the route ends (handing back its best answer)
    p = banded(200, 3, 0.5, seed=7, reach=3)
    data = FrictionData(p)
    assert residual_cluster(data, np.zeros(p.q.size)).size == 0
    r0 = np.zeros(p.q.size)
    assert repair(data, r0, 1e-8) == (r0, 0)


def test_a_failure_carries_the_best_answer_and_each_attempts_work() -> None:
    p = banded(12, 3, 0.5, seed=3)
    with pytest.raises(iq.CertificateError) as caught:
        iq.solve_friction(p, tol=1e-18)  # below round-off: nothing certifies
    exc = caught.value
    assert exc.best is not None and exc.best.status == "not certified"
    assert certify_friction(p, exc.best.r, tol=1e-18).error == pytest.approx(exc.best.error,
                                                                             rel=1e-9)
    failed = [a for a in exc.attempts if "certificate failed" in a]
    assert {a.split(" ")[0] for a in failed} >= {"nsgs-short", "newton", "newton-repair"}
    for note in failed:  # method, its worst figure, iterations and time of each attempt
        assert re.search(r"certificate failed, \w+ = \S+ after \d+ iterations, \S+ s$", note)


def test_the_repairs_come_before_the_cone_programs_on_large_problems_only() -> None:
    order = backends.AUTO_ORDER["friction"]
    small, large = (SimpleNamespace(n_contacts=m) for m in (REPAIR_FIRST - 1, REPAIR_FIRST))
    for program, first in ((small, "clarabel"), (large, "newton-repair")):
        names = friction_order(order, program)
        assert sorted(names) == sorted(order)  # the same methods, one place changed
        pair = [n for n in names if n in ("clarabel", "newton-repair")]
        assert pair[0] == first and names.index(pair[1]) == names.index(pair[0]) + 1


def test_a_newton_probe_stops_where_newton_is_far_from_converging() -> None:
    p = banded(40, 3, 0.5, seed=5)
    data = FrictionData(p)
    start = np.zeros(p.q.size)
    _, steps, ok = newton(data, start, 1e-8, max_steps=30, probe=(2, 1e30))
    assert (steps, ok) == (2, False)  # no two steps divide ‖F‖ by 1e30
    r, steps, ok = newton(data, start, 1e-8, max_steps=30, probe=(2, 1.0))
    assert ok and steps > 2 and certify_friction(p, r).ok  # any gain lets it go on
