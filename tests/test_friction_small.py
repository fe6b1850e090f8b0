"""The route of a few contacts in one compiled solve (impactqp/laws/friction_small.py,
impactqp/kernels/friction_packed.py's pack and solve_packed) against the general route: on
every problem of benchmarks/data/fclib with at most 64 contacts and on random ones, dense and
compressed, the same verdict, velocities within the certificate's tolerance, and a thin result whose
certificate is the one certify_friction recomputes from its r and u."""

from __future__ import annotations

import dataclasses
import pickle

import numpy as np
import pytest
import scipy.sparse as sp

import impactqp as iq
from benchmarks import friction_data
from benchmarks.friction_tiny import ONE_SWEEP, TINY
from impactqp.errors import BackendUnsuitableError, CertificateError
from impactqp.friction import FrictionResult
from impactqp.kernels.friction_packed import answer_size, pack, solve_packed
from impactqp.kernels.friction_tiny import CERTIFIED, NOT_CERTIFIED
from impactqp.laws import friction_small
from impactqp.laws.friction_small import SmallFrictionResult
from impactqp.model.friction import certify_friction
from impactqp.qp.friction import methods

TOL = 1e-8
MIDDLE = ("NESpheres-30", "BoxesStack1", "Confeti-ex03", "PerioBox")
"""Problems of the set beyond 32 contacts and within the swept route's 64."""


def general_route(problem: iq.FrictionContactProblem, tol: float = TOL):
    """``auto`` without the route of a few contacts (nor its one sweep); the pack an earlier
    solve kept on ``problem`` is dropped, or a solve again would take it."""
    problem.__dict__.pop(friction_small._KEPT, None)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(methods, "SMALL_CONTACTS", 0)
        patch.setattr(friction_small, "SWEPT_CONTACTS", 0)
        return iq.solve_friction(problem, tol=tol)


def same_answer(fast, general, problem: iq.FrictionContactProblem, tol: float) -> None:
    """Both certified; the fast result's certificate is certify_friction's of its r and u,
    and the two velocities agree to the certificate's tolerance (the answers' r may differ
    where W is singular, u = W r + q may not)."""
    assert fast.ok and fast.success and fast.status == "solved"
    assert general.certificate.ok
    again = certify_friction(problem, fast.r, fast.u, tol=tol)
    assert again.ok and fast.certificate.ok
    for name, value in again.values.items():
        assert fast.certificate.values[name] == pytest.approx(value, rel=1e-6, abs=1e-15)
    assert fast.error == fast.certificate.error == fast.certificate.values["natural_map"]
    scale = max(np.linalg.norm(problem.q), np.abs(fast.u).max())
    np.testing.assert_allclose(fast.u, general.u, atol=1e3 * tol * scale)


@pytest.mark.parametrize("name", [*TINY, *ONE_SWEEP, *MIDDLE])
def test_every_small_file_agrees_with_the_general_route(name: str) -> None:
    problem = friction_data.load(name).problem
    fast = iq.solve_friction(problem, tol=TOL)
    general = general_route(problem)
    if problem.n_contacts <= methods.SMALL_CONTACTS:
        assert type(fast) is SmallFrictionResult and fast.backend == "kernel"
    if name in ONE_SWEEP:  # ended by the compiled call's first sweep
        assert type(fast) is SmallFrictionResult and fast.iterations == 1
    same_answer(fast, general, problem, TOL)


def random_problem(m: int, d: int, seed: int, form: str = "dense",
                   rank: float = 1.0) -> iq.FrictionContactProblem:
    """W = AᵀA/n + shift (rank-deficient when ``rank`` < 1, no shift), contacts' scales
    over four decades, q with approaching normals; W dense, or sparse in ``form``."""
    rng = np.random.default_rng(seed)
    n = d * m
    k = max(1, int(rank * n))
    A = rng.standard_normal((k, n))
    W = A.T @ A / n + (1e-2 * np.eye(n) if rank == 1.0 else 0.0)
    unit = np.repeat(10.0 ** rng.uniform(-2, 2, m), d)
    W = W * np.outer(unit, unit)
    q = rng.standard_normal(n) * unit
    q[::d] = -np.abs(q[::d])
    mu = rng.uniform(0.0, 1.0, m)
    given = W if form == "dense" else sp.coo_matrix(W).asformat(form)
    return iq.FrictionContactProblem(given, q, mu, contact_dim=d)


