"""Where no friction method certifies, the error carries the best answer found, its ABH
error and every attempt; that answer is never a success (docs/theory.md §15)."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import impactqp as iq
from impactqp.model.friction import certify_friction


def sliding_problem(m: int, seed: int) -> iq.FrictionContactProblem:
    """m contacts whose answer is not exactly representable (no method ends at error 0)."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((3 * m, 3 * m))
    q = rng.standard_normal(3 * m)
    q[::3] = -np.abs(q[::3])  # every contact approaches
    return iq.FrictionContactProblem(A.T @ A / (3 * m) + 1e-2 * np.eye(3 * m), q, 0.7)


def test_a_short_method_hands_back_its_best_answer():
    p = sliding_problem(6, seed=1)
    with pytest.raises(iq.CertificateError, match=r"\.best") as caught:
        iq.solve_friction(p, backend="nsgs-short", tol=1e-18)
    exc = caught.value
    best = exc.best
    assert isinstance(best, iq.friction.FrictionResult)
    assert best.status == "not certified" and not best.ok and not best.success
    assert "NOT certified" in best.message and best.backend == "nsgs-short"
    # its error, recomputed here from r alone, is the one it reports, and above the tolerance
    again = certify_friction(p, best.r, tol=1e-18)
    assert not again.ok
    assert best.error == pytest.approx(again.error, rel=1e-9)
    assert 1e-18 < best.error < 1e-6
    np.testing.assert_allclose(best.u, p.velocity(best.r), atol=1e-12)
    assert exc.attempts and any("nsgs-short" in a for a in exc.attempts)
    # a certified solve at a reachable tolerance is close to it
    good = iq.solve_friction(p, tol=1e-10)
    assert good.status == "solved"
    assert np.linalg.norm(best.r - good.r) <= 1e3 * best.error * max(1.0, np.linalg.norm(good.r))


def test_the_best_of_every_attempt_is_kept():
    # no method reaches 1e-18 (below round-off): all are tried, the error is the smallest
    p = sliding_problem(4, seed=3)
    with pytest.raises(iq.CertificateError) as caught:
        iq.solve_friction(p, tol=1e-18)
    exc = caught.value
    assert exc.best is not None and not exc.best.ok
    tried = {a.split(" ")[0] for a in exc.attempts}
    assert {"nsgs-short", "newton"} <= tried
    for method in ("newton", "clarabel"):
        with pytest.raises(iq.CertificateError) as one:
            iq.solve_friction(p, backend=method, tol=1e-18)
        assert exc.best.error <= one.value.best.error * (1 + 1e-9)
    # the error crosses process boundaries with its best answer (dask workers, pools)
    back = pickle.loads(pickle.dumps(exc))
    assert type(back) is iq.CertificateError and str(back) == str(exc)
    np.testing.assert_array_equal(back.best.r, exc.best.r)
    assert back.attempts == exc.attempts


def test_no_answer_at_all_leaves_best_empty():
    impossible = iq.FrictionContactProblem(np.zeros((3, 3)), [-1.0, 0.0, 0.0], 0.5)
    with pytest.raises(iq.CertificateError) as caught:
        iq.solve_friction(impossible, backend="nsgs")
    best = caught.value.best
    assert best is None or (not best.ok and best.status == "not certified")