@pytest.mark.parametrize("form", ["dense", "csr", "csc", "coo"])
@pytest.mark.parametrize("m, d", [(1, 3), (2, 2), (3, 3), (5, 3), (9, 3), (11, 2), (28, 2),
                                  (40, 3)])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_random_small_problems_agree_with_the_general_route(m: int, d: int, seed: int,
                                                             form: str) -> None:
    problem = random_problem(m, d, seed, form)
    try:
        general = general_route(problem, 1e-10)
    except CertificateError:
        general = None
    try:
        fast = iq.solve_friction(problem, tol=1e-10)
    except CertificateError:
        fast = None
    assert (fast is None) == (general is None)  # the same verdict
    if fast is not None:
        same_answer(fast, general, problem, 1e-10)
        dense = iq.solve_friction(random_problem(m, d, seed), tol=1e-10)
        np.testing.assert_allclose(fast.r, dense.r, rtol=1e-9,
                                   atol=1e-12 * np.abs(dense.r).max())


@pytest.mark.parametrize("seed", range(6))
def test_rank_deficient_small_problems_same_verdict(seed: int) -> None:
    """Singular W (rank half of d·m), where the compiled call may not certify: its verdict
    is never a success the general route would deny, and its answers are certified."""
    problem = random_problem(4, 3, seed, rank=0.5)
    outcomes = []
    for solve in (lambda p: iq.solve_friction(p, tol=TOL), general_route):
        try:
            outcomes.append(solve(problem))
        except CertificateError as exc:
            assert exc.best is None or not exc.best.ok
            outcomes.append(None)
    for res in outcomes:
        if res is not None:
            assert certify_friction(problem, res.r, res.u, tol=TOL).ok


def test_the_thin_result_reads_as_a_friction_result() -> None:
    problem = random_problem(3, 3, 5)
    res = iq.solve_friction(problem, tol=TOL)
    assert isinstance(res, FrictionResult) and type(res) is SmallFrictionResult
    assert "certificate" not in res.__dict__  # nothing built before it is asked for
    assert res.ok and res.certificate.ok
    assert res.attempts[-1] == "kernel (friction): certified"
    assert res.attempts[0] == "solved in its contacts' units (2^0)"
    assert res.iterations >= 1 and res.solve_time > 0
    assert "solved by kernel" in res.message and "FrictionResult(" in repr(res)
    np.testing.assert_allclose(res.u, problem.velocity(res.r),  # u = W r + q, in units
                               atol=1e-13 * np.abs(problem.q).max())
    copy = pickle.loads(pickle.dumps(res))
    np.testing.assert_array_equal(copy.r, res.r)
    assert copy.certificate.values == res.certificate.values
    replaced = dataclasses.replace(res, iterations=99)
    assert replaced.iterations == 99 and replaced.ok
    np.testing.assert_array_equal(replaced.r, res.r)
    assert res == dataclasses.replace(res)


def test_a_named_kernel_never_sweeps_beyond_its_limit() -> None:
    """``backend="kernel"`` keeps the method's own limit: 40 contacts are refused, not
    swept."""
    problem = random_problem(40, 3, 0)
    assert iq.solve_friction(problem).backend == "nsgs-short"
    with pytest.raises(BackendUnsuitableError):
        iq.solve_friction(problem, backend="kernel")


def test_the_first_sweep_alone_is_not_certified_where_it_does_not_reach_tol() -> None:
    """``whole`` False: one sweep, judged; a problem it does not finish is NOT_CERTIFIED,
    and the general route then solves it (and a tolerance no sweep reaches either)."""
    problem = random_problem(4, 3, 3)
    n = problem.q.size
    out = np.empty(answer_size(n))
    rows = (np.empty(0, np.int32), np.empty(0, np.int32), np.empty(0), False)
    outcome = solve_packed(*pack(problem.W, rows, problem.q, problem.mu, 3, (50, 100, 3, False)),
                           TOL, out)
    assert outcome == NOT_CERTIFIED
    outcome = solve_packed(*pack(problem.W, rows, problem.q, problem.mu, 3, (50, 100, 10, True)),
                           TOL, out)
    assert outcome == CERTIFIED
    assert certify_friction(problem, out[:n], out[n:2 * n], tol=TOL).ok


def test_the_benchmark_table_judges_each_target() -> None:
    """benchmarks/friction_tiny.py: ≤ NSGS + 10 µs below five contacts, ≤ 1× from five on."""
    from benchmarks.friction_tiny import meets, summary

    assert meets(1, 11e-6, 2e-6) and not meets(1, 12.5e-6, 2e-6)
    assert meets(4, 11e-6, 1.5e-6) and not meets(5, 11e-6, 1.5e-6)
    assert meets(9, 15e-6, 16e-6) and not meets(9, 17e-6, 16e-6)
    rows = [{"problem": name, "contacts": m, "d": 3, "iq_us": ours, "nsgs_us": theirs,
             "first_us": 2 * ours, "ratio": ours / theirs, "minus_us": ours - theirs,
             "target": "t", "met": meets(m, ours * 1e-6, theirs * 1e-6), "backend": "kernel",
             "iq_error": 1e-16, "nsgs_status": "ok"}
            for name, m, ours, theirs in [("a", 1, 11.0, 2.0), ("b", 1, 13.0, 2.0),
                                          ("c", 9, 15.0, 16.0), ("d", 9, 17.0, 16.0)]]
    text = summary(rows, 3)
    mean = (5.5 * 6.5 * 15 / 16 * 17 / 16) ** 0.25
    assert f"Targets met on 2 of 4 problems; geometric mean of the ratios {mean:.2f}." in text
    assert "| a | 1 | 3 | 11.0 µs (1e-16) | 22.0 µs | 2.0 µs (ok) | +9.0 µs | 5.50 |" in text
    assert ("| b | 1 | 3 | 13.0 µs (1e-16) | 26.0 µs | 2.0 µs (ok) | +11.0 µs | 6.50 | t "
            "| no |") in text


@pytest.mark.parametrize("name, iterations", [("LMGC-00046", 5), ("TwoRods1-condensed", 1),
                                              ("Confeti-ex13-4c", 1), ("FC3D-Example1", 1),
                                              ("Rover4396", 6)])
def test_fast_sweeps_agree_with_the_general_route(name: str, iterations: int) -> None:
    """Sweeps that speed up are taken on (LMGC-00046: five sweeps to round-off, Rover4396:
    six, its sliding contacts solved by their slip angles), and sweeps whose local problems
    are solved exactly end weakly coupled contacts in one (TwoRods1-condensed,
    Confeti-ex13-4c, FC3D-Example1), with no Newton step and not in the method whole from
    r = 0; the answer is the general route's and the ``"kernel"`` method's, to round-off."""
    problem = friction_data.load(name).problem
    fast = iq.solve_friction(problem, tol=TOL)
    assert type(fast) is SmallFrictionResult and fast.iterations == iterations
    assert fast.error <= 1e-12
    same_answer(fast, general_route(problem), problem, TOL)
    same_answer(fast, iq.solve_friction(problem, tol=TOL, backend="kernel"), problem, TOL)


@pytest.mark.parametrize("name", ["FC3D-RR-1c", "Rover11035", "Rover11211", "CubeH8",
                                  "FC3D-1c"])
def test_one_sliding_contact_is_solved_by_its_slip_angle(name: str) -> None:
    """A single 3-D contact the first sweep leaves sliding is solved by the root of its
    slip function, to round-off with no sweep more: the general route's answer, certified
    independently."""
    problem = friction_data.load(name).problem
    fast = iq.solve_friction(problem, tol=TOL)
    assert type(fast) is SmallFrictionResult and fast.iterations == 1
    assert fast.error <= 1e-14
    rn, rt = fast.r[0], np.linalg.norm(fast.r[1:])
    assert rn > 0.0 and rt == pytest.approx(problem.mu[0] * rn, rel=1e-12)  # on the rim
    same_answer(fast, general_route(problem), problem, TOL)


@pytest.mark.parametrize("seed", range(40))
def test_the_slip_angle_root_solves_random_sliding_contacts(seed: int) -> None:
    """sliding_3d on a contact that neither separates nor sticks (W_cc symmetric positive
    definite: the local problem has one solution, hence a sliding one): it finds the root,
    r lies on the cone's rim, u_n = 0, u_t opposes r_t, and the natural map of that answer,
    computed apart, vanishes to round-off."""
    from impactqp.kernels.friction import natural_map
    from impactqp.kernels.friction_blocks import sticking
    from impactqp.kernels.friction_slip import sliding_3d

    rng = np.random.default_rng(seed)
    A = rng.standard_normal((3, 3))
    Wc = A @ A.T + 0.1 * np.eye(3)
    base = rng.standard_normal(3)
    base[0] = -abs(base[0])
    mu = float(rng.uniform(0.05, 1.5))
    r = np.empty(3)
    if sticking(Wc, base, mu, 3, r):
        return  # the sticking answer, checked by the files above
    assert sliding_3d(Wc, base, mu, r)
    u = Wc @ r + base
    assert r[0] > 0.0 and np.hypot(r[1], r[2]) == pytest.approx(mu * r[0], rel=1e-12)
    assert abs(u[0]) <= 1e-12 * (np.abs(Wc).max() * r[0] + abs(base[0]))
    assert u[1] * r[1] + u[2] * r[2] < 0.0
    F = natural_map(r, u, np.array([mu]), 3)
    assert np.linalg.norm(F) <= 1e-12 * (np.linalg.norm(base) + np.linalg.norm(r))
